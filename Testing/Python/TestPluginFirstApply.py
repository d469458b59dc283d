"""pvpython test: what the first Apply shows for each Nimbus source and filter (docs/paraview.md).

    pvpython TestPluginFirstApply.py --plugin Nimbus.so --image Data/SatelliteClouds.png \
        [--output-dir DIR]

Shows each cloud source's output as ParaView shows it on Apply (the controller's default
representation and the XML hints) and checks:
- Nimbus Metaball Cloud, Cloud Automaton (With Maps) and Image Cloud come up as "Cloud",
  coloured Solid Color (the Cloud representation renders the active scalars: no colour map,
  so no legend);
- the metaballs (metaball source, port 1) and the optical-depth maps (image cloud, port 1)
  are not shown on Apply;
- the image cloud takes the sample PNG as ParaView's default reader gives it (GDAL: pixels as
  a cell array "Elevation"), with defaults that keep the dark sea clear;
- the automaton's defaults give separate clouds at time 0, not a box-filling slab.
With --output-dir it also renders each first picture (side view) to PNGs to look at.
Prints what it checks; exit 0 on success.
"""
import argparse
import os
import sys
import tempfile

import numpy as np

from paraview import servermanager
from paraview.simple import (CreateRenderView, Delete, LoadPlugin, OpenDataFile, OutputPort,
                             Render, SaveData, SaveScreenshot, Show)
from paraview.vtk.util.numpy_support import vtk_to_numpy


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message)
    return bool(condition)


def density_columns(proxy, time=0.0):
    proxy.UpdatePipeline(time)
    data = servermanager.Fetch(proxy)
    nx, ny, nz = data.GetDimensions()
    rho = vtk_to_numpy(data.GetPointData().GetArray("density")).reshape(nz, ny, nx)
    return data, rho, rho.sum(axis=0)


def groups(mask):
    """4-connected groups of True cells (periodic), with a plain flood fill."""
    seen = np.zeros_like(mask, dtype=bool)
    ny, nx = mask.shape
    count = 0
    for start in zip(*np.nonzero(mask)):
        if seen[start]:
            continue
        count += 1
        stack = [start]
        seen[start] = True
        while stack:
            y, x = stack.pop()
            for j, i in (((y + 1) % ny, x), ((y - 1) % ny, x), (y, (x + 1) % nx),
                         (y, (x - 1) % nx)):
                if mask[j, i] and not seen[j, i]:
                    seen[j, i] = True
                    stack.append((j, i))
    return count


def first_apply(proxy, view, name):
    """Shows port 0 as the GUI's Apply does; returns the display and whether port 1 would
    be shown (the View hint)."""
    controller = servermanager.vtkSMParaViewPipelineControllerWithRendering()
    display = Show(proxy, view)
    ok = check(display.Representation == "Cloud",
               "%s: shown as %s" % (name, display.Representation))
    color = display.ColorArrayName[1] if display.ColorArrayName else ""
    ok &= check(color == "", "%s: Solid Color (colour array %r), so no legend" % (name, color))
    if proxy.SMProxy.GetNumberOfOutputPorts() > 1:
        shown = controller.ShowInPreferredView(proxy.SMProxy, 1, view.SMProxy)
        ok &= check(shown is None, "%s: port 1 is not shown on Apply" % name)
    return display, ok


def render(view, display, path, size=(640, 400)):
    # The side view the GUI's first Apply gives (Plugin/Behavior): from the south, 11 deg down.
    view.UseColorPaletteForBackground = 0
    view.Background = [0, 0, 0]
    view.OrientationAxesVisibility = 0
    display.SunElevationDegrees = 35.0
    view.CameraFocalPoint = [0, 0, 0]
    view.CameraPosition = [0, -np.cos(np.radians(11.0)), np.sin(np.radians(11.0))]
    view.CameraViewUp = [0, 0, 1]
    view.ResetCamera(False)
    Render(view)
    SaveScreenshot(path, view, ImageResolution=list(size))
    print("wrote", path)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--image", required=True)
    parser.add_argument("--output-dir")
    args = parser.parse_args()
    LoadPlugin(args.plugin, ns=globals())
    ok = True

    # --- the automaton's defaults ---------------------------------------------------------
    automaton = NimbusCloudAutomaton()  # noqa: F821
    data, rho, columns = density_columns(automaton, 0.0)
    cloudy = columns > 1.0
    cover = float(cloudy.mean())
    count = groups(cloudy)
    ok &= check(0.03 < cover < 0.35, "automaton defaults, t = 0: %.1f %% of columns cloudy"
                % (100 * cover))
    ok &= check(count >= 4, "automaton defaults, t = 0: %d separate clouds" % count)
    ok &= check(float(rho[-1].max()) < 0.05, "nothing at the top of the box (max %.3f)"
                % rho[-1].max())
    view = CreateRenderView()
    display, good = first_apply(automaton, view, "Nimbus Cloud Automaton")
    ok &= good
    if args.output_dir:
        render(view, display, os.path.join(args.output_dir, "first-apply-automaton.png"))

    # --- the metaball cloud ------------------------------------------------------------------
    metaballs = NimbusMetaballCloud()  # noqa: F821
    view = CreateRenderView()
    display, good = first_apply(metaballs, view, "Nimbus Metaball Cloud")
    ok &= good
    if args.output_dir:
        render(view, display, os.path.join(args.output_dir, "first-apply-metaball.png"))

    # --- a .vdb file (when the plugin has OpenVDB) ------------------------------------------
    vdb = os.path.join(tempfile.mkdtemp(), "metaball.vdb")
    try:
        SaveData(vdb, proxy=metaballs)
    except Exception as error:  # no OpenVDB in this build
        print("skip  .vdb (%s)" % error)
    else:
        reader = OpenDataFile(vdb)
        reader.UpdatePipeline()
        view = CreateRenderView()
        display = Show(reader, view)
        ok &= check(display.Representation == "Cloud",
                    ".vdb file (%s): shown as %s" % (reader.GetXMLName(), display.Representation))

    # --- the image cloud from ParaView's default PNG reader -------------------------------
    reader = OpenDataFile(args.image)
    reader.UpdatePipeline()  # the GUI has applied the reader before the filter is chosen
    ok &= check(reader.GetXMLName() == "GDALRasterReader",
                "ParaView opens the PNG with %s" % reader.GetXMLName())
    image = NimbusImageCloud(Input=reader)  # noqa: F821
    selected = list(image.SelectInputScalars)
    ok &= check(selected == ["CELLS", "Elevation"], "intensity array chosen: %s" % selected)
    data, rho, columns = density_columns(image)
    ok &= check(data.GetDimensions()[:2] == (129, 129),
                "one column per point of the reader's grid: %s" % (data.GetDimensions(),))
    clear = float((columns == 0.0).mean())
    ok &= check(0.3 < clear < 0.9, "%.0f %% of the columns are clear sky (the dark sea)"
                % (100 * clear))
    ok &= check(float(rho.max()) > 0.5, "bright pixels are cloud (max density %.2f)" % rho.max())
    view = CreateRenderView()
    display, good = first_apply(image, view, "Nimbus Image Cloud")
    ok &= good
    if args.output_dir:
        render(view, display, os.path.join(args.output_dir, "first-apply-image-cloud.png"))
    # --- the lightning: strokes shown as lines, point sources hidden, a flash over time ---
    bolt = NimbusLightning()  # noqa: F821
    controller = servermanager.vtkSMParaViewPipelineControllerWithRendering()
    view = CreateRenderView()
    strokes = Show(bolt, view)
    ok &= check(strokes.Representation == "Surface",
                "Nimbus Lightning: strokes shown as %s" % strokes.Representation)
    ok &= check(controller.ShowInPreferredView(bolt.SMProxy, 1, view.SMProxy) is None,
                "Nimbus Lightning: the point sources are not shown on Apply")
    times = list(bolt.TimestepValues)
    peak = bolt.FlashStartSeconds + bolt.LeaderDurationSeconds
    ok &= check(len(times) > 10 and peak in times,
                "Nimbus Lightning: %d time steps, the return stroke's peak %.3f s among them"
                % (len(times), peak))
    emission = []
    for t in (0.0, peak, peak + 0.5 * bolt.StrokeIntervalSeconds):
        bolt.UpdatePipeline(t)
        cells = servermanager.Fetch(bolt, None, 0)
        values = cells.GetCellData().GetArray("intensity")
        emission.append(sum(values.GetValue(i) for i in range(values.GetNumberOfTuples())))
    ok &= check(emission[0] == 0.0 and emission[1] > 0.0 and emission[2] < 0.5 * emission[1],
                "Nimbus Lightning: dark before the flash, lit at the stroke, fading after "
                "(sum of intensities %s)" % ["%.3g" % e for e in emission])
    # --- the cloud lit by the flash: shown as a Cloud, the lightning's time steps, lit at
    # the stroke and dark before it (cheap settings: a small grid, 14 directions) ---
    cloud = NimbusMetaballCloud(Dimensions=[48, 48, 32])  # noqa: F821
    lit = NimbusLightningIllumination(  # noqa: F821
        Input=cloud, Lightning=OutputPort(bolt, 1), NumberOfDirections=14,
        LightSpacingMetres=750.0, UseDiskCache=0)
    lit_display = Show(lit, view)
    ok &= check(lit_display.Representation == "Cloud",
                "Nimbus Lightning Illumination: shown as %s" % lit_display.Representation)
    ok &= check(list(lit.TimestepValues) == times,
                "Nimbus Lightning Illumination: the lightning's %d time steps"
                % len(lit.TimestepValues))
    light = []
    for t in (0.0, peak):
        lit.UpdatePipeline(t)
        field = servermanager.Fetch(lit).GetFieldData().GetArray(
            "nimbus_lightning_in_scattering")
        light.append(max(abs(field.GetRange(c)[1]) for c in range(12)) if field else -1.0)
    ok &= check(light[0] == 0.0 and light[1] > 0.0,
                "Nimbus Lightning Illumination: no light before the flash, light at the "
                "return stroke (largest coefficient %s)" % ["%.3g" % v for v in light])
    Delete(view)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
