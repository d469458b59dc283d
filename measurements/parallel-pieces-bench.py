"""What each rank holds: peak memory, time and bytes exchanged per rank for the OpenVDB reader
and the cloud automaton under MPI (docs/parallel.md, "What each rank holds").

    python3 measurements/parallel-pieces-bench.py --make-vdb FILE [--size 512]
        writes the metaball cloud (vtkNimbusMetaballCloudSource, SIZE^3 points, defaults) with
        the OpenVDB writer (run once; plain python3)
    python3 measurements/parallel-pieces-bench.py --table --vdb FILE [--ranks 1 2 4 8]
        [--automaton 512 512 128]
        runs the cases below under `mpiexec --oversubscribe -n N pvbatch --symmetric` for each N
        and prints the table (markdown)

    python3 measurements/parallel-pieces-bench.py --breakdown --vdb FILE [--piece 0 8]
        one process (no MPI): where the reader's memory goes, per mapping of /proc/self/smaps
        (the image's anonymous block, each library's code and tables faulted in, the heap),
        in KiB of resident memory above `import nimbus`, after UpdateInformation and after
        UpdatePiece(P, N, 0), and malloc's heap (in use and freed but resident)

One rank's part (run by --table through mpiexec):
    pvbatch --symmetric parallel-pieces-bench.py --rank-job baseline|vdb|automaton ...
      baseline: nothing loaded (no nimbus import): ParaView's, Python's and MPI's own memory;
      imported: `import nimbus` only (Nimbus's, OpenVDB's and their libraries' memory);
      vdb: vtkNimbusOpenVDBReader.UpdatePiece(rank, N, 0) of FILE;
      automaton: vtkNimbusCloudAutomatonSource of NX x NY x NZ cells (defaults: 40 spin-up
        steps, formation regions), UpdatePiece(rank, N, 0) at time 0.
    Each rank prints one JSON line: VmHWM (peak resident memory, /proc/self/status), the
    seconds of the update (wall clock, after a barrier), the points of its piece, and for the
    automaton the halo bytes it sends per step and the bytes of cld rows it received.

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


def smaps_rss():
    """Resident KiB per mapping (path and permissions) of this process."""
    import collections
    rss = collections.Counter()
    name = None
    with open("/proc/self/smaps") as smaps:
        for line in smaps:
            parts = line.split()
            if len(parts) >= 5 and "-" in parts[0] and not parts[0].endswith(":"):
                name = (parts[5] if len(parts) > 5 else "[anonymous]") + " " + parts[1]
            elif parts[0] == "Rss:":
                rss[name] += int(parts[1])
    return rss


def malloc_heap():
    """glibc's heap (mallinfo2): KiB in use and KiB freed but kept."""
    import ctypes

    class MallInfo2(ctypes.Structure):
        _fields_ = [(n, ctypes.c_size_t) for n in (
            "arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks",
            "fordblks", "keepcost")]
    libc = ctypes.CDLL("libc.so.6")
    libc.mallinfo2.restype = MallInfo2
    info = libc.mallinfo2()
    return info.uordblks // 1024, info.fordblks // 1024


def breakdown(args):
    import nimbus
    malloc_heap()
    smaps_rss()  # the measuring's own code loaded and run once before the first snapshot
    steps = [("imported", smaps_rss(), malloc_heap(), vm_hwm())]
    reader = nimbus.vtkNimbusOpenVDBReader()
    reader.SetFileName(args.vdb)
    reader.UpdateInformation()
    steps.append(("information", smaps_rss(), malloc_heap(), vm_hwm()))
    reader.UpdatePiece(args.piece[0], args.piece[1], 0)
    steps.append(("piece", smaps_rss(), malloc_heap(), vm_hwm()))
    print("piece %d of %d of %s: %d points" % (args.piece[0], args.piece[1], args.vdb,
                                                 reader.GetOutput().GetNumberOfPoints()))
    print("VmHWM above imported: %.1f MiB" % ((steps[-1][3] - steps[0][3]) / MiB))
    for (name, heap) in [(s[0], s[2]) for s in steps]:
        print("malloc heap after %s: %d KiB in use, %d KiB freed and kept" % (name, heap[0], heap[1]))
    first, info, last = steps[0][1], steps[1][1], steps[2][1]
    print("KiB resident above imported: after UpdateInformation, then UpdatePiece, mapping")
    for key in sorted(set(first) | set(last), key=lambda k: first[k] - last[k]):
        if last[key] != first[key] or info[key] != first[key]:
            print("%8d %8d  %s" % (info[key] - first[key], last[key] - info[key], key))


def make_vdb(path, size):
    import nimbus
    source = nimbus.vtkNimbusMetaballCloudSource()
    source.SetDimensions(size, size, size)
    start = time.time()
    source.Update()
    generated = time.time() - start
    writer = nimbus.vtkNimbusOpenVDBWriter()
    writer.SetInputConnection(source.GetOutputPort())
    writer.SetFileName(path)
    start = time.time()
    if not writer.Write():
        raise SystemExit("could not write " + path)
    print("%s: %d^3 metaball cloud, generated in %.1f s, written in %.1f s, %.1f MiB"
          % (path, size, generated, time.time() - start, os.path.getsize(path) / MiB))


def rank_job(args):
    from vtkmodules.vtkParallelCore import vtkMultiProcessController
    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId()
    ranks = controller.GetNumberOfProcesses()
    result = {"rank": rank, "ranks": ranks, "job": args.rank_job}
    if args.rank_job == "imported":
        import nimbus  # noqa: F401 (the libraries loaded, nothing made)
    elif args.rank_job != "baseline":
        import nimbus
        if args.rank_job == "vdb":
            algorithm = nimbus.vtkNimbusOpenVDBReader()
            algorithm.SetFileName(args.vdb)
            algorithm.UpdateInformation()
        else:
            algorithm = nimbus.vtkNimbusCloudAutomatonSource()
            algorithm.SetDimensions(*args.automaton)
        controller.Barrier()
        start = time.time()
        algorithm.UpdatePiece(rank, ranks, 0)
        result["seconds"] = time.time() - start
        controller.Barrier()
        result["all_seconds"] = time.time() - start
        result["points"] = algorithm.GetOutput().GetNumberOfPoints()
        if args.rank_job == "automaton":
            result["halo_bytes_per_step"] = algorithm.GetHaloBytesPerStep()
            result["gather_bytes"] = algorithm.GetPieceGatherBytes()
            result["owned_layers"] = list(algorithm.GetOwnedLayers())
    result["vm_hwm"] = vm_hwm()
    with open(os.path.join(args.result_dir, "rank-%d.json" % rank), "w") as out:
        json.dump(result, out)


def run(ranks, job, args):
    import glob
    import tempfile
    directory = tempfile.mkdtemp(prefix="nimbus-pieces-bench-")
    command = ["mpiexec", "--oversubscribe", "-n", str(ranks), "pvbatch", "--symmetric",
               "--force-offscreen-rendering", HERE, "--rank-job", job, "--result-dir", directory]
    if job == "vdb":
        command += ["--vdb", args.vdb]
    if job == "automaton":
        command += ["--automaton"] + [str(n) for n in args.automaton]
    output = subprocess.run(command, check=True, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True).stdout
    rows = []
    for name in glob.glob(os.path.join(directory, "rank-*.json")):
        with open(name) as result:
            rows.append(json.load(result))
        os.remove(name)
    os.rmdir(directory)
    if len(rows) != ranks:
        raise SystemExit("%s on %d ranks: %d results\n%s" % (job, ranks, len(rows), output))
    return sorted(rows, key=lambda r: r["rank"])


def table(args):
    print("| case | ranks | points per rank (max) | pvbatch alone, MiB | nimbus imported, MiB | "
          "peak per rank, MiB (max; all) | above pvbatch alone (goal 1.3 x 1 rank's / N) | "
          "above nimbus imported (goal) | time s (max) | halo bytes sent per step per rank | "
          "cld rows received per rank, MiB (max) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    cases = []
    if args.vdb:
        cases.append(("vdb", "OpenVDB reader %s" % os.path.basename(args.vdb)))
    if args.automaton:
        cases.append(("automaton", "automaton %dx%dx%d" % tuple(args.automaton)))
    for job, name in cases:
        whole = whole_imported = None
        for n in args.ranks:
            base = max(r["vm_hwm"] for r in run(n, "baseline", args)) / MiB
            imported = max(r["vm_hwm"] for r in run(n, "imported", args)) / MiB
            rows = run(n, job, args)
            peaks = [r["vm_hwm"] / MiB for r in rows]
            above = max(peaks) - base
            above_imported = max(peaks) - imported
            if n == 1:
                whole, whole_imported = above, above_imported

            def goal(w):
                return "%.1f" % (1.3 * w / n) if w is not None else "-"
            halo = "; ".join(str(r.get("halo_bytes_per_step", 0)) for r in rows) \
                if job == "automaton" else "-"
            gathered = "%.2f" % (max(r.get("gather_bytes", 0) for r in rows) / MiB) \
                if job == "automaton" else "-"
            print("| %s | %d | %d | %.0f | %.0f | %.0f (%s) | %.1f (%s) | %.1f (%s) | %.2f | %s | %s |"
                  % (name, n, max(r["points"] for r in rows), base, imported, max(peaks),
                     ", ".join("%.0f" % p for p in peaks), above, goal(whole), above_imported,
                     goal(whole_imported), max(r["seconds"] for r in rows), halo, gathered),
                  flush=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--make-vdb", metavar="FILE")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--table", action="store_true")
    parser.add_argument("--vdb")
    parser.add_argument("--automaton", type=int, nargs=3, metavar=("NX", "NY", "NZ"))
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4, 8])
    parser.add_argument("--breakdown", action="store_true")
    parser.add_argument("--piece", type=int, nargs=2, default=[0, 8], metavar=("P", "N"))
    parser.add_argument("--result-dir")
    parser.add_argument("--rank-job", choices=["baseline", "imported", "vdb", "automaton"])
    args = parser.parse_args()
    if args.make_vdb:
        make_vdb(args.make_vdb, args.size)
    elif args.breakdown:
        breakdown(args)
    elif args.rank_job:
        rank_job(args)
    elif args.table:
        table(args)
    else:
        parser.print_help()
        sys.exit(2)


if __name__ == "__main__":
    main()
