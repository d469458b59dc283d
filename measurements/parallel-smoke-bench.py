"""Nimbus Smoke under MPI: every rank runs the whole simulation (docs/parallel.md, "The smoke
solver under MPI"). Peak memory and time per frame on each rank.

    python3 measurements/parallel-smoke-bench.py --table [--ranks 1 2 4] [--size 64 64 64]
        [--frames 4]
        runs `mpiexec --oversubscribe -n N pvbatch --symmetric` on this script for each N
        and prints the table (markdown) and every rank's JSON line

One rank's part (run by --table through mpiexec):
    pvbatch --symmetric parallel-smoke-bench.py --rank-job --size NX NY NZ --frames F
      vtkNimbusSmokeSource of NX x NY x NZ cells (other parameters the defaults), then
      UpdateTimeStep(f x FrameDurationSeconds, rank, N, 0) for f = 1..F (playing forward:
      one frame of simulation each). Each rank prints one JSON line: VmHWM (peak resident
      memory, /proc/self/status) before the source and after the last frame, the seconds of
      each frame (wall clock, after a barrier), the solver's sub-steps per frame, the points
      of its piece and of the whole grid, and the bytes of its piece's arrays (what one
      simulating rank would send it per frame instead).

PYTHONPATH must reach the nimbus package (build/lib/python3.11/site-packages). As root,
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1. Take the machine's measurement lock
(flock /tmp/nimbus-measure.lock) around --table.
"""
import argparse
import json
import os
import subprocess
import sys
import time

HERE = os.path.abspath(__file__)
MiB = 1024.0 * 1024.0


def vm_hwm():
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    return 0


def rank_job(args):
    from vtkmodules.vtkParallelCore import vtkMultiProcessController
    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId()
    ranks = controller.GetNumberOfProcesses()
    import nimbus
    before = vm_hwm()
    source = nimbus.vtkNimbusSmokeSource()
    source.SetDimensions(*args.size)
    source.SetNumberOfFrames(max(args.frames, 1))
    dt = source.GetFrameDurationSeconds()
    seconds, substeps = [], []
    for frame in range(1, args.frames + 1):
        controller.Barrier()
        start = time.perf_counter()
        source.UpdateTimeStep(frame * dt, rank, ranks, 0)
        seconds.append(time.perf_counter() - start)
        substeps.append(source.GetLastSubsteps())
    out = source.GetOutput()
    print(json.dumps({"rank": rank, "ranks": ranks, "size": list(args.size),
                      "vmhwm_before_mib": before / MiB, "vmhwm_mib": vm_hwm() / MiB,
                      "frame_seconds": seconds, "substeps": substeps,
                      "piece_points": out.GetNumberOfPoints(),
                      "whole_points": args.size[0] * args.size[1] * args.size[2],
                      "piece_bytes": sum(a.GetNumberOfValues() * a.GetDataTypeSize() for a in
                                         (out.GetPointData().GetArray(i) for i in
                                          range(out.GetPointData().GetNumberOfArrays()))),
                      "arrays": [out.GetPointData().GetArrayName(i)
                                 for i in range(out.GetPointData().GetNumberOfArrays())]}),
          flush=True)


def table(args):
    print("| ranks | whole grid, points | points per rank | peak per rank, MiB (VmHWM, each rank) "
          "| above pvbatch + nimbus before the source, MiB (max) | time per frame, s (mean "
          "of frames 2..F, max over ranks) | first frame, s (max) | sub-steps per frame |")
    print("|---|---|---|---|---|---|---|---|")
    lines = []
    for n in args.ranks:
        command = ["mpiexec", "--oversubscribe", "-n", str(n), "pvbatch", "--symmetric", HERE,
                   "--rank-job", "--size"] + [str(s) for s in args.size] + \
                  ["--frames", str(args.frames)]
        run = subprocess.run(command, capture_output=True, text=True, timeout=1800)
        rows = sorted((json.loads(line) for line in run.stdout.splitlines()
                       if line.startswith("{")), key=lambda r: r["rank"])
        if len(rows) != n:
            print(run.stdout, run.stderr, file=sys.stderr)
            raise SystemExit("%d ranks printed %d lines" % (n, len(rows)))
        lines += rows
        later = [sum(r["frame_seconds"][1:]) / max(len(r["frame_seconds"]) - 1, 1) for r in rows]
        print("| %d | %d | %d | %s | %.0f | %.2f | %.2f | %s |" % (
            n, rows[0]["whole_points"], max(r["piece_points"] for r in rows),
            ", ".join("%.0f" % r["vmhwm_mib"] for r in rows),
            max(r["vmhwm_mib"] - r["vmhwm_before_mib"] for r in rows), max(later),
            max(r["frame_seconds"][0] for r in rows),
            "/".join(str(s) for s in rows[0]["substeps"])), flush=True)
    for row in lines:
        print(json.dumps(row))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--table", action="store_true")
    parser.add_argument("--rank-job", action="store_true")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    parser.add_argument("--size", type=int, nargs=3, default=[64, 64, 64])
    parser.add_argument("--frames", type=int, default=4)
    args = parser.parse_args()
    if args.rank_job:
        rank_job(args)
    elif args.table:
        table(args)
    else:
        print(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
