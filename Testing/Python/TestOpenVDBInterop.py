"""Interoperability of Nimbus's OpenVDB reader/writer with another producer and consumer:
Debian's python3-openvdb (``import pyopenvdb``, OpenVDB's own Python bindings).

1. pyopenvdb writes a file at test time — a dense float grid with a non-unit voxel size
   and an offset, a Vec3s velocity grid, and a sparse grid whose active voxels sit near
   index (10000, -5000, 3000) — and vtkNimbusOpenVDBReader must give every voxel's value
   at the world position pyopenvdb's transform gives it.
2. vtkNimbusOpenVDBWriter writes an image and pyopenvdb must read back the same values,
   transform, grid types and the fog-volume class.

Run with Debian's /usr/bin/python3 and PYTHONPATH=<build>/lib/python3.11/site-packages.
"""
import os
import sys
import tempfile

import numpy as np
import pyopenvdb as vdb

import nimbus
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkImageData

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message)


def image_array(image, name):
    """The named point array as a numpy array indexed [i, j, k(, c)]."""
    array = image.GetPointData().GetArray(name)
    assert array is not None, name
    ext = image.GetExtent()
    dims = (ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1)
    values = vtk_to_numpy(array)
    comps = array.GetNumberOfComponents()
    shape = (dims[2], dims[1], dims[0]) + ((comps,) if comps > 1 else ())
    values = values.reshape(shape)  # VTK: x fastest -> [k, j, i]
    return np.swapaxes(values, 0, 2) if comps == 1 else values.transpose(2, 1, 0, 3)


def test_read_pyopenvdb_file(tmp):
    path = os.path.join(tmp, "from-pyopenvdb.vdb")
    rng = np.random.default_rng(5)

    # Dense float grid: voxel size 0.37, translated, starting at index (3, -4, 5).
    voxel = 0.37
    shift = [12.5, -3.25, 100.0]
    matrix = [[voxel, 0, 0, 0], [0, voxel, 0, 0], [0, 0, voxel, 0], shift + [1]]
    dense = rng.uniform(0.1, 1.0, size=(12, 10, 8)).astype(np.float32)
    density = vdb.FloatGrid()
    density.name = "density"
    density.copyFromArray(dense, ijk=(3, -4, 5))
    density.transform = vdb.createLinearTransform(matrix)
    density.gridClass = vdb.GridClass.FOG_VOLUME

    velocity = vdb.Vec3SGrid()
    velocity.name = "velocity"
    vel = rng.uniform(-2, 2, size=(12, 10, 8, 3)).astype(np.float32)
    velocity.copyFromArray(vel, ijk=(3, -4, 5))
    velocity.transform = vdb.createLinearTransform(matrix)

    # Sparse grid far from the origin, voxel size 0.05.
    sparse = vdb.FloatGrid(background=0.0)
    sparse.name = "far"
    sparse.transform = vdb.createLinearTransform(voxelSize=0.05)
    acc = sparse.getAccessor()
    far_voxels = {}
    for n in range(40):
        ijk = (10000 + int(rng.integers(0, 30)), -5000 + int(rng.integers(0, 20)),
               3000 + int(rng.integers(0, 10)))
        value = float(rng.uniform(0.5, 2.0))
        acc.setValueOn(ijk, value)
        far_voxels[ijk] = np.float32(value)
    vdb.write(path, grids=[density, velocity, sparse])

    # density + velocity together (same transform): exact values at exact positions.
    reader = nimbus.vtkNimbusOpenVDBReader()
    reader.SetFileName(path)
    reader.UpdateInformation()
    reader.SetGridArrayStatus("far", 0)
    reader.Update()
    image = reader.GetOutput()
    reader_names = nimbus.vtkNimbusOpenVDBReader()
    reader_names.SetFileName(path)
    reader_names.UpdateInformation()
    names = sorted(reader_names.GetGridNames().GetValue(i)
                   for i in range(reader_names.GetGridNames().GetNumberOfValues()))
    check(names == ["density", "far", "velocity"], f"grid names {names}")
    check(image.GetExtent() == (3, 14, -4, 5, 5, 12), f"dense extent {image.GetExtent()}")
    got = image_array(image, "density")
    check(np.array_equal(got, dense), "dense float values differ from pyopenvdb's")
    got_vel = image_array(image, "velocity")
    check(np.array_equal(got_vel, vel), "Vec3s velocity values differ from pyopenvdb's")
    # World positions: measured identical (difference 0.0); atol 1e-12 allows a different
    # evaluation order of origin + i * spacing.
    for ijk in [(3, -4, 5), (14, 5, 12), (7, 0, 9)]:
        world_vdb = density.transform.indexToWorld(ijk)
        world_vtk = [0.0, 0.0, 0.0]
        image.TransformIndexToPhysicalPoint(list(ijk), world_vtk)
        check(np.allclose(world_vdb, world_vtk, rtol=0, atol=1e-12),
              f"world position of {ijk}: VDB {world_vdb} vs image {world_vtk}")
    # OpenVDB's own matrix -> scale-translate simplification rounds the voxel size
    # (0.37 -> 0.3699999999999992 here); the image must carry the file's value exactly.
    check(image.GetSpacing() == tuple(density.transform.voxelSize()),
          f"spacing {image.GetSpacing()} vs the file's {density.transform.voxelSize()}")
    check(np.allclose(image.GetSpacing(), voxel, rtol=1e-13, atol=0), f"spacing {image.GetSpacing()}")

    # The far sparse grid alone.
    reader = nimbus.vtkNimbusOpenVDBReader()
    reader.SetFileName(path)
    reader.UpdateInformation()
    reader.SetGridArrayStatus("density", 0)
    reader.SetGridArrayStatus("velocity", 0)
    reader.Update()
    far = reader.GetOutput()
    lo = np.min(np.array(list(far_voxels)), axis=0)
    hi = np.max(np.array(list(far_voxels)), axis=0)
    expected_extent = (lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
    check(far.GetExtent() == tuple(int(v) for v in expected_extent),
          f"far extent {far.GetExtent()} vs {expected_extent}")
    check(far.GetPointData().GetArray("density") is None, "deselected grid was read")
    values = image_array(far, "far")
    active = 0
    for ijk, value in far_voxels.items():
        local = tuple(ijk[c] - int(lo[c]) for c in range(3))
        check(values[local] == value, f"far voxel {ijk}: {values[local]} vs {value}")
        world_vdb = sparse.transform.indexToWorld(ijk)
        world_vtk = [0.0, 0.0, 0.0]
        far.TransformIndexToPhysicalPoint(list(ijk), world_vtk)
        check(np.allclose(world_vdb, world_vtk, rtol=1e-15, atol=1e-9),
              f"far world position {ijk}: {world_vdb} vs {world_vtk}")
        active += 1
    check(int(np.count_nonzero(values)) == len(far_voxels),
          f"far grid: {np.count_nonzero(values)} non-zero points, {len(far_voxels)} active voxels")
    print(f"read pyopenvdb file: dense {dense.shape}, velocity, {active} far voxels OK")


def test_pyopenvdb_reads_nimbus_file(tmp):
    path = os.path.join(tmp, "from-nimbus.vdb")
    image = vtkImageData()
    image.SetExtent(-2, 9, 0, 6, 4, 8)
    image.SetOrigin(-1.5, 2.0, 0.25)
    image.SetSpacing(0.2, 0.2, 0.2)
    n = image.GetNumberOfPoints()
    rng = np.random.default_rng(11)
    dens = rng.uniform(0.0, 1.0, n).astype(np.float32)
    dens[dens < 0.3] = 0.0  # sparse: inactive where 0
    arr = numpy_to_vtk(dens, deep=1)
    arr.SetName("density")
    image.GetPointData().AddArray(arr)
    velv = rng.uniform(-1, 1, (n, 3)).astype(np.float32)
    varr = numpy_to_vtk(velv, deep=1)
    varr.SetName("velocity")
    image.GetPointData().AddArray(varr)
    writer = nimbus.vtkNimbusOpenVDBWriter()
    writer.SetInputData(image)
    writer.SetFileName(path)
    check(writer.Write() == 1, "nimbus writer failed")

    grids, meta = vdb.readAll(path)
    by_name = {g.name: g for g in grids}
    check(sorted(by_name) == ["density", "velocity"], f"grids {sorted(by_name)}")
    d = by_name["density"]
    check(d.gridClass == vdb.GridClass.FOG_VOLUME, f"density class {d.gridClass}")
    check(d.valueTypeName == "float", d.valueTypeName)
    check(by_name["velocity"].valueTypeName == "vec3s", by_name["velocity"].valueTypeName)
    check(d.activeVoxelCount() == int(np.count_nonzero(dens)),
          f"active voxels {d.activeVoxelCount()} vs {np.count_nonzero(dens)}")
    dims = (12, 7, 5)
    out = np.zeros(dims, dtype=np.float32)
    d.copyToArray(out, ijk=(-2, 0, 4))
    check(np.array_equal(out, image_array(image, "density")), "pyopenvdb density differs")
    vout = np.zeros(dims + (3,), dtype=np.float32)
    by_name["velocity"].copyToArray(vout, ijk=(-2, 0, 4))
    check(np.array_equal(vout, image_array(image, "velocity")), "pyopenvdb velocity differs")
    for ijk in [(-2, 0, 4), (9, 6, 8)]:
        world = [0.0, 0.0, 0.0]
        image.TransformIndexToPhysicalPoint(list(ijk), world)
        check(np.allclose(d.transform.indexToWorld(ijk), world, rtol=0, atol=1e-12),
              f"transform at {ijk}: {d.transform.indexToWorld(ijk)} vs {world}")
    print(f"pyopenvdb read the nimbus file: {d.activeVoxelCount()} active density voxels OK")


def main():
    with tempfile.TemporaryDirectory(prefix="nimbus-vdb-interop-") as tmp:
        test_read_pyopenvdb_file(tmp)
        test_pyopenvdb_reads_nimbus_file(tmp)
    if failures:
        print(f"{len(failures)} failure(s)")
        return 1
    print("OpenVDB interop OK (pyopenvdb", ".".join(map(str, vdb.LIBRARY_VERSION)), ")")
    return 0


if __name__ == "__main__":
    sys.exit(main())
