#!/usr/bin/env bash
# Builds what ./scripts/setup.sh left out (tests, benchmarks) and runs the
# whole test suite: two ctest slots per core; a multi-process integration
# test takes two of them (cmake/IplanHelpers.cmake), so at most two run at
# once; the browser tests and the install check run alone.
# Tests read recorded data from ../shared beside the checkout.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -d ../shared ]; then
  echo "test: ../shared (recorded data, robot model) is missing beside the checkout" >&2
  exit 2
fi
# Leftover Fast DDS shared-memory files from killed processes are harmless
# with our UDP-only profiles, but clean them when the tool is there.
command -v fastdds >/dev/null 2>&1 && fastdds shm clean >/dev/null 2>&1 || true
jobs="${IPLAN_JOBS:-$(nproc)}"
cmake --build build -j "$jobs"
cd build
ctest --output-on-failure --timeout 900 -j "$((2 * $(nproc)))" "$@"
