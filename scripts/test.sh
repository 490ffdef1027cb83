#!/usr/bin/env bash
# Runs the whole test suite of an already set-up build (./scripts/setup.sh):
# unit tests in parallel, multi-process integration tests one at a time.
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
cd build
ctest --output-on-failure --timeout 900 -j 2 "$@"
