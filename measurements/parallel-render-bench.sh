#!/usr/bin/env bash
# Frame time and memory per rank of the Cloud representation in pvbatch on 1, 2 and 4
# ranks (docs/parallel.md). Usage: measurements/parallel-render-bench.sh [grid] [ranks...]
# Prints, per rank count, the first render (delivery, coarse all-gather, uploads and
# solves), the mean of 3 still renders after small camera moves (passes and IceT
# compositing), and every rank's peak resident memory (GNU time's %M).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
grid="${1:-192}"
shift || true
ranks=("${@:-1 2 4}")
plugin="$repo/build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so"
work="$(mktemp -d)"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
for n in ${ranks[@]}; do
  "$repo/Testing/with-display.sh" mpiexec -n "$n" /usr/bin/time -f "rank peak %M KiB" \
    pvbatch --force-offscreen-rendering "$repo/Testing/Python/ParallelCloudRender.py" \
    --plugin "$plugin" --output "$work/cloud-$n.png" --data "$work/cloud.vti" \
    --grid "$grid" --frames 3 --timings "$work/timings-$n.json" 2>&1 |
    grep -E "^ranks|rank peak" || true
done
echo "images and timings in $work"
