"""MPI test (data parallel, docs/parallel.md): the pieces of every Nimbus field source, assembled,
equal the serial output bit for bit.

    mpiexec -n N pvbatch --symmetric --force-offscreen-rendering TestParallelPieces.py \
        [--output-dir DIR]

(PYTHONPATH must reach the nimbus package.) Every rank runs the script. For each source
(metaball cloud, cloud automaton, image cloud from a synthetic image, smoke, the OpenVDB
reader on a .vdb written by the project's writer) and for 0 and 1 ghost levels, each rank
updates piece (rank, N) and sends its output to rank 0, which checks:

- the piece's extent is VTK's block of the whole extent for that piece grown by the ghost
  levels and clamped (vtkExtentTranslator, the executive's own split);
- the layers outside the piece's own block, and only those, are marked in vtkGhostType
  (DUPLICATEPOINT on points, DUPLICATECELL on cells), and there are none without ghosts;
- the pieces' own cells cover every cell of the whole extent exactly once; their own
  points cover every point (pieces share the points on their common faces: those copies
  must be identical);
- the assembled arrays (every point array but vtkGhostType, and the field data) equal a
  serial Update() of an identical source on rank 0: same names, dtype and bytes
  (numpy.array_equal).

Every rank exits non-zero when any check failed on any rank (an AllReduce of the failure
flag, so no rank waits for another).
"""
import argparse
import os
import sys
import tempfile
import traceback

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkFloatArray, vtkIntArray
from vtkmodules.vtkCommonDataModel import vtkDataSetAttributes, vtkImageData
from vtkmodules.vtkCommonExecutionModel import vtkExtentTranslator
from vtkmodules.vtkParallelCore import vtkCommunicator, vtkMultiProcessController

import nimbus

CONTROLLER = vtkMultiProcessController.GetGlobalController()
RANK = CONTROLLER.GetLocalProcessId()
SIZE = CONTROLLER.GetNumberOfProcesses()
GHOST = vtkDataSetAttributes.GhostArrayName()
TAG = 4718


def metaballs():
    s = nimbus.vtkNimbusMetaballCloudSource()
    s.SetDimensions(26, 23, 19)
    s.SetNumberOfLevels(2)
    s.SetBallsPerLevel(30)
    s.SetSeed(5)
    return s, None


def automaton():
    s = nimbus.vtkNimbusCloudAutomatonSource()
    s.SetDimensions(28, 22, 10)
    s.SetSpinUpSteps(12)
    s.SetStepDuration(2.0)
    s.SetNumberOfTimeSteps(4)
    s.SetSeed(7)
    s.SetWind(1.3, -0.6)
    return s, 3.0  # between steps 1 and 2: the interpolation is tested too


def automaton_periodic():
    """Periodic sides (the slabs' rows wrap in x and y), wind and shear across the pieces,
    a width that is no multiple of 64 cells, no formation regions (uniform probabilities)."""
    s = nimbus.vtkNimbusCloudAutomatonSource()
    s.SetDimensions(70, 19, 12)
    s.SetPeriodicBoundary(True)
    s.SetNumberOfFormationRegions(0)
    s.SetInitialHumidity(0.3)
    s.SetInitialActivation(0.01)
    s.SetSpinUpSteps(9)
    s.SetStepDuration(1.0)
    s.SetNumberOfTimeSteps(3)
    s.SetSeed(11)
    s.SetWind(900.0, -450.0)  # m/s over 200 m cells: several cells per step
    s.SetShear(2.0, 1.0)
    return s, 1.5


def automaton_maps():
    """Probability maps as input (3-D p_hum and p_ext): each rank uses its layers of them."""
    s, time = automaton()
    maps = vtkImageData()
    maps.SetDimensions(28, 22, 10)
    for name, scale in (("p_hum", 0.2), ("p_ext", 0.1)):
        values = vtkFloatArray()
        values.SetName(name)
        values.SetNumberOfTuples(28 * 22 * 10)
        for i in range(28 * 22 * 10):
            values.SetValue(i, scale * ((i * 37) % 11) / 10.0)
        maps.GetPointData().AddArray(values)
    s.SetInputData(maps)
    return s, time


def synthetic_image():
    image = vtkImageData()
    image.SetDimensions(22, 17, 1)
    values = vtkFloatArray()
    values.SetName("intensity")
    values.SetNumberOfTuples(22 * 17)
    for j in range(17):
        for i in range(22):
            r2 = ((i - 9.0) / 6.0) ** 2 + ((j - 8.0) / 5.0) ** 2
            values.SetValue(j * 22 + i, 250.0 * max(0.0, 1.0 - r2) + 3.0 * ((i * 7 + j * 3) % 5))
    image.GetPointData().SetScalars(values)
    return image


def image_cloud():
    s = nimbus.vtkNimbusImageCloudFilter()
    s.SetInputData(synthetic_image())
    s.SetPixelSize(40.0)
    s.SetVerticalSpacing(40.0)
    s.SetSeed(3)
    return s, None


def smoke():
    s = nimbus.vtkNimbusSmokeSource()
    s.SetDimensions(10, 9, 14)
    s.SetCellSizeMetres(0.4)
    s.SetOrigin(-2.0, -1.8, 0.0)
    s.SetEmitterCentre(0.0, 0.0, 0.8)
    s.SetEmitterRadiusMetres(0.7)
    s.SetNumberOfFrames(4)
    s.SetNumberOfThreads(1)
    return s, 2.0 * s.GetFrameDurationSeconds()


def vdb_reader(path, bounds_grid=None):
    def make():
        s = nimbus.vtkNimbusOpenVDBReader()
        s.SetFileName(path)
        if bounds_grid:
            s.SetBoundsGrid(bounds_grid)
        return s, None
    return make


def write_vdb(path):
    """A .vdb with a scalar grid whose active box is smaller than the image (an extent that
    does not start at 0), a dense scalar grid and a vector grid: the smoke's frame 2."""
    source, time = smoke()
    source.UpdateTimeStep(time)
    writer = nimbus.vtkNimbusOpenVDBWriter()
    writer.SetInputData(source.GetOutput())
    writer.SetFileName(path)
    if not writer.Write():
        raise RuntimeError("could not write " + path)


def update(algorithm, time, piece, pieces, ghosts):
    if time is None:
        if piece is None:
            algorithm.Update()
        else:
            algorithm.UpdatePiece(piece, pieces, ghosts)
    elif piece is None:
        algorithm.UpdateTimeStep(time)
    else:
        algorithm.UpdateTimeStep(time, piece, pieces, ghosts)
    output = vtkImageData()
    output.ShallowCopy(algorithm.GetOutputDataObject(0))
    return output


def geometry_values(image):
    """Extent, origin, spacing and direction matrix (row-major) of an image, as doubles."""
    direction = image.GetDirectionMatrix()
    return ([float(e) for e in image.GetExtent()] + list(image.GetOrigin()) +
            list(image.GetSpacing()) +
            [direction.GetElement(r, c) for r in range(3) for c in range(3)])


def geometry(image):
    array = vtkDoubleArray()
    for value in geometry_values(image):
        array.InsertNextValue(value)
    return array


def block(whole, piece, pieces, ghosts):
    extent = [0] * 6
    translator = vtkExtentTranslator()
    translator.PieceToExtentThreadSafe(piece, pieces, ghosts, list(whole), extent,
                                       vtkExtentTranslator.BLOCK_MODE, 0)
    return extent


def box_slices(extent, origin_extent, cells):
    """Index slices (z, y, x) of `extent` inside an array laid out over `origin_extent`."""
    d = 1 if cells else 0
    return tuple(slice(extent[2 * a] - origin_extent[2 * a],
                       extent[2 * a + 1] - origin_extent[2 * a] + 1 - d) for a in (2, 1, 0))


def shape(extent, cells):
    d = 1 if cells else 0
    return tuple(max(0, extent[2 * a + 1] - extent[2 * a] + 1 - d) for a in (2, 1, 0))


def arrays(attributes):
    result = {}
    for i in range(attributes.GetNumberOfArrays()):
        array = attributes.GetArray(i)
        if array is not None and array.GetName() != GHOST:
            result[array.GetName()] = vtk_to_numpy(array)
    return result


def check_case(name, make, ghosts, all_errors):
    """Runs one case on every rank; rank 0 collects and checks. Appends to all_errors."""
    errors = []
    try:
        check_pieces(name, make, ghosts, errors)
    except Exception:  # a failure, not a hang: every rank still reaches the AllReduce
        errors.append("%s, %d ghost level(s): rank %d: %s"
                      % (name, ghosts, RANK, traceback.format_exc()))
    all_errors.extend(errors)


def check_pieces(name, make, ghosts, errors):
    def fail(message):
        errors.append("%s, %d ghost level(s): %s" % (name, ghosts, message))

    try:
        algorithm, time = make()
        piece_output = update(algorithm, time, RANK, SIZE, ghosts)
        if hasattr(algorithm, "GetOwnedLayers") and SIZE > 1:
            # The automaton's ranks share it by layers: this rank stepped only its slab.
            owned = algorithm.GetOwnedLayers()
            nz = algorithm.GetDimensions()[2]
            if owned[1] - owned[0] >= nz or algorithm.GetHaloBytesPerStep() <= 0:
                fail("rank %d ran the whole automaton (layers %s of %d, %d halo bytes per step)"
                     % (RANK, list(owned), nz, algorithm.GetHaloBytesPerStep()))
    except Exception:  # still send, so that rank 0 does not wait forever
        fail("rank %d: %s" % (RANK, traceback.format_exc()))
        piece_output = vtkImageData()
    if RANK != 0:
        # The geometry travels apart: the data object's transport (VTK's legacy format)
        # writes origin and spacing as text with 6 digits.
        CONTROLLER.Send(geometry(piece_output), 0, TAG)
        CONTROLLER.Send(piece_output, 0, TAG + 1)
        return
    geometries = [geometry(piece_output)]
    outputs = [piece_output]
    for r in range(1, SIZE):
        g = vtkDoubleArray()
        CONTROLLER.Receive(g, r, TAG)
        geometries.append(g)
        outputs.append(CONTROLLER.ReceiveDataObject(r, TAG + 1))
    if errors:
        return
    serial_algorithm, serial_time = make()
    serial = update(serial_algorithm, serial_time, None, 1, 0)
    whole = serial.GetExtent()
    if serial.GetNumberOfPoints() == 0:
        fail("the serial output is empty")
        return
    expected = arrays(serial.GetPointData())
    if not any(np.any(a != 0) for a in expected.values()):
        fail("the serial output is all zero: the comparison would prove nothing")
    assembled = {n: np.zeros(shape(whole, False) + a.shape[1:], a.dtype)
                 for n, a in expected.items()}
    point_count = np.zeros(shape(whole, False), np.int32)
    cell_count = np.zeros(shape(whole, True), np.int32)
    for piece, (out, g) in enumerate(zip(outputs, geometries)):
        own = block(whole, piece, SIZE, 0)
        grown = block(whole, piece, SIZE, ghosts)
        extent = [int(g.GetValue(i)) for i in range(6)]
        if extent != list(out.GetExtent()):
            fail("piece %d: extent %s sent, %s received" % (piece, extent, out.GetExtent()))
        if extent != grown:
            fail("piece %d has extent %s, expected %s (piece %s grown by %d, clamped)"
                 % (piece, extent, grown, own, ghosts))
            continue
        if [g.GetValue(i) for i in range(6, 21)] != geometry_values(serial)[6:]:
            fail("piece %d: origin, spacing, direction %s differ from the serial %s"
                 % (piece, [g.GetValue(i) for i in range(6, 21)], geometry_values(serial)[6:]))
        # Ghost marks: exactly the layers outside the piece's own block.
        own_points = np.zeros(shape(extent, False), bool)
        own_points[box_slices(own, extent, False)] = True
        own_cells = np.zeros(shape(extent, True), bool)
        own_cells[box_slices(own, extent, True)] = True
        for what, attributes, mask, bit in (
                ("point", out.GetPointData(), own_points, vtkDataSetAttributes.DUPLICATEPOINT),
                ("cell", out.GetCellData(), own_cells, vtkDataSetAttributes.DUPLICATECELL)):
            ghost = attributes.GetArray(GHOST)
            if ghost is None:
                if ghosts > 0 and not mask.all():
                    fail("piece %d has ghost %ss but no %s array" % (piece, what, GHOST))
                continue
            marked = (vtk_to_numpy(ghost).reshape(mask.shape) & bit) != 0
            if not np.array_equal(marked, ~mask):
                fail("piece %d: %d %ss marked as ghosts, %d expected (or not the same ones)"
                     % (piece, int(marked.sum()), what, int((~mask).sum())))
        if ghosts == 0 and extent != own:
            fail("piece %d without ghost levels is not its own block" % piece)
        # The piece's own points and cells, placed in the whole.
        cell_count[box_slices(own, whole, True)] += 1
        target = box_slices(own, whole, False)
        point_count[target] += 1
        got = arrays(out.GetPointData())
        if set(got) != set(expected):
            fail("piece %d has arrays %s, the serial output %s"
                 % (piece, sorted(got), sorted(expected)))
            continue
        for n, values in got.items():
            if values.dtype != expected[n].dtype:
                fail("piece %d: array %s is %s, serially %s"
                     % (piece, n, values.dtype, expected[n].dtype))
                continue
            values = values.reshape(shape(extent, False) + values.shape[1:])
            mine = values[box_slices(own, extent, False)]
            shared = point_count[target] > 1  # filled by an earlier piece too
            if not np.array_equal(assembled[n][target][shared], mine[shared]):
                fail("piece %d: array %s differs from a neighbour on their shared points"
                     % (piece, n))
            assembled[n][target] = mine
        serial_fields = arrays(serial.GetFieldData())
        piece_fields = arrays(out.GetFieldData())
        for n, values in serial_fields.items():
            if n not in piece_fields or not np.array_equal(piece_fields[n], values):
                fail("piece %d: field data %s differs from the serial one" % (piece, n))
    if errors:
        return
    if not np.all(cell_count == 1):
        fail("cells covered 0 times: %d, more than once: %d"
             % (int((cell_count == 0).sum()), int((cell_count > 1).sum())))
    if not np.all(point_count >= 1):
        fail("%d points covered by no piece" % int((point_count == 0).sum()))
    for n, values in expected.items():
        if not np.array_equal(assembled[n].reshape(values.shape), values):
            differing = int(np.sum(assembled[n].reshape(values.shape) != values))
            fail("assembled array %s differs from the serial output (%d values)"
                 % (n, differing))
    print("%s, %d ghost level(s), %d pieces: extent %s, arrays %s: bit-identical"
          % (name, ghosts, SIZE, list(whole), sorted(expected)), flush=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--output-dir", default=None)
    args = parser.parse_args()

    errors = []
    directory = args.output_dir or tempfile.gettempdir()
    vdb_path = os.path.join(directory, "parallel_pieces_%d.vdb" % SIZE)
    if RANK == 0:
        try:
            os.makedirs(directory, exist_ok=True)
            write_vdb(vdb_path)
        except Exception:
            errors.append("writing the .vdb: " + traceback.format_exc())
    CONTROLLER.Barrier()

    cases = [("metaball cloud", metaballs), ("cloud automaton", automaton),
             ("cloud automaton, periodic", automaton_periodic),
             ("cloud automaton, probability maps", automaton_maps),
             ("image cloud", image_cloud), ("smoke", smoke),
             ("OpenVDB reader", vdb_reader(vdb_path)),
             ("OpenVDB reader, density's box", vdb_reader(vdb_path, "density"))]
    for name, make in cases:
        for ghosts in (0, 1):
            check_case(name, make, ghosts, errors)

    for e in errors:
        print("FAILED (rank %d): %s" % (RANK, e), flush=True)
    flag = vtkIntArray()
    flag.InsertNextValue(1 if errors else 0)
    total = vtkIntArray()
    CONTROLLER.AllReduce(flag, total, vtkCommunicator.MAX_OP)
    if RANK == 0 and os.path.exists(vdb_path):
        os.remove(vdb_path)
    if total.GetValue(0) != 0:
        if RANK == 0:
            print("TestParallelPieces: FAILED", flush=True)
        sys.exit(1)  # every rank: mpiexec then exits non-zero
    if RANK == 0:
        print("TestParallelPieces: all %d cases bit-identical on %d ranks"
              % (2 * len(cases), SIZE), flush=True)
    # Success ends the script normally (no sys.exit(0)): pvbatch then finalizes MPI.


if __name__ == "__main__":
    main()
