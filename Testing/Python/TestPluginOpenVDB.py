"""pvpython test: the Nimbus plugin's OpenVDB writer and reader through ParaView.

    pvpython TestPluginOpenVDB.py --plugin Nimbus.so --output-dir DIR

LoadPlugin, then SaveData('x.vdb') of a Wavelet image with a scalar and a vector array
(ParaView picks the writer from the WriterFactory hint), then OpenDataFile('x.vdb')
(the ReaderFactory hint) and a comparison of the fetched arrays with the originals
(float32-rounded: the writer stores floats), of extent, origin and spacing, and of the
grid selection list; then the Up Axis property (its five choices on the reader the user
sees, Auto on Nimbus's own file, +Y turning the image, a file whose creator names Houdini
opening y up); then a numbered series of three files opened as one reader with time steps
0, 1, 2, each step with its own extent.
"""
import argparse
import os
import subprocess
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import (Calculator, Delete, LoadPlugin, OpenDataFile, SaveData,
                             Wavelet)
from vtkmodules.util.numpy_support import vtk_to_numpy


UP_AXIS_CHOICES = [("Auto (from the file)", -1), ("+X", 0), ("+Y", 1), ("+Z", 2), ("-Y", 3)]

# A y-up file as Houdini's File SOP writes it (file metadata "creator" =
# "Houdini <version>/GEO_VDBTranslator"), written by Debian's pyopenvdb in its own process
# (pvpython must not load a second libopenvdb before the plugin's).
HOUDINI_FILE_SCRIPT = """
import sys
import numpy as np
import pyopenvdb as vdb
grid = vdb.FloatGrid()
grid.name = "density"
values = np.arange(1, 4 * 6 * 8 + 1, dtype=np.float32).reshape(4, 6, 8)
grid.copyFromArray(values, ijk=(0, 0, 0))
grid.transform = vdb.createLinearTransform(voxelSize=3.33)
vdb.write(sys.argv[1], grids=[grid],
          metadata={"creator": "Houdini 20.5.278/GEO_VDBTranslator"})
"""


def up_axis_source(image):
    array = image.GetFieldData().GetAbstractArray("nimbus_up_axis_source")
    return array.GetValue(0) if array is not None and array.GetNumberOfValues() == 1 else None


def check_up_axis(reader, source, output_dir):
    """Up Axis on the reader proxy (not advanced, five choices), what Auto decided on the
    writer's file, the image turned +Y up, and a Houdini file opened y up by Auto."""
    failures = []
    prop = reader.GetProperty("UpAxis")
    if prop is None:
        return ["the reader has no UpAxis property"]
    if prop.SMProperty.GetPanelVisibility() != "default":
        failures.append(f"UpAxis panel visibility {prop.SMProperty.GetPanelVisibility()}")
    domain = prop.SMProperty.FindDomain("vtkSMEnumerationDomain")
    entries = [(domain.GetEntryText(i), domain.GetEntryValue(i))
               for i in range(domain.GetNumberOfEntries())] if domain else None
    if entries != UP_AXIS_CHOICES:
        failures.append(f"UpAxis choices {entries}")
    if prop.SMProperty.GetElement(0) != -1:
        failures.append(f"UpAxis default {prop.SMProperty.GetElement(0)}, expected -1 (Auto)")

    # Nimbus's writer writes up_axis = +Z: Auto reads it.
    reader.UpdatePipeline()
    reader.UpdatePropertyInformation()
    said = reader.GetProperty("UpAxisSource").GetData()
    fetched = up_axis_source(servermanager.Fetch(reader))
    if said != "+Z (file metadata up_axis = '+Z')" or fetched != said:
        failures.append(f"Auto on the writer's file: UpAxisSource {said!r}, field data {fetched!r}")

    # +Y: U = (x, -z, y): extent [-10,10] x [-6,6] x [-8,8]; point (i, j, k) of the source is
    # point (i, -k, j); velocity (vx, vy, vz) becomes (vx, -vz, vy).
    reader.UpAxis = "+Y"
    reader.UpdatePipeline()
    turned = servermanager.Fetch(reader)
    if turned.GetExtent() != (-10, 10, -6, 6, -8, 8):
        failures.append(f"+Y extent {turned.GetExtent()}")
    if up_axis_source(turned) != "+Y (chosen)":
        failures.append(f"+Y field data {up_axis_source(turned)!r}")
    dims = (13, 17, 21)  # source (z, y, x) points
    for name in ("RTData", "velocity"):
        a = vtk_to_numpy(source.GetPointData().GetArray(name)).astype(np.float32)
        a = a.reshape(dims + ((3,) if a.ndim == 2 else ()))
        expected = a.transpose((1, 0, 2) + ((3,) if a.ndim == 4 else ()))[:, ::-1, :]
        if a.ndim == 4:
            expected = np.stack([expected[..., 0], -expected[..., 2], expected[..., 1]], -1)
        b_array = turned.GetPointData().GetArray(name)
        b = vtk_to_numpy(b_array).reshape(expected.shape) if b_array is not None else None
        if b is None or not np.array_equal(b, expected):
            failures.append(f"+Y: {name} is not the source turned by hand")
    reader.UpAxis = "Auto (from the file)"

    # A file whose creator names Houdini opens y up.
    houdini = os.path.join(output_dir, "paraview_houdini_creator.vdb")
    python = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
    done = subprocess.run([python, "-c", HOUDINI_FILE_SCRIPT, houdini],
                          capture_output=True, text=True)
    if done.returncode != 0:
        return failures + [f"writing {houdini} with pyopenvdb failed: {done.stderr}"]
    cloud = OpenDataFile(houdini)
    cloud.UpdatePipeline()
    cloud.UpdatePropertyInformation()
    image = servermanager.Fetch(cloud)
    expected_source = "+Y (creator 'Houdini 20.5.278/GEO_VDBTranslator')"
    if cloud.GetProperty("UpAxisSource").GetData() != expected_source or \
            up_axis_source(image) != expected_source:
        failures.append(f"Houdini file: {cloud.GetProperty('UpAxisSource').GetData()!r}")
    # File x 0..3, y 0..5, z 0..7 -> turned x 0..3, y -7..0, z 0..5; spacing 3.33.
    if image.GetExtent() != (0, 3, -7, 0, 0, 5):
        failures.append(f"Houdini file extent {image.GetExtent()}")
    bounds = image.GetBounds()
    if not np.allclose(bounds, (0, 9.99, -23.31, 0, 0, 16.65), rtol=0, atol=1e-9):
        failures.append(f"Houdini file bounds {bounds}")
    Delete(cloud)
    return failures


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output-dir", required=True)
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    path = os.path.join(args.output_dir, "paraview_wavelet.vdb")
    if os.path.exists(path):
        os.remove(path)

    LoadPlugin(args.plugin, ns=globals())
    wavelet = Wavelet(WholeExtent=[-10, 10, -8, 8, -6, 6])
    calc = Calculator(Input=wavelet, ResultArrayName="velocity",
                      Function="coordsX*iHat + RTData*jHat - 2*kHat")
    source = servermanager.Fetch(calc)
    SaveData(path, proxy=calc, Tolerance=0.0)
    if not os.path.exists(path):
        print("SaveData wrote nothing at", path)
        return 1

    reader = OpenDataFile(path)
    if reader is None or reader.GetXMLName() != "NimbusOpenVDBReader":
        print("OpenDataFile did not pick the Nimbus reader:", reader and reader.GetXMLName())
        return 1
    grids = list(reader.GetProperty("GridInfo")[::2])
    if sorted(grids) != ["RTData", "velocity"]:
        print("grid list:", grids)
        return 1
    reader.UpdatePipeline()
    result = servermanager.Fetch(reader)
    failures = []
    if result.GetExtent() != source.GetExtent():
        failures.append(f"extent {result.GetExtent()} vs {source.GetExtent()}")
    if result.GetOrigin() != source.GetOrigin() or result.GetSpacing() != source.GetSpacing():
        failures.append(f"origin/spacing {result.GetOrigin()} {result.GetSpacing()} vs "
                        f"{source.GetOrigin()} {source.GetSpacing()}")
    for name in ("RTData", "velocity"):
        a = vtk_to_numpy(source.GetPointData().GetArray(name)).astype(np.float32)
        b_array = result.GetPointData().GetArray(name)
        if b_array is None:
            failures.append(f"no array {name} after reading")
            continue
        b = vtk_to_numpy(b_array)
        if a.shape != b.shape or not np.array_equal(a, b):
            failures.append(f"{name} differs (max {np.max(np.abs(a - b)) if a.shape == b.shape else a.shape})")

    # BoundsGrid: a drop-down of "(union)" and the grid names.
    domain = reader.GetProperty("BoundsGrid").SMProperty.FindDomain("vtkSMStringListDomain")
    choices = [domain.GetString(i) for i in range(domain.GetNumberOfStrings())]
    if choices != ["(union)", "RTData", "velocity"]:
        failures.append(f"BoundsGrid choices {choices}")
    reader.BoundsGrid = "velocity"
    reader.UpdatePipeline()
    if reader.GetDataInformation().GetNumberOfPoints() != source.GetNumberOfPoints():
        failures.append("BoundsGrid='velocity' changed the image")
    reader.BoundsGrid = "(union)"

    # Grid selection: only RTData.
    reader.Grids = ["RTData"]
    reader.UpdatePipeline()
    only = servermanager.Fetch(reader)
    if only.GetPointData().GetArray("velocity") is not None or \
            only.GetPointData().GetArray("RTData") is None:
        failures.append("grid selection Grids=['RTData'] not honoured")
    reader.Grids = ["RTData", "velocity"]
    failures.extend(check_up_axis(reader, source, args.output_dir))
    Delete(reader)

    # A numbered series is one reader with time steps; each step has its own extent
    # (a cloud that moves or grows changes its active bounding box).
    series = []
    for step, half in enumerate((3, 5, 7)):
        w = Wavelet(WholeExtent=[-half, half, -half, half, -half, half])
        name = os.path.join(args.output_dir, f"paraview_series_{step}.vdb")
        SaveData(name, proxy=w)
        series.append(name)
        Delete(w)
    animated = OpenDataFile(series)
    steps = list(animated.TimestepValues)
    if steps != [0.0, 1.0, 2.0]:
        failures.append(f"file series time steps {steps}")
    for step, half in enumerate((3, 5, 7)):
        animated.UpdatePipeline(time=float(step))
        points = animated.GetDataInformation().GetNumberOfPoints()
        if points != (2 * half + 1) ** 3:
            failures.append(f"series step {step}: {points} points, expected {(2 * half + 1) ** 3}")
    for f in failures:
        print("FAIL:", f)
    if failures:
        return 1
    print(f"pvpython SaveData/OpenDataFile round trip OK: {result.GetNumberOfPoints()} points, "
          f"{os.path.getsize(path)} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
