"""MPI test: a rank that reads its piece of a .vdb holds the piece, not the whole file.

    python3 TestParallelVdbMemory.py --write FILE [--size S]          (the fixture)
    mpiexec -n N pvbatch --symmetric TestParallelVdbMemory.py --read FILE [--size S]

(PYTHONPATH must reach the nimbus package.) --write makes an S x S x S float grid with every
voxel active (noise in [0.1, 1): the tree is dense and Blosc hardly compresses it), written by
vtkNimbusOpenVDBWriter. --read: every rank resets its peak resident memory (5 into
/proc/self/clear_refs), reads its piece with 1 ghost level (UpdatePiece(rank, N, 1)) and takes
the growth of VmHWM over the resident memory before the read. With W = 4 S^3 bytes (the whole
grid as floats) and P the piece's bytes, a piece read costs its output array (P), its ghost
levels' vtkGhostType array (P / 4), the topology that touches the piece (no leaves: each leaf's
values go into the output as they are read) and the first read's fixed cost (OpenVDB's and
Blosc's code and tables; with the ghost array about 10 MiB beside P measured here: 26.4 MiB for
a piece of 16.3 MiB of a 256^3 grid on 4 ranks);
a read that held the piece's leaves as a tree (as the reader did before) costs P more, and a
rank that read the whole file (as the reader did before clipped reads) held the whole tree (W)
and the file's bytes (about W here) besides its piece. The test fails when a rank's growth
exceeds

    limit = 1.5 P + 12 MiB

and, as a check of the measurement itself, when a whole read (piece 0 of 1, by the last rank
after its piece) does not exceed the limit; that rank's piece must also equal the whole read's
crop bit for bit. Every rank prints its figures; every rank exits
non-zero when a check failed on any rank.
"""
import argparse
import os
import sys


def vm_status(field):
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1]) * 1024  # kB -> bytes
    raise RuntimeError("no %s in /proc/self/status" % field)


def reset_peak():
    """VmHWM back to the current resident memory (Linux >= 4.0); the baseline."""
    with open("/proc/self/clear_refs", "w") as clear:
        clear.write("5")
    return vm_status("VmRSS")


def write(path, size):
    import numpy as np
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData

    import nimbus

    rng = np.random.default_rng(7)
    values = rng.uniform(0.1, 1.0, size ** 3).astype(np.float32)
    image = vtkImageData()
    image.SetDimensions(size, size, size)
    image.SetSpacing(10.0, 10.0, 10.0)
    array = numpy_to_vtk(values, deep=1)
    array.SetName("density")
    image.GetPointData().SetScalars(array)
    writer = nimbus.vtkNimbusOpenVDBWriter()
    writer.SetInputData(image)
    writer.SetFileName(path)
    if not writer.Write():
        raise SystemExit("could not write " + path)
    print("wrote %s: %d^3 float voxels, all active" % (path, size))


def read(path, size):
    from vtkmodules.vtkCommonCore import vtkIntArray
    from vtkmodules.vtkParallelCore import vtkCommunicator, vtkMultiProcessController

    import nimbus

    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId()
    ranks = controller.GetNumberOfProcesses()
    MiB = 1024.0 * 1024.0
    whole = 4.0 * size ** 3
    errors = []

    def growth(piece, pieces, ghosts):
        reader = nimbus.vtkNimbusOpenVDBReader()
        reader.SetFileName(path)
        reader.UpdateInformation()
        before = reset_peak()
        reader.UpdatePiece(piece, pieces, ghosts)
        peak = vm_status("VmHWM") - before
        return reader, peak, 4.0 * reader.GetOutput().GetNumberOfPoints()

    try:
        reader, peak, piece_bytes = growth(rank, ranks, 1)
        limit = 1.5 * piece_bytes + 12.0 * MiB
        print("rank %d of %d: piece %.1f MiB (whole %.1f MiB), peak growth %.1f MiB, limit %.1f MiB"
              % (rank, ranks, piece_bytes / MiB, whole / MiB, peak / MiB, limit / MiB),
              flush=True)
        if piece_bytes <= 0 or piece_bytes >= whole:
            errors.append("rank %d: a piece of %.1f MiB is no piece of %.1f MiB"
                          % (rank, piece_bytes / MiB, whole / MiB))
        if peak > limit:
            errors.append("rank %d: reading its piece grew the peak memory by %.1f MiB, more "
                          "than %.1f MiB: it read more than its piece (the whole file?)"
                          % (rank, peak / MiB, limit / MiB))
        if rank == ranks - 1:
            piece = reader.GetOutput()
            whole_reader, whole_peak, _ = growth(0, 1, 0)
            # The piece (only the topology that touches it read) equals the whole read's crop
            # bit for bit.
            import numpy as np
            from vtkmodules.util.numpy_support import vtk_to_numpy
            full = whole_reader.GetOutput()
            e, w = piece.GetExtent(), full.GetExtent()
            dims = [w[2 * a + 1] - w[2 * a] + 1 for a in range(3)]
            cube = vtk_to_numpy(full.GetPointData().GetArray("density")).reshape(dims[::-1])
            crop = cube[e[4] - w[4]:e[5] - w[4] + 1, e[2] - w[2]:e[3] - w[2] + 1,
                        e[0] - w[0]:e[1] - w[0] + 1]
            mine = vtk_to_numpy(piece.GetPointData().GetArray("density")).reshape(crop.shape)
            if not np.array_equal(mine, crop):
                errors.append("rank %d: its piece differs from the whole read's crop in %d values"
                              % (rank, int(np.sum(mine != crop))))
            print("rank %d: a whole read grew the peak by %.1f MiB (must exceed %.1f MiB)"
                  % (rank, whole_peak / MiB, limit / MiB), flush=True)
            if whole_peak <= limit:
                errors.append("rank %d: a whole read grew the peak by only %.1f MiB, not more "
                              "than the limit %.1f MiB: the measurement cannot tell"
                              % (rank, whole_peak / MiB, limit / MiB))
    except Exception as e:  # still reach the AllReduce
        errors.append("rank %d: %r" % (rank, e))
    for e in errors:
        print("FAILED: " + e, flush=True)
    flag, total = vtkIntArray(), vtkIntArray()
    flag.InsertNextValue(1 if errors else 0)
    controller.AllReduce(flag, total, vtkCommunicator.MAX_OP)
    if rank == 0:
        os.remove(path)  # 64 MiB; the fixture writes it again
    if total.GetValue(0):
        sys.exit(1)
    if rank == 0:
        print("TestParallelVdbMemory: every rank held only its piece", flush=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--write", metavar="FILE")
    parser.add_argument("--read", metavar="FILE")
    parser.add_argument("--size", type=int, default=256)
    args = parser.parse_args()
    if args.write:
        write(args.write, args.size)
    if args.read:
        read(args.read, args.size)


if __name__ == "__main__":
    main()
