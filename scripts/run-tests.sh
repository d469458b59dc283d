#!/usr/bin/env bash
# Set up (packages, configure, build) and run the whole Nimbus test suite with ctest.
# Extra arguments go to ctest (e.g. -L unit, -R image).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${NIMBUS_BUILD_DIR:-$repo/build}"
bash "$repo/scripts/setup.sh"
cd "$build"
ctest --output-on-failure --parallel "${NIMBUS_JOBS:-$(nproc)}" "$@"
