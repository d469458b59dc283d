"""What a user must do today to get a believable cloud from Data/UserData's files.

    /usr/bin/pvpython --force-offscreen-rendering measurements/user-data-before.py \
        --plugin build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so \
        --data-dir Data/UserData --output-dir DIR [--case vdb|netcdf|pvti] [--control]

For each file, the steps of docs/user-data.md's "before" column, one at a time: after each
step the view (400 x 300, the default sun, the camera of Testing/Python/TestUserData.py) is
rendered and judged by the same checks as that test, and the seconds since the file was
opened are printed. Only properties that exist in today's plugin are used. Images:
DIR/<case>-<step>.png. --control also runs the checks on pictures made wrong on purpose
(a lighter box of air, the cloud cut by the ground, the cloud on its side), to show that
each check can fail.
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, os.pardir, "Testing", "Python"))
import TestUserData as checks  # noqa: E402
from paraview.simple import (  # noqa: E402
    ColorBy, Delete, GetSources, Hide, LoadPlugin, NetCDFReader, OpenDataFile, Render,
    ResampleToImage, SaveScreenshot, Show, Transform)

# Liquid water content -> extinction for droplets of effective radius r_e:
# sigma = 3 LWC / (2 rho_w r_e) (Stephens 1978; Hansen & Travis 1974), LWC = rho_air ql.
RHO_WATER = 1000.0          # kg m-3
EFFECTIVE_RADIUS = 10e-6    # m
RHO_AIR_CLOUD = 1.06        # kg m-3: the standard atmosphere at 1.3 km, the cloud's middle
EXTINCTION_PER_QL = 3.0 * RHO_AIR_CLOUD / (2.0 * RHO_WATER * EFFECTIVE_RADIUS)  # 1/m per kg/kg


class Steps:
    """Renders and judges the view after each step; keeps the clock from opening the file."""

    def __init__(self, case, view, output_dir):
        self.case, self.view, self.output_dir = case, view, output_dir
        self.start = time.time()
        self.judging = 0.0   # seconds spent on the checks' extra renders, not the user's
        self.rows = []

    def judge(self, label, display, source, array, tall=False, seconds=None, tau=None):
        Render(self.view)
        elapsed = time.time() - self.start - self.judging if seconds is None else seconds
        began = time.time()
        failures = []
        name = "%s-%d" % (self.case, len(self.rows))
        if display is None:
            path = os.path.join(self.output_dir, name + ".png")
            SaveScreenshot(path, self.view, ImageResolution=checks.SIZE)
            failures.append("no Cloud representation")
        else:
            checks.check_picture(self.view, display, source, array, name, self.output_dir,
                                 failures, checks.zero_extinction, tall=tall,
                                 optical_depth=tau)
        self.judging += time.time() - began
        print("[%s] step %d (%.2f s): %s" % (self.case, len(self.rows), elapsed, label))
        for failure in failures:
            print("    not yet:", failure)
        if not failures:
            print("    believable: every check passes")
        self.rows.append((label, elapsed, failures))
        return failures


def cloud_display(source, view):
    display = Show(source, view)
    if "Cloud" not in display.GetProperty("Representation").Available:
        print("    Cloud is not offered for %s; offered: %s" % (
            source.GetDataInformation().GetDataSetTypeAsString(),
            list(display.GetProperty("Representation").Available)))
        return display, False
    display.SetRepresentationType("Cloud")
    return display, True


def look(view, source, display):
    azimuth = display.SunAzimuthDegrees if display.GetProperty("SunAzimuthDegrees") else 135.0
    checks.first_look(view, source.GetDataInformation().GetBounds(), azimuth)


def before_vdb(path, view, output_dir):
    steps = Steps("vdb", view, output_dir)
    reader = OpenDataFile(path)
    display, _ = cloud_display(reader, view)
    look(view, reader, display)
    steps.judge("open the .vdb, show it as Cloud", display, reader, "density", tall=True)
    # Turn it: Transform (rotate +90 degrees about x takes +y to +z), which makes a
    # structured grid, then Resample To Image at the file's own resolution.
    Hide(reader, view)
    turn = Transform(Input=reader)
    turn.Transform = "Transform"
    turn.Transform.Rotate = [90.0, 0.0, 0.0]
    turned_display = Show(turn, view)
    offered = "Cloud" in turned_display.GetProperty("Representation").Available
    print("    Transform's output: %s, Cloud offered: %s" % (
        turn.GetDataInformation().GetDataSetTypeAsString(), offered))
    Hide(turn, view)
    image = ResampleToImage(Input=turn)
    image.SamplingDimensions = [44, 44, 64]
    display, _ = cloud_display(image, view)
    look(view, image, display)
    steps.judge("Transform (Rotate 90 0 0) + Resample To Image 44 x 44 x 64", display, image,
                "density", tall=True)
    # The ground is at z = 0, through the cloud: put it at the data's lowest z.
    display.GroundHeight = image.GetDataInformation().GetBounds()[4]
    steps.judge("Ground Height = the data's lowest z (%.2f)" % display.GroundHeight, display,
                image, "density", tall=True)
    # The density has no unit: 0.02 1/m per unit leaves a 143 m wide cloud translucent
    # and grey (optical depth about 3 across); a denser look needs a guess.
    display.ExtinctionPerDensity = 0.08
    steps.judge("Extinction per Unit Density 0.02 -> 0.08 (a guess: denser, whiter)", display,
                image, "density", tall=True)
    return steps, display, image


def optical_depth_of_ql(image):
    """The largest vertical optical depth of the resampled ql (the test's formula)."""
    data = checks.output_of(image)
    z = data.GetOrigin()[2] + data.GetSpacing()[2] * np.arange(data.GetDimensions()[2])
    sigma = 3.0 * checks.standard_atmosphere_density(z)[:, None, None] * checks.grid_values(
        data, "ql") / (2.0 * checks.RHO_WATER * checks.EFFECTIVE_RADIUS)
    return checks.largest_column_optical_depth(data, sigma, 1.0)


def before_netcdf(path, view, output_dir):
    steps = Steps("netcdf", view, output_dir)
    reader = NetCDFReader(FileName=[path])
    reader.UpdatePipeline(reader.TimestepValues[0])
    display, offered = cloud_display(reader, view)
    look(view, reader, display)
    steps.judge("open the .nc (NetCDF CF reader, defaults: %s)" % (
        reader.GetDataInformation().GetDataSetTypeAsString()),
        display if offered else None, reader, "ql")
    # Spherical Coordinates must be off before the first Apply: a display made for the
    # spherical structured grid stays a structured-grid display (no Cloud) afterwards.
    Hide(reader, view)
    reader = NetCDFReader(FileName=[path])
    reader.SphericalCoordinates = 0
    reader.UpdatePipeline(reader.TimestepValues[0])
    display, offered = cloud_display(reader, view)
    look(view, reader, display)
    steps.judge("open again with Spherical Coordinates off, Cloud (%s)" % (
        reader.GetDataInformation().GetDataSetTypeAsString()),
        display if offered else None, reader, "ql")
    ColorBy(display, ("POINTS", "ql"))
    steps.judge("Colour by ql", display if offered else None, reader, "ql")
    Hide(reader, view)
    image = ResampleToImage(Input=reader)
    image.SamplingDimensions = [64, 64, 85]    # 25 m vertically, the finest level
    image.UpdatePipeline(reader.TimestepValues[0])
    tau = optical_depth_of_ql(image)
    display, _ = cloud_display(image, view)
    # The resampled image has no active scalars either: colour by ql again.
    ColorBy(display, ("POINTS", "ql"))
    look(view, image, display)
    steps.judge("Resample To Image 64 x 64 x 85, Cloud, colour by ql", display, image, "ql",
                tau=tau)
    display.ExtinctionPerDensity = EXTINCTION_PER_QL
    steps.judge("Extinction per Unit Density = 3 rho_air / (2 rho_w r_e) = %.0f 1/m" %
                EXTINCTION_PER_QL, display, image, "ql", tau=tau)
    return steps, display, image


def before_pvti(path, view, output_dir):
    steps = Steps("pvti", view, output_dir)
    reader = OpenDataFile(path)
    reader.UpdatePipeline()
    data = checks.output_of(reader)
    tau = checks.largest_column_optical_depth(data, checks.grid_values(data, "extinction"),
                                              1000.0)
    display, _ = cloud_display(reader, view)
    look(view, reader, display)
    steps.judge("open the .pvti, show it as Cloud", display, reader, "extinction", tau=tau)
    display.MetresPerUnit = 1000.0
    steps.judge("Metres Per Unit = 1000", display, reader, "extinction", tau=tau)
    display.ExtinctionPerDensity = 1.0
    steps.judge("Extinction per Unit Density = 1 (the array is the extinction in 1/m)",
                display, reader, "extinction", tau=tau)
    return steps, display, reader


def controls(view, display, source, array, output_dir):
    """The checks fail on pictures made wrong on purpose."""
    print("[controls]")
    name = "control"
    image_path = os.path.join(output_dir, name + ".png")
    SaveScreenshot(image_path, view, ImageResolution=checks.SIZE)
    image = checks.read_png(image_path)
    bounds = source.GetDataInformation().GetBounds()
    horizon = checks.horizon_row(view)
    # A lighter box: 4 levels added inside the projected box.
    columns, rows = checks.project(view, checks.box_corners(bounds))
    hull = checks.convex_hull(list(zip(columns, checks.SIZE[1] - rows)))
    yy, xx = np.mgrid[0:checks.SIZE[1], 0:checks.SIZE[0]]
    inside = np.ones(xx.shape, dtype=bool)
    for a, b in zip(hull, hull[1:] + hull[:1]):
        inside &= (b[0] - a[0]) * ((checks.SIZE[1] - yy) - a[1]) - \
            (b[1] - a[1]) * (xx - a[0]) >= 0
    lighter = image + 4.0 * inside[:, :, None]
    step, edges = checks.air_step_at_box(view, lighter, bounds,
                                         np.zeros(inside.shape, dtype=bool), horizon)
    print("    a box of air 4 levels lighter: step %.2f (edges %s) -> %s" % (
        step, edges, "caught" if step > checks.AIR_STEP_LEVELS else "MISSED"))
    step, edges = checks.air_step_at_box(view, image, bounds,
                                         np.zeros(inside.shape, dtype=bool), horizon)
    print("    the same picture unchanged: step %.2f (edges %s)" % (step, edges))
    # Cut by the ground: the ground put through the middle of the cloud.
    kept = display.GroundHeight
    bounds = source.GetDataInformation().GetBounds()
    display.GroundHeight = bounds[4] + 0.35 * (bounds[5] - bounds[4])
    failures = []
    checks.check_picture(view, display, source, array, "control-cut", output_dir, failures,
                         checks.zero_extinction, tall=True)
    print("    ground through the cloud:", "caught" if any(
        "hidden" in f or "cuts" in f for f in failures) else "MISSED", failures)
    display.GroundHeight = kept


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--data-dir", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--case", choices=["vdb", "netcdf", "pvti"], action="append")
    parser.add_argument("--control", action="store_true")
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    LoadPlugin(args.plugin, ns=globals())
    recipes = {"vdb": before_vdb, "netcdf": before_netcdf, "pvti": before_pvti}
    for case in args.case or ["vdb", "netcdf", "pvti"]:
        view = checks.make_view()
        steps, display, source = recipes[case](
            os.path.join(args.data_dir, checks.FILES[case]), view, args.output_dir)
        if args.control and case == "vdb":
            controls(view, display, source, "density", args.output_dir)
        for representation in list(view.Representations):
            Delete(representation)
        Delete(view)
        del view
        for proxy in list(GetSources().values()):
            Delete(proxy)
    return 0


if __name__ == "__main__":
    sys.exit(main())
