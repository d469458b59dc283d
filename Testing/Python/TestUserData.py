"""pvpython test: clouds in the forms users bring (Data/UserData) shown as Cloud.

    pvpython --force-offscreen-rendering TestUserData.py --plugin Nimbus.so \
        --data-dir Data/UserData --output-dir DIR --case vdb|netcdf|pvti

Each case opens its file, shows it as Cloud in a 400 x 300 view with the default sun,
sets ONLY what a user knows about the data, and checks the picture:

  vdb     cumulus_y_up.vdb (Houdini-style, y up, voxel 3.33, offset from the origin): the
          reader's UpAxis = +Y. The reader must turn the data so that +Y becomes +z
          (U = R W of Physics/UpAxis.h, about the origin).
  netcdf  les_cumulus_ql.nc (CF NetCDF, ql in kg/kg, stretched z, 3 time steps): the
          reader's SphericalCoordinates off (x and y are metres, not longitude and
          latitude), colour by ql (the reader sets no active scalars), DensityUnits =
          liquid water mixing ratio (kg/kg). Cloud must be offered for its rectilinear
          grid, and follow its time steps.
  pvti    automaton_extinction_km.pvti (extinction in 1/m on a grid in km):
          DensityUnits = extinction (1/m), MetresPerUnit = 1000.

The camera is the GUI's first look (11 degrees down, z up, fitted to the data) turned so
that the default sun (azimuth 135, elevation 45) is behind the viewer: the cloud is lit
from the front and its shadow falls behind and below it. The checks (each explained where
it is made):

  upright and above the ground  the cloud's pixels (those that differ from the same view
      with the density's extinction scaled to zero, within the projection of the density;
      the rest is its shadow) form a blob as tall and as wide as the cloud's
      density projected through the same camera, reaching down to the projected lowest
      cloudy point (a cloud cut by the ground loses its bottom rows); for the .vdb, a
      tower, the blob is taller than wide (a cloud lying on its side is not). The ground
      the display draws (GroundHeight, GroundBelowData, and the mapper's last ground
      height when `import nimbus` works) is at or below the cloud's lowest point.
  seamless air  no step in the air at the outline of the projected data box, in the
      zero-extinction image and, away from the cloud, in the user's image.
  not blank or blown out  enough cloud pixels, mean luminance of the cloud's pixels in
      [0.15, 0.96], fewer than 5 % of them at 255; where the units are known (netcdf, pvti)
      and the data's densest column has an optical depth of 10 or more, the cloud and its
      shadow change their 10 % most-changed pixels by 60 levels or more (not a pale ghost:
      the units were honoured, not off by orders of magnitude).

Properties that do not exist yet are reported as failures and the test goes on, so one
run shows every check. Images and a JSON summary (with the seconds from opening the file to
the first rendered still) go to the output directory.
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np
from paraview.simple import (ColorBy, CreateRenderView, Delete, GetActiveCamera, GetSources,
                             LoadPlugin, NetCDFReader, OpenDataFile, Render, SaveScreenshot,
                             Show)
from vtkmodules.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import read_png  # noqa: E402

SIZE = [400, 300]
CLOUD_DIFF_LEVELS = 8.0     # a pixel is the cloud's when a channel changes by more (of 255)
MIN_CLOUD_FRACTION = 0.003  # fewer cloud pixels than this fraction of the image: blank
LUMINANCE_RANGE = (0.15, 0.96)
MAX_SATURATED_FRACTION = 0.05
AIR_STEP_LEVELS = 2.0       # the largest mean step allowed at the box outline (of 255)
THICK_OPTICAL_DEPTH = 10.0  # a cloud whose densest column is this thick (or more) ...
THICK_CONTRAST_LEVELS = 60.0  # ... changes the 10 % most-changed pixels (its shadow's
#                               included) by this much or more
UP_AXIS_PLUS_Y = 1
DENSITY_UNITS_EXTINCTION = 1
DENSITY_UNITS_MIXING_RATIO = 3

FILES = {"vdb": "cumulus_y_up.vdb", "netcdf": "les_cumulus_ql.nc",
         "pvti": "automaton_extinction_km.pvti"}
ARRAYS = {"vdb": "density", "netcdf": "ql", "pvti": "extinction"}


# --- small helpers ------------------------------------------------------------------------
def set_property(proxy, name, value, failures):
    """proxy.name = value; a missing property is a failure (the feature has not landed)."""
    if proxy.GetProperty(name) is None:
        failures.append("%s has no property %s" % (proxy.GetXMLName(), name))
        return False
    proxy.SetPropertyWithName(name, value)
    return True


def get_property(proxy, name, default=None):
    prop = proxy.GetProperty(name)
    if prop is None:
        return default
    return prop.GetData()


def output_of(source):
    """The source's output data object (builtin session: the server's own object)."""
    return source.GetClientSideObject().GetOutputDataObject(0)


def luminance(pixels):
    """Rec. 709 luma of display-encoded pixels (0-255) as 0..1."""
    return (0.2126 * pixels[..., 0] + 0.7152 * pixels[..., 1] + 0.0722 * pixels[..., 2]) / 255.0


def cloud_mapper(view):
    """The visible vtkNimbusCloudVolumeMapper (None without `import nimbus`)."""
    try:
        import nimbus
    except ImportError:
        return None
    return nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())


# --- the data: where the cloud is ---------------------------------------------------------
def point_coordinates(data):
    """World coordinates of every point of an image or rectilinear grid, [n, 3], in VTK's
    point order (x fastest)."""
    if data.IsA("vtkRectilinearGrid"):
        axes = [vtk_to_numpy(data.GetXCoordinates()), vtk_to_numpy(data.GetYCoordinates()),
                vtk_to_numpy(data.GetZCoordinates())]
        z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
        return np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    dims = data.GetDimensions()
    extent = data.GetExtent()
    k, j, i = np.meshgrid(*(np.arange(extent[2 * a], extent[2 * a] + dims[a]) for a in (2, 1, 0)),
                          indexing="ij")
    index = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1).astype(float)
    origin = np.array(data.GetOrigin())
    spacing = np.array(data.GetSpacing())
    direction = np.array([data.GetDirectionMatrix().GetElement(r, c)
                          for r in range(3) for c in range(3)]).reshape(3, 3)
    return origin + (index * spacing) @ direction.T


def cloudy_points(data, array_name, fraction=0.1):
    """World points where the array exceeds `fraction` of its maximum (the cloud's body)."""
    array = data.GetPointData().GetArray(array_name)
    if array is None:
        array = data.GetCellData().GetArray(array_name)
        if array is None:
            return np.zeros((0, 3))
        # Cell data: the cell centres (not used by the sample files; kept for safety).
        from vtkmodules.vtkFiltersCore import vtkCellCenters
        centres = vtkCellCenters()
        centres.SetInputData(data)
        centres.Update()
        points = vtk_to_numpy(centres.GetOutput().GetPoints().GetData())
    else:
        points = point_coordinates(data)
    values = vtk_to_numpy(array).astype(float)
    if values.size == 0 or values.max() <= 0:
        return np.zeros((0, 3))
    return points[values > fraction * values.max()]


def box_corners(bounds):
    return np.array([[bounds[0 + a], bounds[2 + b], bounds[4 + c]]
                     for a in (0, 1) for b in (0, 1) for c in (0, 1)])


# Liquid water -> extinction: sigma = 3 LWC / (2 rho_w r_e) for droplets of effective radius
# r_e (Hansen & Travis 1974, Eq. 2.51 with Q_ext = 2; Stephens 1978), LWC = rho_air q_l.
RHO_WATER = 1000.0          # kg m-3
EFFECTIVE_RADIUS = 10e-6    # m: the Cloud representation's default droplet radius


def standard_atmosphere_density(z):
    """ICAO standard atmosphere, troposphere (ISO 2533): air density (kg m-3) at z metres."""
    return 1.225 * (1.0 - 0.0065 * z / 288.15) ** (9.80665 / (287.053 * 0.0065) - 1.0)


def largest_column_optical_depth(data, sigma, metres_per_unit):
    """max over (x, y) of the vertical optical depth, integral of sigma dz (trapezoids),
    for `sigma` (1/m) on the points of an image or rectilinear grid, [z, y, x]."""
    if data.IsA("vtkRectilinearGrid"):
        z = vtk_to_numpy(data.GetZCoordinates()).astype(float)
    else:
        z = data.GetOrigin()[2] + data.GetSpacing()[2] * np.arange(data.GetDimensions()[2])
    dz = np.diff(z) * metres_per_unit
    return float((0.5 * (sigma[1:] + sigma[:-1]) * dz[:, None, None]).sum(axis=0).max())


def grid_values(data, name):
    dims = data.GetDimensions()
    return vtk_to_numpy(data.GetPointData().GetArray(name)).astype(float).reshape(
        dims[2], dims[1], dims[0])


# --- the camera ---------------------------------------------------------------------------
def first_look(view, bounds, sun_azimuth_degrees):
    """The GUI's first look (11 degrees down, z up, camera fitted to the data), turned so
    that the sun is behind the viewer: looking toward azimuth sun + 180 degrees (azimuth
    from north (+y) toward east (+x), Physics/Sun.h)."""
    centre = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2,
              (bounds[4] + bounds[5]) / 2]
    azimuth = math.radians(sun_azimuth_degrees + 180.0)
    down = math.radians(11.0)
    look = [math.cos(down) * math.sin(azimuth), math.cos(down) * math.cos(azimuth),
            -math.sin(down)]
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[i] - look[i] for i in range(3)]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CameraViewAngle = 30.0
    view.ResetCamera(bounds, False)


def project(view, points):
    """Pixel (column, row from the top) of world points through the view's camera."""
    camera = GetActiveCamera()
    matrix = camera.GetCompositeProjectionTransformMatrix(SIZE[0] / SIZE[1], -1, 1)
    m = np.array([[matrix.GetElement(r, c) for c in range(4)] for r in range(4)])
    homogeneous = np.c_[points, np.ones(len(points))] @ m.T
    ndc = homogeneous[:, :3] / homogeneous[:, 3:4]
    columns = (ndc[:, 0] + 1.0) / 2.0 * SIZE[0]
    rows = SIZE[1] - (ndc[:, 1] + 1.0) / 2.0 * SIZE[1]
    return columns, rows


def horizon_row(view):
    """Row of the horizon of a flat ground: a far point level with the camera."""
    position = np.array(view.CameraPosition)
    look = np.array(view.CameraFocalPoint) - position
    look[2] = 0.0
    look /= np.linalg.norm(look)
    _, rows = project(view, (position + 1e6 * look)[None, :])
    return rows[0]


# --- the picture --------------------------------------------------------------------------
def grid_steps(data):
    """The largest distance between neighbouring points along x, y and z."""
    if data.IsA("vtkRectilinearGrid"):
        return [float(np.diff(vtk_to_numpy(axis)).max()) if axis.GetNumberOfTuples() > 1 else 0.0
                for axis in (data.GetXCoordinates(), data.GetYCoordinates(),
                             data.GetZCoordinates())]
    return list(data.GetSpacing())


def silhouette(view, points, steps):
    """Pixels covered by the projected points, each grown by the projected size of one grid
    step (so that the points' pixels join into the cloud's outline)."""
    covered = np.zeros((SIZE[1], SIZE[0]), dtype=bool)
    if len(points) == 0:
        return covered
    centre = points.mean(axis=0)
    probes = np.array([centre] + [centre + step * np.eye(3)[axis]
                                  for axis, step in enumerate(steps)])
    columns, rows = project(view, probes)
    reach = max(np.hypot(columns[1:] - columns[0], rows[1:] - rows[0]))
    radius = int(min(np.ceil(reach), 12)) + 1
    columns, rows = project(view, points)
    inside = (columns >= 0) & (columns < SIZE[0]) & (rows >= 0) & (rows < SIZE[1])
    covered[rows[inside].astype(int), columns[inside].astype(int)] = True
    grown = covered.copy()
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            if dx * dx + dy * dy > radius * radius:
                continue
            shifted = np.roll(np.roll(covered, dy, axis=0), dx, axis=1)
            grown |= shifted
    return grown


def cloud_mask(image, empty):
    """The cloud's pixels: where the image differs from the zero-extinction image."""
    return np.abs(image - empty).max(axis=2) > CLOUD_DIFF_LEVELS


def blob(mask):
    rows, columns = np.nonzero(mask)
    if len(rows) == 0:
        return None
    # 1st and 99th percentiles: single stray pixels (noise, a shaft) do not widen it.
    top, bottom = np.percentile(rows, [1, 99])
    left, right = np.percentile(columns, [1, 99])
    return {"pixels": int(len(rows)), "top": float(top), "bottom": float(bottom),
            "left": float(left), "right": float(right), "height": float(bottom - top + 1),
            "width": float(right - left + 1), "centre_column": float(columns.mean()),
            "centre_row": float(rows.mean())}


def convex_hull(points):
    """Andrew's monotone chain; counter-clockwise in (column, row-up) coordinates."""
    pts = sorted(set(map(tuple, points)))
    if len(pts) < 3:
        return pts

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def air_step_at_box(view, image, bounds, exclude, horizon):
    """The largest mean colour step (levels of 255) across the projected box outline.

    For every edge of the convex hull of the projected box, at 40 places along its middle
    80 %, the mean colours 2-4 px inside (n_in) and outside (n_out) the edge are compared,
    less the air's own gradient across the edge, estimated from 6-8 px inside (f_in) and
    outside (f_out): step = n_in - n_out - 6 g, g = ((f_in - n_in) + (n_out - f_out)) / 8
    per pixel inward (linear continuation over the 6 px between the two near bands). Places
    on the cloud (`exclude`, grown by 3 px), within 10 px of the horizon (where the ground
    meets the sky: a real edge) or outside the image are skipped; an edge needs 8 places.
    A lighter or darker box of air shows as a step of the same sign all along an edge."""
    columns, rows = project(view, box_corners(bounds))
    hull = convex_hull(list(zip(np.round(columns, 3), np.round(SIZE[1] - rows, 3))))
    grown = exclude.copy()
    for shift in range(1, 4):
        grown[shift:, :] |= exclude[:-shift, :]
        grown[:-shift, :] |= exclude[shift:, :]
        grown[:, shift:] |= exclude[:, :-shift]
        grown[:, :-shift] |= exclude[:, shift:]

    def band(p, inward, distances):
        colours = []
        for d in distances:
            column, row_up = p + d * inward
            row = SIZE[1] - row_up
            c, r = int(round(column)), int(round(row))
            if not (0 <= c < SIZE[0] and 0 <= r < SIZE[1]) or grown[r, c] or \
                    abs(row - horizon) < 10.0:
                return None
            colours.append(image[r, c])
        return np.mean(colours, axis=0)

    worst, edges = 0.0, []
    for a, b in zip(hull, hull[1:] + hull[:1]):
        a, b = np.array(a), np.array(b)
        edge = b - a
        length = np.linalg.norm(edge)
        if length < 20:
            continue
        inward = np.array([-edge[1], edge[0]]) / length   # counter-clockwise: left is in
        steps = []
        for t in np.linspace(0.1, 0.9, 40):
            p = a + t * edge
            bands = [band(p, inward, distances) for distances in
                     ((2, 3, 4), (6, 7, 8), (-2, -3, -4), (-6, -7, -8))]
            if any(x is None for x in bands):
                continue
            near_in, far_in, near_out, far_out = bands
            gradient = ((far_in - near_in) + (near_out - far_out)) / 8.0
            steps.append(near_in - near_out - 6.0 * gradient)
        if len(steps) < 8:
            continue
        step = np.abs(np.mean(steps, axis=0)).max()
        edges.append(round(float(step), 2))
        worst = max(worst, step)
    return worst, edges


def check_picture(view, display, source, array_name, name, output_dir, failures,
                  zero_extinction, tall=False, optical_depth=None):
    """Renders the user's image and the zero-extinction image and checks them (see the
    module's docstring). `zero_extinction(display)` makes the display's extinction zero
    and returns a function that puts it back. `optical_depth`: the data's largest vertical
    optical depth where the units are known (then a thick cloud must look thick). Returns
    the measurements."""
    data = output_of(source)
    bounds = source.GetDataInformation().GetBounds()
    image_path = os.path.join(output_dir, name + ".png")
    SaveScreenshot(image_path, view, ImageResolution=SIZE)
    image = read_png(image_path)
    mapper = cloud_mapper(view)
    last_ground = mapper.GetLastGroundHeight() if mapper is not None and \
        hasattr(mapper, "GetLastGroundHeight") else None

    restore = zero_extinction(display)
    empty_path = os.path.join(output_dir, name + "-zero-extinction.png")
    SaveScreenshot(empty_path, view, ImageResolution=SIZE)
    restore()
    Render(view)
    empty = read_png(empty_path)

    # The cloud's pixels: those that change when the cloud is there, within the projection of
    # its density. The rest of the change is its shadow on the ground and in the air.
    changed = cloud_mask(image, empty)
    cloudy = cloudy_points(data, array_name)
    covered = silhouette(view, cloudy, grid_steps(data))
    mask = changed & covered
    write_mask(mask, os.path.join(output_dir, name + "-cloud-pixels.png"))
    found = blob(mask)
    measured = {"blob": found, "bounds": list(bounds),
                "shadow_pixels": int((changed & ~covered).sum())}

    # --- not blank or blown out -----------------------------------------------------------
    fraction = mask.mean()
    measured["cloud_fraction"] = float(fraction)
    if fraction < MIN_CLOUD_FRACTION or found is None:
        failures.append("%s: blank: %.2f %% of the pixels show the cloud (at least %.1f %%)"
                        % (name, 100 * fraction, 100 * MIN_CLOUD_FRACTION))
    else:
        cloud = image[mask]
        mean_luminance = float(luminance(cloud).mean())
        saturated = float((cloud.min(axis=1) >= 254.5).mean())
        # The change the cloud makes to the picture, its shadow included.
        contrast = float(np.percentile(np.abs(image - empty).max(axis=2)[changed], 90))
        measured.update(mean_luminance=mean_luminance, saturated_fraction=saturated,
                        contrast_p90_levels=contrast)
        if not LUMINANCE_RANGE[0] <= mean_luminance <= LUMINANCE_RANGE[1]:
            failures.append("%s: the cloud's mean luminance %.3f is outside [%.2f, %.2f]" % (
                name, mean_luminance, LUMINANCE_RANGE[0], LUMINANCE_RANGE[1]))
        if saturated >= MAX_SATURATED_FRACTION:
            failures.append("%s: blown out: %.1f %% of the cloud's pixels are white at 255" % (
                name, 100 * saturated))
        # Units honoured: a cloud that the data says is optically thick is not a faint haze
        # (extinction wrong by orders of magnitude shows as a pale ghost of the cloud with a
        # faint shadow; a thick one has a dark shadow and a shaded side).
        if optical_depth is not None:
            measured["largest_column_optical_depth"] = optical_depth
            if optical_depth >= THICK_OPTICAL_DEPTH and contrast < THICK_CONTRAST_LEVELS:
                failures.append("%s: thin: the data's columns reach optical depth %.0f, but the "
                                "cloud changes its pixels by only %.0f levels (at least %.0f)" % (
                                    name, optical_depth, contrast, THICK_CONTRAST_LEVELS))

    # --- upright and above the ground -----------------------------------------------------
    # The ground the display draws must be at or below the cloud's lowest point: the
    # mapper's last ground height where we can read it, else the properties' meaning
    # (GroundBelowData: min(GroundHeight, the bottom of the data's box)).
    if len(cloudy):
        lowest = float(cloudy[:, 2].min())
        ground = float(get_property(display, "GroundHeight", 0.0))
        if get_property(display, "GroundBelowData", 0):
            ground = min(ground, bounds[4])
        if last_ground is not None:
            ground = last_ground
        measured.update(lowest_cloudy_z=lowest, ground_z=ground)
        if ground > lowest + 1e-6 * max(1.0, abs(lowest)):
            failures.append("%s: the ground (z = %g) cuts the cloud (lowest cloudy point z = %g)"
                            % (name, ground, lowest))
    if found is not None and len(cloudy):
        # Where the density says the cloud is, through the same camera.
        columns, rows = project(view, cloudy)
        expected = {"top": float(rows.min()), "bottom": float(rows.max()),
                    "left": float(columns.min()), "right": float(columns.max())}
        expected["height"] = expected["bottom"] - expected["top"] + 1
        expected["width"] = expected["right"] - expected["left"] + 1
        measured["expected_blob"] = expected
        # As tall and as wide as the cloud (a cloud seen on its side, or hidden in part,
        # is not); its edges fade, so 65 % of the projected extent of the density above
        # a tenth of its maximum is enough.
        if found["height"] < 0.65 * expected["height"]:
            failures.append("%s: the cloud's pixels span %.0f rows, the cloud %.0f" % (
                name, found["height"], expected["height"]))
        if found["width"] < 0.65 * expected["width"]:
            failures.append("%s: the cloud's pixels span %.0f columns, the cloud %.0f" % (
                name, found["width"], expected["width"]))
        # Not cut by the ground: the pixels reach down to the lowest cloudy point's row
        # (within 12 % of the cloud's projected height; a ground through the cloud hides
        # everything below it, a quarter of the .vdb's tower).
        if found["bottom"] < expected["bottom"] - 0.12 * expected["height"]:
            failures.append("%s: the cloud's pixels end at row %.0f, the cloud at row %.0f: "
                            "its bottom is hidden" % (name, found["bottom"], expected["bottom"]))
        if tall and found["height"] < 1.3 * found["width"]:
            # The .vdb's cloud is a tower about twice as tall as wide: upright it is a tall
            # blob; lying on its side (the wrong up axis) it is not.
            failures.append("%s: the tower's pixels are %.0f x %.0f (w x h): not upright" % (
                name, found["width"], found["height"]))

    # --- seamless air ---------------------------------------------------------------------
    horizon = horizon_row(view)
    no_cloud = np.zeros(mask.shape, dtype=bool)
    step_empty, edges_empty = air_step_at_box(view, empty, bounds, no_cloud, horizon)
    step_image, edges_image = air_step_at_box(view, image, bounds, changed, horizon)
    measured.update(air_step_zero_extinction=float(step_empty), air_edges_zero=edges_empty,
                    air_step_image=float(step_image), air_edges_image=edges_image)
    for label, step in (("zero-extinction image", step_empty), ("image", step_image)):
        if step > AIR_STEP_LEVELS:
            failures.append("%s: the air steps by %.1f levels at the box's outline in the %s"
                            % (name, step, label))
    print("%s: %s" % (name, json.dumps(measured, default=lambda x: round(x, 3))))
    return measured


def write_mask(mask, path):
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    image = vtkImageData()
    image.SetDimensions(mask.shape[1], mask.shape[0], 1)
    values = (mask[::-1, :] * 255).astype(np.uint8).ravel()
    array = numpy_to_vtk(values, deep=1)
    image.GetPointData().SetScalars(array)
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()


def make_view():
    view = CreateRenderView()
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [0.0, 0.0, 0.0]   # the Cloud representation draws the sky over it
    return view


def show_as_cloud(source, view, failures):
    display = Show(source, view)
    available = list(display.GetProperty("Representation").Available)
    if "Cloud" not in available:
        failures.append("'Cloud' is not offered for %s (%s): %s" % (
            source.GetXMLName(), source.GetDataInformation().GetDataSetTypeAsString(),
            available))
        return display
    display.SetRepresentationType("Cloud")
    return display


def zero_extinction(display):
    """The density's extinction scaled to zero: dimensionless units times 0 per metre.
    The data, its box and the ground stay as they are."""
    kept = {name: get_property(display, name) for name in ("DensityUnits", "ExtinctionPerDensity")}
    if display.GetProperty("DensityUnits") is not None:
        display.DensityUnits = 0
    display.ExtinctionPerDensity = 0.0

    def restore():
        for name, value in kept.items():
            if value is not None:
                display.SetPropertyWithName(name, value)
    return restore


# --- the cases ----------------------------------------------------------------------------
def case_vdb(path, view, output_dir, failures):
    """Houdini's y-up fog volume: the user says +Y is up (the reader's UpAxis)."""
    start = time.time()
    reader = OpenDataFile(path)
    if reader is None or reader.GetXMLName() != "NimbusOpenVDBReader":
        failures.append("OpenDataFile did not pick the Nimbus reader")
        return {}
    set_property(reader, "UpAxis", UP_AXIS_PLUS_Y, failures)
    reader.UpdatePipeline()
    display = show_as_cloud(reader, view, failures)
    bounds = reader.GetDataInformation().GetBounds()
    first_look(view, bounds, display.SunAzimuthDegrees)
    Render(view)
    seconds = time.time() - start

    # The reader's turn: +Y up means U = (x, -z, y) (Physics/UpAxis.h), about the origin.
    turned = output_of(reader)
    raw_reader = OpenDataFile(path)
    if raw_reader.GetProperty("UpAxis") is not None:
        raw_reader.UpAxis = 2   # +Z: the file as it is
    raw_reader.UpdatePipeline()
    raw = output_of(raw_reader)
    b = raw.GetBounds()
    expected = [b[0], b[1], -b[5], -b[4], b[2], b[3]]
    if not np.allclose(bounds, expected, atol=1e-6 * (1 + np.abs(expected).max())):
        failures.append("vdb: the turned bounds %s are not R(+Y) of the file's %s (%s)" % (
            list(np.round(bounds, 3)), list(np.round(b, 3)), list(np.round(expected, 3))))
    else:
        # Values follow their points: a sample of the file's cloudy voxels, turned, holds
        # the same density in the reader's output.
        values = vtk_to_numpy(raw.GetPointData().GetArray("density"))
        points = point_coordinates(raw)
        chosen = np.nonzero(values > 0.2)[0][::97]
        out = turned.GetPointData().GetArray("density")
        wrong = 0
        for index in chosen:
            x, y, z = points[index]
            found = turned.FindPoint(x, -z, y)
            if found < 0 or abs(out.GetValue(found) - values[index]) > 1e-6:
                wrong += 1
        if wrong:
            failures.append("vdb: %d of %d sampled voxels moved or changed in the turn" % (
                wrong, len(chosen)))
    measured = check_picture(view, display, reader, "density", "vdb", output_dir, failures,
                             zero_extinction, tall=True)
    measured["seconds_to_first_image"] = seconds
    return measured


def case_netcdf(path, view, output_dir, failures):
    """LES output: ql in kg/kg on a stretched grid in metres, three time steps."""
    start = time.time()
    reader = NetCDFReader(FileName=[path])
    # The user's knowledge: x and y are metres on a flat grid, not longitude and latitude.
    reader.SphericalCoordinates = 0
    steps = list(reader.TimestepValues)
    reader.UpdatePipeline(steps[0] if steps else 0.0)
    info = reader.GetDataInformation()
    kind = info.GetDataSetTypeAsString()
    display = show_as_cloud(reader, view, failures)
    # The reader sets no active scalars: the user picks ql in the colouring menu.
    ColorBy(display, ("POINTS", "ql"))
    set_property(display, "DensityUnits", DENSITY_UNITS_MIXING_RATIO, failures)
    bounds = info.GetBounds()
    first_look(view, bounds, display.SunAzimuthDegrees)
    Render(view)
    seconds = time.time() - start

    data = output_of(reader)
    if len(steps) != 3:
        failures.append("netcdf: %d time steps, expected 3: %s" % (len(steps), steps))
    if kind != "vtkRectilinearGrid":
        failures.append("netcdf: the reader made a %s, expected vtkRectilinearGrid" % kind)
    else:
        z = vtk_to_numpy(data.GetZCoordinates())
        dz = np.diff(z)
        if len(z) != 40 or dz.max() < 3.0 * dz.min():
            failures.append("netcdf: z has %d levels, spacing %.1f..%.1f m: not the stretched "
                            "grid" % (len(z), dz.min(), dz.max()))
    tau = None
    if data.GetPointData().GetArray("ql") is None:
        failures.append("netcdf: no point array ql")
    elif data.IsA("vtkRectilinearGrid"):
        ql = grid_values(data, "ql")
        z = vtk_to_numpy(data.GetZCoordinates()).astype(float)
        sigma = 3.0 * standard_atmosphere_density(z)[:, None, None] * ql / (
            2.0 * RHO_WATER * EFFECTIVE_RADIUS)
        tau = largest_column_optical_depth(data, sigma, 1.0)
    measured = check_picture(view, display, reader, "ql", "netcdf", output_dir, failures,
                             zero_extinction, optical_depth=tau)
    measured.update(seconds_to_first_image=seconds, data_type=kind, time_steps=steps)

    # The cloud drifts with the wind (+x, 300 m per step): at the last step the cloud's
    # pixels move the way the density's projected centre moves.
    if len(steps) == 3 and measured.get("blob"):
        view.ViewTime = steps[-1]
        reader.UpdatePipeline(steps[-1])
        late = check_picture(view, display, reader, "ql", "netcdf-last-step", output_dir,
                             failures, zero_extinction, optical_depth=tau)
        cloudy_first = cloudy_points(output_of_at(reader, steps[0]), "ql")
        cloudy_last = cloudy_points(output_of_at(reader, steps[-1]), "ql")
        if late.get("blob") and len(cloudy_first) and len(cloudy_last):
            c0, _ = project(view, cloudy_first.mean(axis=0)[None, :])
            c1, _ = project(view, cloudy_last.mean(axis=0)[None, :])
            expected_shift = float(c1[0] - c0[0])
            shift = late["blob"]["centre_column"] - measured["blob"]["centre_column"]
            measured.update(drift_columns=shift, expected_drift_columns=expected_shift)
            if (abs(expected_shift) > 4 and shift * expected_shift <= 0) or \
                    abs(shift) < 0.4 * abs(expected_shift):
                failures.append("netcdf: the cloud moved %.1f columns between the first and the "
                                "last step, the data %.1f" % (shift, expected_shift))
        view.ViewTime = steps[0]
        reader.UpdatePipeline(steps[0])
    return measured


def output_of_at(reader, t):
    reader.UpdatePipeline(t)
    copy = output_of(reader).NewInstance()
    copy.DeepCopy(output_of(reader))
    return copy


def case_pvti(path, view, output_dir, failures):
    """Extinction in 1/m on a grid in km (four .vti pieces)."""
    start = time.time()
    reader = OpenDataFile(path)
    reader.UpdatePipeline()
    display = show_as_cloud(reader, view, failures)
    set_property(display, "DensityUnits", DENSITY_UNITS_EXTINCTION, failures)
    display.MetresPerUnit = 1000.0
    bounds = reader.GetDataInformation().GetBounds()
    first_look(view, bounds, display.SunAzimuthDegrees)
    Render(view)
    seconds = time.time() - start
    data = output_of(reader)
    tau = largest_column_optical_depth(data, grid_values(data, "extinction"), 1000.0)
    measured = check_picture(view, display, reader, "extinction", "pvti", output_dir, failures,
                             zero_extinction, optical_depth=tau)
    measured["seconds_to_first_image"] = seconds
    return measured


CASES = {"vdb": case_vdb, "netcdf": case_netcdf, "pvti": case_pvti}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--data-dir", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--case", required=True, choices=sorted(CASES))
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    path = os.path.join(args.data_dir, FILES[args.case])
    if not os.path.exists(path):
        print("FAIL: no file", path)
        return 1
    LoadPlugin(args.plugin, ns=globals())
    failures = []
    view = make_view()
    measured = CASES[args.case](path, view, args.output_dir, failures)
    measured["failures"] = failures
    # Displays, view and readers deleted before Python exits (pvpython otherwise dies in
    # its X/GL teardown and the exit status is lost).
    for representation in list(view.Representations):
        Delete(representation)
    Delete(view)
    del view
    for source in list(GetSources().values()):
        Delete(source)
    with open(os.path.join(args.output_dir, "user-data-%s.json" % args.case), "w") as f:
        json.dump(measured, f, indent=1, default=float)
    if "seconds_to_first_image" in measured:
        print("%s: %.2f s from opening the file to the first image" % (
            args.case, measured["seconds_to_first_image"]))
    for failure in failures:
        print("FAIL:", failure)
    if failures:
        return 1
    print("user data %s OK" % args.case)
    return 0


if __name__ == "__main__":
    sys.exit(main())
