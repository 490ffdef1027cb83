#!/usr/bin/env bash
# Sets up iplan on a Debian 12 machine: installs every dependency from
# Debian's packages (only what is missing), then configures a Release build
# in build/ and builds what the demo runs (executables in build/bin/);
# scripts/test.sh builds the tests and benchmarks.
#
#   ./scripts/setup.sh            # install + build
#   IPLAN_JOBS=1 ./scripts/setup.sh   # build with fewer parallel jobs
#   IPLAN_BUILD_ALL=1 ./scripts/setup.sh   # build the tests and benchmarks too
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config python3 git
  # DDS: both vendors, their code generators and tools
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools cyclonedds-dev cyclonedds-tools
  # algorithms
  libeigen3-dev libfcl-dev libccd-dev libceres-dev liburdfdom-dev
  # collision meshes of URDFs (STL, DAE, OBJ; common/collision/src/mesh_io.cc)
  libassimp-dev
  # point clouds (found through its pkg-config files, see common/cloud/CMakeLists.txt)
  libpcl-dev
  # infrastructure
  libspdlog-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libsystemd-dev systemd
  # DDS Security keystores (iplan security, common/dds/src/pki.cc; the openssl
  # CLI to inspect them)
  libssl-dev openssl
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # the multi-host test: network namespaces, veth pairs, a bridge (iproute2)
  # and packet loss inside a namespace (nftables)
  iproute2 nftables
  # the planning benchmark's peer planner (benchmark only, no service links it)
  libompl-dev
  # viewer (iplan view / record / report): HTTP + WebSocket server, Node.js for
  # the page's npm dependencies, the MCAP writer and the report, Chromium for
  # the browser tests
  libwebsocketpp-dev libasio-dev chromium
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# Node.js and npm: Debian's packages only where no node/npm is installed
# (a machine with NodeSource's nodejs has npm inside it, and Debian's npm
# package conflicts with that nodejs).
command -v node >/dev/null 2>&1 || missing+=(nodejs)
command -v npm >/dev/null 2>&1 || missing+=(npm)
if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -q
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all Debian packages present"
fi

# The web part: npm packages exactly as locked (three.js, @foxglove/*,
# @mcap/core, uPlot, esbuild, playwright-core), then the page bundle in
# web/dist. Nothing is fetched at run time.
echo "setup: installing the web part's npm packages (web/package-lock.json)"
(cd web && npm ci --no-audit --no-fund && node build.mjs)

jobs="${IPLAN_JOBS:-$(nproc)}"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
# Only what the demo runs (the iplan tool, the services, the viewer's page);
# scripts/test.sh builds the tests and benchmarks, IPLAN_BUILD_ALL=1 here too.
if [ "${IPLAN_BUILD_ALL:-0}" = 1 ]; then
  cmake --build build -j "$jobs"
else
  cmake --build build -j "$jobs" --target demo_cell
fi
# The cell's DDS Security keystore (CA, governance, one enclave per service):
# made once per user, never overwritten; `iplan demo` runs secured with it.
# Built beside its folder and renamed into place, so an interrupted setup
# never leaves a half keystore (docs/deployment.md, "DDS Security").
./build/bin/iplan security ensure-keystore
echo "setup: done; executables in build/bin/"
