"""Generation time and peak memory per rank of the Nimbus field sources in pieces (docs/parallel.md).

    PYTHONPATH=build/lib/python3.11/site-packages \
        mpiexec -n N pvbatch --symmetric measurements/parallel-generation-bench.py \
        --source metaball|automaton|smoke [--size 256] [--json out.json]

(Open MPI as root: add --allow-run-as-root; more ranks than cores: --oversubscribe.) Every
rank updates its piece (rank, N), no ghost levels. Printed by rank 0:

- time: the largest, over the ranks, of the source's RequestData time (from its
  StartEvent to its EndEvent), seconds;
- memory: the largest, over the ranks, of the peak resident set of the update
  (getrusage's ru_maxrss after the update minus before it), MiB;
- the points each rank outputs (largest).

One source per run, so that one source's peak does not hide the next one's. The metaball
cloud samples its final density on the piece only (its growth runs on the whole grid); the
automaton and the smoke run on the whole grid on every rank (redundant) and crop.
"""
import argparse
import json
import resource
import sys
import time

from vtkmodules.vtkCommonCore import vtkCommand, vtkDoubleArray
from vtkmodules.vtkParallelCore import vtkCommunicator, vtkMultiProcessController

import nimbus


def make(source, size):
    if source == "metaball":
        s = nimbus.vtkNimbusMetaballCloudSource()
        s.SetDimensions(size, size, size)
        return s, None
    if source == "automaton":
        s = nimbus.vtkNimbusCloudAutomatonSource()
        s.SetDimensions(size, size, max(8, size // 4))
        return s, 0.0
    if source == "smoke":
        s = nimbus.vtkNimbusSmokeSource()
        s.SetDimensions(size, size, size + size // 2)
        return s, 4.0 * s.GetFrameDurationSeconds()
    raise ValueError(source)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", choices=["metaball", "automaton", "smoke"], required=True)
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--json")
    args = parser.parse_args()

    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId()
    ranks = controller.GetNumberOfProcesses()
    source, t = make(args.source, args.size)
    clock = {}
    source.AddObserver(vtkCommand.StartEvent, lambda *_: clock.__setitem__("start", time.perf_counter()))
    source.AddObserver(vtkCommand.EndEvent, lambda *_: clock.__setitem__("end", time.perf_counter()))
    controller.Barrier()
    baseline = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    if t is None:
        source.UpdatePiece(rank, ranks, 0)
    else:
        source.UpdateTimeStep(t, rank, ranks, 0)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    points = source.GetOutputDataObject(0).GetNumberOfPoints()

    mine = vtkDoubleArray()
    for value in (clock["end"] - clock["start"], (peak - baseline) / 1024.0, points):
        mine.InsertNextValue(value)
    largest = vtkDoubleArray()
    controller.AllReduce(mine, largest, vtkCommunicator.MAX_OP)
    if rank == 0:
        result = {"source": args.source, "size": args.size, "ranks": ranks,
                  "seconds": largest.GetValue(0), "peak_mib": largest.GetValue(1),
                  "points_per_rank": int(largest.GetValue(2)),
                  "whole_extent": list(source.GetOutputInformation(0).Get(
                      source.GetExecutive().WHOLE_EXTENT()))}
        print(json.dumps(result), flush=True)
        if args.json:
            with open(args.json, "a") as stream:
                stream.write(json.dumps(result) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
