"""pvpython tests of the Cloud representation on data that is not the project's own:
any frame, any grid, any units, a ground under the data, and air without a seam.

    pvpython TestCloudFrame.py --plugin Nimbus.so --output-dir DIR --case CASE

CASE:
  seamless-air  A volume of zero density over air and ground renders the same image
                as no volume (a box 1e-6 of its size, out of sight), within 8-bit
                rounding (1 level), from six views: beside, above, inside the box,
                along a face, from below looking up, and far away, for three suns
                (20 deg, the zenith, below the horizon), with the ground crossing the
                box, below sea level (Metres Per Unit 5, Ground Height -300: the
                condition that showed the box as a lighter hexagon in the sky).
  up-axis       A cloud stored y up (and -y up, x up) with Up Axis set to match, seen
                by the camera turned the same way, renders the same image as the cloud
                stored z up with Up Axis +Z: the sun, the ground and the air turned
                with the axis (also over a Nimbus Sky whose Up Axis is set); and the
                ground stays under the data by default.
  any-grid      Cloud is offered for image, rectilinear, structured, unstructured,
                multiblock and AMR data; each renders a cloud (not blank); a
                resampled image over the memory budget ends in an error, not a crash.
  units         Every Density Array Means choice renders the same image as the
                dimensionless density with the extinction per density computed by
                hand (uniform water content: one scale); "Unknown" reports its
                estimate (EstimatedExtinctionPerDensityInfo, shown in the panel), which
                goes as 1/Target Optical Thickness, and renders the image of the
                dimensionless density at that extinction per density.
  bad-input     Every new property of the Cloud representation (Up Axis, Density Array
                Means and the droplets, the target, Sampling Dimensions, the resample
                budget, Metres Per Unit, the ground) set to values outside its meaning
                (NaN, infinities, zero, negative, huge, missing arrays), and data with
                NaN, infinite and negative values in every unit: each render ends (an
                error message, or a finite picture), and setting the good value back gives
                the first picture again (nothing is stuck or lost).
"""
import argparse
import math
import os
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import (ColorBy, CreateRenderView, Delete, GroupDatasets, Hide, LoadPlugin,
                             Render, SaveScreenshot, Show, Tetrahedralize, Transform,
                             TrivialProducer)
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkRectilinearGrid

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import read_png  # noqa: E402

SIZE = [320, 240]
FAILURES = []


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message)
    if not condition:
        FAILURES.append(message)


def image_of(array, spacing, origin, name="density"):
    """A vtkImageData of a numpy array indexed [z, y, x]."""
    image = vtkImageData()
    image.SetDimensions(array.shape[2], array.shape[1], array.shape[0])
    image.SetSpacing(spacing)
    image.SetOrigin(origin)
    values = numpy_to_vtk(np.ascontiguousarray(array, dtype=np.float32).ravel(), deep=1)
    values.SetName(name)
    image.GetPointData().SetScalars(values)
    return image


def producer(data):
    source = TrivialProducer()
    source.GetClientSideObject().SetOutput(data)
    return source


def cloud_density(nx=48, ny=40, nz=32):
    """A smooth cloud of blobs, z up, indexed [z, y, x], values 0..1."""
    z, y, x = np.meshgrid(np.linspace(-1, 1, nz), np.linspace(-1, 1, ny), np.linspace(-1, 1, nx),
                          indexing="ij")
    density = np.zeros_like(x)
    for cx, cy, cz, r in [(0.0, 0.0, -0.2, 0.55), (0.35, 0.1, 0.15, 0.4), (-0.3, -0.2, 0.1, 0.35)]:
        density += np.exp(-((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (r * r))
    return np.clip(density - 0.3, 0.0, 1.0)


def show_cloud(source, view, array="density", association="POINTS"):
    display = Show(source, view)
    display.SetRepresentationType("Cloud")
    ColorBy(display, (association, array))
    display.MultipleScatteringMethod = 1  # octaves: fast, and the same in every render
    return display


def new_view():
    view = CreateRenderView()
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.CameraViewAngle = 30.0
    return view


def shot(view, path, camera=None):
    if camera is not None:
        view.CameraPosition, view.CameraFocalPoint, view.CameraViewUp = camera
        view.CameraViewAngle = 30.0
    Render(view)
    SaveScreenshot(path, view, ImageResolution=SIZE)
    return read_png(path)


def first_render(view):
    # paraview.simple resets the camera at a view's first render: get it over with.
    Render(view)


# --- seamless air ----------------------------------------------------------------------
def seamless_air(out):
    zero = image_of(np.zeros((44, 64, 64)), (30.0, 30.0, 30.0), (-945.0, -945.0, -645.0))
    view = new_view()
    display = show_cloud(producer(zero), view)
    display.MetresPerUnit = 5.0
    display.GroundHeight = -300.0   # below sea level, crossing the box
    display.GroundBelowData = 0     # the same ground with and without the box
    if os.environ.get("NIMBUS_TEST_ATMOSPHERE_STEPS"):
        display.AtmosphereSteps = int(os.environ["NIMBUS_TEST_ATMOSPHERE_STEPS"])
    only = os.environ.get("NIMBUS_TEST_VIEWS")
    first_render(view)
    views = {
        "beside": ([-4540.0, -3534.0, -115.0], [-15.0, -15.0, -15.0]),
        "above": ([900.0, -1350.0, 6300.0], [0.0, 0.0, 0.0]),
        "inside": ([90.0, -180.0, 45.0], [1800.0, 2700.0, 90.0]),
        "along-a-face": ([-3600.0, -945.0, 0.0], [0.0, -945.0, 0.0]),
        "from-below": ([-2700.0, -1800.0, -225.0], [0.0, 0.0, 900.0]),
        "far": ([-20000.0, -15000.0, 300.0], [0.0, 0.0, 300.0]),
    }
    for sun in (20.0, 90.0, -4.0):
        display.SunElevationDegrees = sun
        for name, (eye, focal) in views.items():
            if only and name not in only.split():
                continue
            camera = (eye, focal, [0.0, 0.0, 1.0])
            display.Scale = [1.0, 1.0, 1.0]
            display.Position = [0.0, 0.0, 0.0]
            with_box = shot(view, os.path.join(out, "air-%s-sun%g-box.png" % (name, sun)), camera)
            # "No volume": the box shrunk to a point at the focal point, drawn by the
            # same passes (the air outside any box).
            display.Scale = [1e-6, 1e-6, 1e-6]
            display.Position = focal
            without = shot(view, os.path.join(out, "air-%s-sun%g-none.png" % (name, sun)), camera)
            difference = np.abs(with_box - without)
            check(difference.max() <= 1.0,
                  "seamless air, %s, sun %g deg: max difference %g levels, mean %.3f "
                  "(bound 1: 8-bit rounding)" % (name, sun, difference.max(), difference.mean()))
            if sun > 0.0:
                check(without.mean() > 20.0, "seamless air, %s, sun %g deg: the air is drawn "
                      "(mean %.1f)" % (name, sun, without.mean()))
    Delete(view)


# --- up axis ---------------------------------------------------------------------------
# Physics/UpAxis.h: world = R^T up. For each axis: the image of a z-up array stored with
# that axis up (numpy), and a point of the up frame in world coordinates.
def turned(axis, density, spacing, origin):
    """(array [z, y, x] in world axes, world spacing, world origin)."""
    nz, ny, nx = density.shape
    up_extent = [origin[a] + np.array([0.0, (n - 1) * spacing[a]]) for a, n in
                 enumerate((nx, ny, nz))]
    if axis == 2:
        return density, spacing, origin
    if axis == 1:   # world (x, y, z) = (ux, uz, -uy)
        world = np.transpose(density, (1, 0, 2))[::-1, :, :]
        lows = (up_extent[0][0], up_extent[2][0], -up_extent[1][1])
        return world, (spacing[0], spacing[2], spacing[1]), lows
    if axis == 3:   # world (x, y, z) = (ux, -uz, uy)
        world = np.transpose(density, (1, 0, 2))[:, ::-1, :]
        lows = (up_extent[0][0], -up_extent[2][1], up_extent[1][0])
        return world, (spacing[0], spacing[2], spacing[1]), lows
    if axis == 0:   # world (x, y, z) = (uz, ux, uy)
        # world x = uz, world y = ux, world z = uy: indexed [world z, world y, world x]
        world = np.transpose(density, (1, 2, 0))
        lows = (up_extent[2][0], up_extent[0][0], up_extent[1][0])
        return world, (spacing[2], spacing[0], spacing[1]), lows
    raise ValueError(axis)


def to_world(axis, p):
    x, y, z = p
    return {2: (x, y, z), 1: (x, z, -y), 3: (x, -z, y), 0: (z, x, y)}[axis]


def up_axis(out):
    density = cloud_density()
    spacing, origin = (40.0, 40.0, 40.0), (-940.0, -780.0, 400.0)
    camera_up = ([-2600.0, -2200.0, 900.0], [0.0, 0.0, 1000.0], [0.0, 0.0, 1.0])
    for with_sky in (False, True):
        images = {}
        for axis in (2, 1, 3, 0):
            array, world_spacing, world_origin = turned(axis, density, spacing, origin)
            view = new_view()
            if with_sky:
                sky = NimbusSky(SunElevationDegrees=25.0, SunAzimuthDegrees=200.0,  # noqa: F821
                                UpAxis=axis)
                Show(sky, view)
            display = show_cloud(producer(image_of(array, world_spacing, world_origin)), view)
            display.UpAxis = axis
            display.ExtinctionPerDensity = 0.05
            display.SunElevationDegrees = 25.0
            display.SunAzimuthDegrees = 200.0
            display.GroundHeight = 200.0
            first_render(view)
            camera = tuple(list(to_world(axis, p)) for p in camera_up)
            name = "up-%s-axis%d.png" % ("sky" if with_sky else "own", axis)
            images[axis] = shot(view, os.path.join(out, name), camera)
            Delete(view)
        reference = images[2]
        check(reference.std() > 5.0, "up axis: the z-up cloud is not blank (std %.1f)"
              % reference.std())
        for axis in (1, 3, 0):
            difference = np.abs(images[axis] - reference)
            check(difference.max() <= 2.0 and difference.mean() < 0.05,
                  "up axis %s (%s): the turned cloud, camera and up axis give the z-up image "
                  "(max difference %g levels, mean %.4f)"
                  % ({1: "+Y", 3: "-Y", 0: "+X"}[axis], "sky" if with_sky else "own air",
                     difference.max(), difference.mean()))
    # The ground under the data: the cloud's box bottom is at z = 400; a ground set at
    # 1000 lies at 400 unless the user turns the option off.
    view = new_view()
    display = show_cloud(producer(image_of(density, spacing, origin)), view)
    display.GroundHeight = 1000.0
    first_render(view)
    mapper = cloud_mapper(view)
    if mapper is not None:
        check(abs(mapper.GetLastGroundHeight() - 400.0) < 1e-9,
              "the ground lies at the data's bottom (%g)" % mapper.GetLastGroundHeight())
        display.GroundBelowData = 0
        Render(view)
        check(abs(mapper.GetLastGroundHeight() - 1000.0) < 1e-9,
              "Keep the Ground Below the Data off: the ground at Ground Height (%g)"
              % mapper.GetLastGroundHeight())
    Delete(view)


def cloud_mapper(view):
    try:
        import nimbus
    except ImportError:
        return None
    return nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())


# --- any grid --------------------------------------------------------------------------
def rectilinear(density, spacing, origin):
    nz, ny, nx = density.shape
    grid = vtkRectilinearGrid()
    grid.SetDimensions(nx, ny, nz)
    # A stretched vertical axis, as an LES's levels.
    zs = origin[2] + spacing[2] * (np.arange(nz) + 0.02 * np.arange(nz) ** 2)
    for setter, coords in ((grid.SetXCoordinates, origin[0] + spacing[0] * np.arange(nx)),
                           (grid.SetYCoordinates, origin[1] + spacing[1] * np.arange(ny)),
                           (grid.SetZCoordinates, zs)):
        setter(numpy_to_vtk(coords.astype(np.float64), deep=1))
    values = numpy_to_vtk(density.astype(np.float32).ravel(), deep=1)
    values.SetName("density")
    grid.GetPointData().SetScalars(values)
    return grid


def any_grid(out):
    density = cloud_density(32, 28, 24)
    spacing, origin = (50.0, 50.0, 50.0), (-775.0, -675.0, 300.0)
    image = producer(image_of(density, spacing, origin))
    sources = {
        "image": image,
        "rectilinear": producer(rectilinear(density, spacing, origin)),
        "structured": Transform(Input=image),
        "unstructured": Tetrahedralize(Input=image),
        "multiblock": GroupDatasets(Input=[image]),
    }
    try:
        from paraview.simple import AMRGaussianPulseSource
        sources["amr"] = AMRGaussianPulseSource()
    except ImportError:
        pass
    for name, source in sources.items():
        view = new_view()
        display = Show(source, view)
        domain = display.GetProperty("Representation").SMProperty.GetDomain("list")
        offered = [domain.GetString(i) for i in range(domain.GetNumberOfStrings())]
        check("Cloud" in offered, "%s (%s): Cloud is offered" % (name, display.GetXMLName()))
        if "Cloud" not in offered:
            Delete(view)
            continue
        array = "Gaussian-Pulse" if name == "amr" else "density"
        association = "CELLS" if name == "amr" else "POINTS"
        display.SetRepresentationType("Cloud")
        ColorBy(display, (association, array))
        display.MultipleScatteringMethod = 1
        display.CloudSamplingDimensions = [48, 48, 48]
        if name == "amr":
            display.DensityUnits = 5  # its values have no unit: a typical cloud
        first_render(view)
        bounds = source.GetDataInformation().GetBounds()
        centre = [0.5 * (bounds[2 * a] + bounds[2 * a + 1]) for a in range(3)]
        size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4])
        camera = ([centre[0] - 2.2 * size, centre[1] - 1.8 * size, centre[2] + 0.2 * size],
                  centre, [0.0, 0.0, 1.0])
        with_cloud = shot(view, os.path.join(out, "grid-%s.png" % name), camera)
        Hide(source, view)
        # The same air with no cloud: a zero box the size of a point.
        show_cloud(producer(image_of(np.zeros((2, 2, 2)), (1e-6,) * 3, centre)), view)
        clear = shot(view, os.path.join(out, "grid-%s-clear.png" % name), camera)
        changed = (np.abs(with_cloud - clear).max(axis=2) > 8.0).mean()
        check(changed > 0.01, "%s: the cloud changes %.1f %% of the pixels" % (name,
                                                                             100 * changed))
        if name == "unstructured":
            unstructured = (camera, with_cloud)
        Delete(view)
    # A resampled image over the budget: an error and nothing drawn, no crash.
    view = new_view()
    display = Show(sources["unstructured"], view)
    display.SetRepresentationType("Cloud")
    ColorBy(display, ("POINTS", "density"))
    display.MultipleScatteringMethod = 1
    display.CloudSamplingDimensions = [2048, 2048, 2048]
    display.ResampleMemoryBudgetMiB = 64.0
    first_render(view)
    camera, with_cloud = unstructured
    over = shot(view, os.path.join(out, "grid-over-budget.png"), camera)
    drawn = (np.abs(over - with_cloud).max(axis=2) > 8.0).mean()
    check(drawn > 0.01, "a 2048^3 resample over a 64 MiB budget: refused with a message, "
          "no cloud drawn (%.1f %% of the pixels differ from the cloud)" % (100 * drawn))
    display.CloudSamplingDimensions = [48, 48, 48]
    again = shot(view, os.path.join(out, "grid-within-budget.png"), camera)
    check(np.abs(again - with_cloud).max() <= 1.0,
          "back within the budget: the cloud again (max difference %g levels)"
          % np.abs(again - with_cloud).max())
    Delete(view)


# --- units -----------------------------------------------------------------------------
def units(out):
    shape = cloud_density(40, 36, 28) > 0.05   # a cloud's footprint
    spacing, origin = (30.0, 30.0, 30.0), (-585.0, -525.0, 600.0)
    camera = ([-2400.0, -2000.0, 700.0], [0.0, 0.0, 1000.0], [0.0, 0.0, 1.0])

    def render(values, setup, name):
        view = new_view()
        display = show_cloud(producer(image_of(values, spacing, origin)), view)
        setup(display)
        first_render(view)
        pixels = shot(view, os.path.join(out, "units-%s.png" % name), camera)
        Delete(view)
        return pixels

    def dimensionless(k):
        def setup(display):
            display.DensityUnits = 0
            display.ExtinctionPerDensity = k
        return setup

    # Uniform contents inside the footprint: one extinction per unit value, by hand.
    lwc = 0.3                      # g/m^3
    r_e = 10.0                     # um
    beta = 3.0 * lwc * 1e-3 / (2.0 * 1000.0 * r_e * 1e-6)   # 1/m: 0.045
    check(abs(beta - 0.045) < 1e-12, "3 LWC / (2 rho_w r_e) = %.4f /m" % beta)
    reference = render(shape * 1.0, dimensionless(beta), "reference")
    cases = {
        "extinction": (shape * beta, lambda d: setattr(d, "DensityUnits", 1)),
        "lwc": (shape * lwc, lambda d: (setattr(d, "DensityUnits", 2),
                                        setattr(d, "DropletEffectiveRadiusMicrometres", r_e))),
        "iwc": (shape * (lwc * 917.0 / 1000.0),
                lambda d: (setattr(d, "DensityUnits", 4),
                           setattr(d, "DropletEffectiveRadiusMicrometres", r_e))),
        # r_e from N: (3 LWC / (4 pi rho_w k N))^(1/3) with k = 0.8 (maritime).
        "number": (shape * lwc, lambda d: (setattr(d, "DensityUnits", 2),
                                           setattr(d, "DropletSize", 1),
                                           setattr(d, "DropletNumberConcentrationPerCubicCentimetre",
                                                   3.0 * lwc * 1e-3 / (4.0 * math.pi * 1000.0 * 0.8
                                                                       * (r_e * 1e-6) ** 3) * 1e-6))),
    }
    for name, (values, setup) in cases.items():
        pixels = render(values, setup, name)
        difference = np.abs(pixels - reference)
        check(difference.max() <= 1.0 and reference.std() > 5.0,
              "units %s: the image of the hand-computed extinction (max difference %g levels)"
              % (name, difference.max()))
    # Mixing ratio with an air density array: q rho_air = LWC.
    rho = 0.9
    values = shape * (lwc * 1e-3 / rho)   # kg/kg

    def mixing(display):
        display.DensityUnits = 3
        display.AirDensityArray = "rho"
        display.DropletEffectiveRadiusMicrometres = r_e
    image = image_of(values, spacing, origin)
    rho_array = numpy_to_vtk(np.full(values.size, rho, dtype=np.float32), deep=1)
    rho_array.SetName("rho")
    image.GetPointData().AddArray(rho_array)
    view = new_view()
    display = show_cloud(producer(image), view)
    mixing(display)
    first_render(view)
    pixels = shot(view, os.path.join(out, "units-mixing-ratio.png"), camera)
    Delete(view)
    difference = np.abs(pixels - reference)
    check(difference.max() <= 1.0, "units mixing ratio with rho: max difference %g levels"
          % difference.max())
    estimated_units(out, spacing, origin, camera, render, dimensionless)


def estimated_units(out, spacing, origin, camera, render, dimensionless):
    """"Unknown": the estimate the panel shows (EstimatedExtinctionPerDensityInfo) is the
    scale used: 1/target (a quarter of the extinction for a quarter of the optical
    thickness), and the image is the dimensionless one at that extinction per density."""
    values = cloud_density(40, 36, 28)   # a smooth field: the columns differ

    def estimate(display):
        display.UpdatePropertyInformation()
        return display.GetPropertyValue("EstimatedExtinctionPerDensityInfo")

    view = new_view()
    display = show_cloud(producer(image_of(values, spacing, origin)), view)
    display.DensityUnits = 0
    first_render(view)
    check(estimate(display) == 0.0, "estimate: 0 while Density Array Means is not Unknown (%g)"
          % estimate(display))
    display.DensityUnits = 5
    estimated = {}
    for target in (20.0, 5.0):
        display.TargetOpticalThickness = target
        pixels = shot(view, os.path.join(out, "units-estimated-tau%g.png" % target), camera)
        estimated[target] = (estimate(display), pixels)
    Delete(view)
    k20, k5 = estimated[20.0][0], estimated[5.0][0]
    check(k20 > 0.0, "estimate for optical thickness 20: %.6g /m per unit value" % k20)
    check(k20 > 0.0 and abs(k20 / k5 - 4.0) < 1e-9,
          "estimate scales as 1/target: k(20) / k(5) = %.12g (4)" % (k20 / k5 if k5 else 0.0))
    for target, (k, pixels) in estimated.items():
        by_hand = render(values, dimensionless(k), "estimated-tau%g-by-hand" % target)
        difference = np.abs(pixels - by_hand)
        check(difference.max() <= 1.0 and pixels.std() > 5.0,
              "estimate, optical thickness %g: the image of the dimensionless density at "
              "%.6g /m per unit value (max difference %g levels)"
              % (target, k, difference.max()))


# --- bad input -------------------------------------------------------------------------
BAD_VALUES = {
    "UpAxis": [-1, 4, 99],
    "DensityUnits": [-1, 6, 1000],
    "DropletSize": [-1, 2],
    "DropletEffectiveRadiusMicrometres": [0.0, -5.0, float("nan"), float("inf"), 1e30],
    "DropletNumberConcentrationPerCubicCentimetre": [0.0, -1.0, float("nan"), float("-inf"),
                                                     1e30],
    "TargetOpticalThickness": [0.0, -1.0, float("nan"), float("inf"), 1e300],
    "CloudSamplingDimensions": [[0, 0, 0], [-5, 10, 10], [1, 1, 1], [1 << 30] * 3],
    "ResampleMemoryBudgetMiB": [-1.0, float("nan"), 1e-9],
    "MetresPerUnit": [0.0, -1.0, float("nan"), float("inf"), 1e-300, 1e300],
    "AirDensityArray": ["missing", "density"],
    "GroundHeight": [float("nan"), float("inf"), -1e30, 1e30],
    "RenderingMethod": [-1, 2, 99],
    "RayMarchStepTexels": [0.0, -1.0, float("nan"), float("inf"), 1e-30, 1e30],
}
# The units each property matters for (the others ignore it).
UNITS_FOR = {"DropletSize": 2, "DropletEffectiveRadiusMicrometres": 2,
             "DropletNumberConcentrationPerCubicCentimetre": 2, "TargetOpticalThickness": 5,
             "AirDensityArray": 3}


def bad_input(out):
    density = cloud_density(24, 20, 16)
    spacing, origin = (60.0, 60.0, 60.0), (-690.0, -570.0, 300.0)
    camera = ([-2400.0, -2000.0, 700.0], [0.0, 0.0, 750.0], [0.0, 0.0, 1.0])
    sources = {"image": producer(image_of(density * 0.3, spacing, origin))}
    sources["unstructured"] = Tetrahedralize(Input=sources["image"])
    count = 0
    for kind, source in sources.items():
        for name, values in BAD_VALUES.items():
            view = new_view()
            view.ViewSize = [160, 120]
            display = show_cloud(source, view)
            display.CloudSamplingDimensions = [24, 24, 24]   # a quick resample
            display.DropletSize = 1 if name == "DropletNumberConcentrationPerCubicCentimetre" else 0
            display.DensityUnits = UNITS_FOR.get(name, 2)
            first_render(view)
            good = display.GetPropertyValue(name)
            good = list(good) if isinstance(good, (list, tuple)) or hasattr(good, "__len__") \
                and not isinstance(good, str) else good
            size = [160, 120]
            path = os.path.join(out, "bad-%s-%s-good.png" % (kind, name))
            view.CameraPosition, view.CameraFocalPoint, view.CameraViewUp = camera
            Render(view)
            SaveScreenshot(path, view, ImageResolution=size)
            first = read_png(path)
            for value in values:
                setattr(display, name, value)
                Render(view)   # an error message, or a picture: never a crash or a hang
                count += 1
            setattr(display, name, good)
            Render(view)
            SaveScreenshot(path.replace("-good", "-again"), view, ImageResolution=size)
            again = read_png(path.replace("-good", "-again"))
            difference = np.abs(again - first).max()
            check(difference <= 1.0 and first.std() > 3.0,
                  "%s, %s: %d bad values rendered or refused, the good value gives the first "
                  "picture again (max difference %g levels)" % (kind, name, len(values),
                                                                difference))
            Delete(view)
    # Data with NaN, infinite and negative values, in every unit.
    poisoned = density * 0.3
    flat = poisoned.reshape(-1)
    flat[::7] = np.nan
    flat[3::11] = np.inf
    flat[5::13] = -np.inf
    flat[2::17] = -1.0
    for units in (0, 1, 2, 3, 4, 5):
        view = new_view()
        view.ViewSize = [160, 120]
        display = show_cloud(producer(image_of(poisoned, spacing, origin)), view)
        display.DensityUnits = units
        first_render(view)
        pixels = shot(view, os.path.join(out, "bad-poisoned-units%d.png" % units), camera)
        count += 1
        check(np.isfinite(pixels).all() and (pixels >= 254.5).mean() < 0.5,
              "NaN/Inf/negative data, Density Array Means %d: a picture, not blown out "
              "(%.1f %% white)" % (units, 100 * (pixels >= 254.5).mean()))
        Delete(view)
    print("%d bad inputs rendered" % count)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--case", required=True,
                        choices=["seamless-air", "up-axis", "any-grid", "units", "bad-input"])
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    LoadPlugin(args.plugin, ns=globals())
    {"seamless-air": seamless_air, "up-axis": up_axis, "any-grid": any_grid,
     "units": units, "bad-input": bad_input}[args.case](args.output_dir)
    if FAILURES:
        print("%d check(s) failed" % len(FAILURES))
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
