"""pvpython test: the Nimbus plugin's OpenVDB writer and reader through ParaView.

    pvpython TestPluginOpenVDB.py --plugin Nimbus.so --output-dir DIR

LoadPlugin, then SaveData('x.vdb') of a Wavelet image with a scalar and a vector array
(ParaView picks the writer from the WriterFactory hint), then OpenDataFile('x.vdb')
(the ReaderFactory hint) and a comparison of the fetched arrays with the originals
(float32-rounded: the writer stores floats), of extent, origin and spacing, and of the
grid selection list; then a numbered series of three files opened as one reader with
time steps 0, 1, 2, each step with its own extent.
"""
import argparse
import os
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import (Calculator, Delete, LoadPlugin, OpenDataFile, SaveData,
                             Wavelet)
from vtkmodules.util.numpy_support import vtk_to_numpy


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
