#!/usr/bin/env bash
# Set up (packages, configure, build) and render the Nimbus demo scene to a PNG;
# prints the image's path. Extra arguments go to nimbus-demo (see --help there).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${NIMBUS_BUILD_DIR:-$repo/build}"
bash "$repo/scripts/setup.sh" >&2
"$repo/Testing/with-display.sh" "$build/bin/nimbus-demo" --output "$build/nimbus-demo.png" "$@"
