"""pvpython test of the view's own lights on the Cloud representation (the Lights group).

    pvpython TestPluginLights.py --plugin Nimbus.so --output-dir DIR

The scene of Examples/Python/lamp_in_fog_paraview.py, smaller: a zero-density grid shown
as Cloud (the air only) with Fog Visibility 80 m at night (sun 10 degrees below the
horizon), a 35-degree spotlight added through the proxy API (AddLight, Type
Positional) 4.5 m up, and a post (a Box) 1.4 m in front of it. Every pixel is
classified from the camera and the scene's geometry alone (no image): its view ray
sampled every 0.1 m up to the ground, the post or 60 m, against the beam's cone.

Checks:
  1. the Lights group's properties exist with the mapper's defaults and reach it
     (with `import nimbus`: one light drawn, the post among the shadow casters);
  2. the beam: the mean of the pixels whose ray crosses at least 2 m of the beam is at
     least BEAM_FACTOR times that of the pixels whose ray misses it (and their ground
     point is outside it), and at least BEAM_MIN_LEVEL (linear luminance of the
     screenshot's sRGB pixels, 0 to 1; every measure below is in it);
  3. Lights Used = None: the beam's pixels fall below NONE_FRACTION of their mean (at
     night nothing else lights the fog);
  4. the post's shadow: on the ground inside the beam, the pixels whose ground point
     the post hides from the lamp are at most GROUND_SHADOW_FRACTION of the same pixels
     with the post hidden; in the fog (rays crossing at least 0.5 m of the post's
     shadow volume inside the beam, not ending on the lit ground), at most
     FOG_SHADOW_FRACTION of the same pixels with Light Shadow Map Size 0;
  5. a light map whose left half is black dims the beam (LIGHT_MAP_KEPT of it kept);
  6. a light-map file that cannot be read (missing; not an image) gives an error
     naming the file, and the view still renders the beam without a map; a partial
     name (no such file, no image extension: the GUI's field sets each name typed on
     the way) gives none.
"""
import argparse
import math
import os
import sys

import numpy as np
from vtkmodules.util.misc import calldata_type
from vtkmodules.util.vtkConstants import VTK_STRING
from paraview.simple import (AddLight, Box, Calculator, ColorBy, CreateRenderView, Delete,
                             Hide, LoadPlugin, Render, SaveScreenshot, Show, Wavelet)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from image_compare import read_png  # noqa: E402

SIZE = [400, 250]
LAMP = np.array([0.0, 0.0, 4.5])
AIM = np.array([7.0, 0.0, 0.5])
CONE_DEGREES = 35.0
POST_BOUNDS = np.array([1.15, 1.65, -0.25, 0.25, 0.0, 3.6])  # x, y, z ranges (metres)
# At eye height beside the lamp, looking down the street: many view rays cross the beam and
# the post's shadow in it above the horizon, with nothing lit behind them.
CAMERA = dict(position=[-3.0, -8.0, 1.7], focal=[4.0, 0.0, 2.5], up=[0.0, 0.0, 1.0], angle=42.0)

# Thresholds, with what the test measured (llvmpipe, Xvfb/GLX): beam 0.0432 inside, 0.00014
# outside (a factor of 319); None 0.0 %; ground shadow 0.021; fog shadow 0.724, where a
# single-scattering quadrature of the same pixels (the cone, 1/d^2, the fog's extinction
# and its Cornette-Shanks phase, g 0.76) gives 0.733; the half-black light map 45.5 %.
BEAM_FACTOR = 20.0         # inside / outside the beam
BEAM_MIN_LEVEL = 0.02      # the beam's mean linear luminance (sRGB 40 of 255)
NONE_FRACTION = 0.01       # Lights Used = None: the beam's pixels keep less than this
GROUND_SHADOW_FRACTION = 0.2
FOG_SHADOW_FRACTION = 0.85
LIGHT_MAP_KEPT = (0.2, 0.8)

# The mapper's defaults of the Lights group (vtkNimbusCloudVolumeMapper.h), and the
# representation's own (0: no fog, no light map).
LIGHTS_DEFAULTS = {
    "LightSources": 1,
    "LightIntensityScale": 1.0,
    "SpotEdgeWidthDegrees": 2.0,
    "LightShaftMethod": 0,
    "LightSamples": 16,
    "LightShaftDownsampling": 2,
    "NumberOfVirtualPlanes": 64,
    "LightShadowMapSize": 256,
    "LightCloudSteps": 48,
    "MaximumLights": 8,
}


def cloud_mapper(view):
    """The visible vtkNimbusCloudVolumeMapper in the view (None without `import nimbus`)."""
    try:
        import nimbus
    except ImportError:
        return None
    return nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())


def scalar(display, name):
    """The display's property `name` as a number (an enumeration's value)."""
    return float(display.SMProxy.GetProperty(name).GetElement(0))


def view_rays():
    """Unit view rays through every pixel centre, [row (top first), column, xyz]."""
    eye = np.array(CAMERA["position"])
    forward = np.array(CAMERA["focal"]) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, CAMERA["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half_height = math.tan(math.radians(CAMERA["angle"]) / 2.0)
    half_width = half_height * SIZE[0] / SIZE[1]
    columns = (np.arange(SIZE[0]) + 0.5) / SIZE[0] * 2.0 - 1.0
    rows = 1.0 - (np.arange(SIZE[1]) + 0.5) / SIZE[1] * 2.0
    x = columns[None, :, None] * half_width
    y = rows[:, None, None] * half_height
    rays = forward + x * right + y * up
    return eye, rays / np.linalg.norm(rays, axis=2, keepdims=True)


def box_entry(origin, directions, bounds):
    """Distance along each ray to where it enters the box (inf: it misses)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (bounds[0::2] - origin) / directions
        t1 = (bounds[1::2] - origin) / directions
    near = np.nanmax(np.minimum(t0, t1), axis=-1)
    far = np.nanmin(np.maximum(t0, t1), axis=-1)
    return np.where((far >= near) & (far > 0.0), np.maximum(near, 0.0), np.inf)


def in_beam(points):
    """Whether points lie inside the spotlight's cone (its full angle, edge included)."""
    axis = (AIM - LAMP) / np.linalg.norm(AIM - LAMP)
    v = points - LAMP
    along = v @ axis
    return along > np.cos(math.radians(CONE_DEGREES)) * np.linalg.norm(v, axis=-1)


def in_post_shadow(points):
    """Whether the post lies between points and the lamp."""
    d = LAMP - points
    length = np.linalg.norm(d, axis=-1)
    t = box_entry(points, d / length[..., None], POST_BOUNDS)
    return t < length - 1e-3


def classify():
    """Pixel masks from the geometry: the beam's inside and outside, the ground shadow
    inside the beam, the fog shadow."""
    eye, rays = view_rays()
    ground = np.where(rays[..., 2] < 0.0, -eye[2] / np.minimum(rays[..., 2], -1e-12), np.inf)
    post = box_entry(eye, rays, POST_BOUNDS)
    end = np.minimum(np.minimum(ground, post), 60.0)
    steps = np.arange(0.05, 60.0, 0.1)
    beam_length = np.zeros(rays.shape[:2])
    shadow_length = np.zeros(rays.shape[:2])
    for row in range(rays.shape[0]):
        points = eye + rays[row, :, None, :] * steps[None, :, None]  # column, step, xyz
        alive = steps[None, :] < end[row, :, None]
        inside = in_beam(points) & alive
        beam_length[row] = 0.1 * inside.sum(axis=1)
        shadowed = np.zeros_like(inside)
        shadowed[inside] = in_post_shadow(points[inside])
        shadow_length[row] = 0.1 * shadowed.sum(axis=1)
    hits_ground = np.isfinite(ground) & (ground < post) & (ground < 60.0)
    ground_point = eye + rays * np.where(hits_ground, ground, 0.0)[..., None]
    ground_lit = hits_ground & in_beam(ground_point)
    ground_shadow = ground_lit & in_post_shadow(ground_point)
    hits_post = np.isfinite(post) & (post < ground)
    masks = {
        "beam": (beam_length >= 2.0) & ~hits_post & ~ground_shadow,
        "outside": (beam_length == 0.0) & ~hits_post & ~ground_lit,
        "ground shadow": ground_shadow,
        "fog shadow": (shadow_length >= 0.5) & ~hits_post & ~ground_lit,
    }
    for name, mask in masks.items():
        print("pixels %-14s %6d" % (name, int(mask.sum())))
    return masks


def luminance(path):
    """A screenshot's linear luminance (its sRGB pixels decoded), 0 to 1."""
    x = read_png(path) / 255.0
    x = np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
    return 0.2126 * x[..., 0] + 0.7152 * x[..., 1] + 0.0722 * x[..., 2]


class ErrorLog:
    """Errors of the Cloud representation (its ErrorEvent), printed as they come."""

    def __init__(self, display):
        self.messages = []
        # The composite representation's active one: the Cloud (vtkNimbusCloudRepresentation).
        representation = display.GetClientSideObject().GetActiveRepresentation()
        print("error log on", representation.GetClassName())
        representation.AddObserver("ErrorEvent", self.error)

    @calldata_type(VTK_STRING)
    def error(self, caller, event, message=None):
        text = str(message) if message is not None else "(no text)"
        print("error event:", text.strip())
        self.messages.append(text)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output-dir", required=True)
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    failures = []
    LoadPlugin(args.plugin, ns=globals())

    view = CreateRenderView()
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = [0.0, 0.0, 0.0]
    view.EnableRenderOnInteraction = 0
    view.UseLight = 0

    grid = Wavelet(WholeExtent=[-8, 8, -6, 12, 0, 8])
    air = Calculator(Input=grid, ResultArrayName="density", Function="0")
    display = Show(air, view)
    display.SetRepresentationType("Cloud")
    ColorBy(display, ("POINTS", "density"))
    errors = ErrorLog(display)

    # 1. The group's defaults, before the test sets any.
    for name, default in LIGHTS_DEFAULTS.items():
        if abs(scalar(display, name) - default) > 1e-12:
            failures.append("%s: XML default %g, the mapper's is %g"
                            % (name, scalar(display, name), default))
    if display.LightMapFile != "" or scalar(display, "FogVisibilityMetres") != 0.0:
        failures.append("LightMapFile %r, FogVisibilityMetres %g: expected '' and 0"
                        % (display.LightMapFile, scalar(display, "FogVisibilityMetres")))
    try:
        import nimbus
        fresh = nimbus.vtkNimbusCloudVolumeMapper()
        for name, default in LIGHTS_DEFAULTS.items():
            own = float(getattr(fresh, "Get" + name)())
            if abs(own - default) > 1e-12:
                failures.append("%s: the mapper's default is %g, the XML's %g" % (name, own, default))
    except ImportError:
        pass
    print("Lights Used offers", list(display.GetProperty("LightSources").Available))
    print("Light Shaft Method offers", list(display.GetProperty("LightShaftMethod").Available))

    display.SunElevationDegrees = -10.0
    display.FogVisibilityMetres = 80.0
    display.Exposure = 800.0

    light = AddLight(view=view)
    light.Coords = "Scene"
    light.Type = "Positional"
    light.Position = list(LAMP)
    light.FocalPoint = list(AIM)
    light.ConeAngle = CONE_DEGREES
    light.Intensity = 1.0

    post = Box(XLength=0.5, YLength=0.5, ZLength=3.6, Center=[1.4, 0.0, 1.8])
    post_display = Show(post, view)
    post_display.DiffuseColor = [0.35, 0.33, 0.3]

    Render(view)  # the first Render resets the camera
    view.CameraPosition = CAMERA["position"]
    view.CameraFocalPoint = CAMERA["focal"]
    view.CameraViewUp = CAMERA["up"]
    view.CameraViewAngle = CAMERA["angle"]

    def shot(name):
        Render(view)
        path = os.path.join(args.output_dir, "TestPluginLights-%s.png" % name)
        SaveScreenshot(path, view, ImageResolution=SIZE)
        return luminance(path)

    masks = classify()
    for name, mask in masks.items():
        if mask.sum() < 200:
            failures.append("only %d pixels %s: the test's scene is not what it expects"
                            % (int(mask.sum()), name))

    def mean(image, name):
        return float(image[masks[name]].mean())

    lit = shot("lit")
    mapper = cloud_mapper(view)
    if mapper is not None:
        # The fog's Mie scattering: 0.9 x 3.912 / 80 m.
        expected_mie = 0.9 * 3.912 / 80.0
        print("mapper: lights %d, shadow casters %d, Mie scattering %.6g /m (expected %.6g)" % (
            mapper.GetNumberOfLightsLastRender(), mapper.GetNumberOfShadowCastersLastRender(),
            mapper.GetMieScatteringPerMetre(), expected_mie))
        if mapper.GetNumberOfLightsLastRender() != 1:
            failures.append("the mapper drew %d lights, expected 1"
                            % mapper.GetNumberOfLightsLastRender())
        if mapper.GetNumberOfShadowCastersLastRender() < 1:
            failures.append("the post casts no shadow (no shadow casters)")
        if abs(mapper.GetMieScatteringPerMetre() - expected_mie) > 1e-9:
            failures.append("Fog Visibility 80 m gave Mie scattering %g, expected %g"
                            % (mapper.GetMieScatteringPerMetre(), expected_mie))
        # Every property of the group through the proxy reaches the mapper.
        trial = {"LightIntensityScale": 2.0, "SpotEdgeWidthDegrees": 5.0, "LightShaftMethod": 1,
                 "LightSamples": 16, "NumberOfVirtualPlanes": 32, "LightShadowMapSize": 128,
                 "LightCloudSteps": 6, "MaximumLights": 4, "LightSources": 0}
        for name, value in trial.items():
            display.SetPropertyWithName(name, value)
        display.UpdateVTKObjects()
        for name, value in trial.items():
            got = float(getattr(mapper, "Get" + name)())
            if abs(got - value) > 1e-12:
                failures.append("%s = %g did not reach the mapper (it has %g)" % (name, value, got))
        for name, value in LIGHTS_DEFAULTS.items():
            display.SetPropertyWithName(name, value)
        display.UpdateVTKObjects()

    # 2. The beam.
    beam, outside = mean(lit, "beam"), mean(lit, "outside")
    print("beam: inside %.5f, outside %.5f: factor %.1f (at least %g), inside at least %g"
          % (beam, outside, beam / max(outside, 1e-9), BEAM_FACTOR, BEAM_MIN_LEVEL))
    if not (beam >= BEAM_MIN_LEVEL and beam >= BEAM_FACTOR * outside):
        failures.append("no beam: inside %.5f, outside %.5f" % (beam, outside))

    # 3. Lights Used = None.
    display.LightSources = 0
    none = shot("none")
    display.LightSources = 1
    kept = mean(none, "beam") / max(beam, 1e-6)
    print("Lights Used = None: the beam's pixels %.5f (%.1f %% of lit; at most %g %%)"
          % (mean(none, "beam"), 100.0 * kept, 100.0 * NONE_FRACTION))
    if kept > NONE_FRACTION:
        failures.append("Lights Used = None leaves %.1f %% of the beam" % (100.0 * kept))

    # 4. The post's shadow: on the ground (post hidden) and in the fog (shadow maps off).
    Hide(post, view)
    no_post = shot("no-post")
    Show(post, view)
    ground_ratio = mean(lit, "ground shadow") / max(mean(no_post, "ground shadow"), 1e-6)
    print("ground shadow: %.5f with the post, %.5f without: %.3f (at most %g)"
          % (mean(lit, "ground shadow"), mean(no_post, "ground shadow"), ground_ratio,
             GROUND_SHADOW_FRACTION))
    if ground_ratio > GROUND_SHADOW_FRACTION:
        failures.append("the post's shadow on the ground keeps %.3f of the light" % ground_ratio)
    display.LightShadowMapSize = 0
    no_shadows = shot("no-shadow-maps")
    display.LightShadowMapSize = LIGHTS_DEFAULTS["LightShadowMapSize"]
    fog_ratio = mean(lit, "fog shadow") / max(mean(no_shadows, "fog shadow"), 1e-6)
    print("fog shadow: %.5f with shadow maps, %.5f without: %.3f (at most %g)"
          % (mean(lit, "fog shadow"), mean(no_shadows, "fog shadow"), fog_ratio,
             FOG_SHADOW_FRACTION))
    if fog_ratio > FOG_SHADOW_FRACTION:
        failures.append("the post's shadow in the fog keeps %.3f of the light" % fog_ratio)

    # 5. A light map, its left half black.
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    half = vtkImageData()
    half.SetDimensions(64, 64, 1)
    half.AllocateScalars(3, 1)  # VTK_UNSIGNED_CHAR
    scalars = half.GetPointData().GetScalars()
    for j in range(64):
        for i in range(64):
            scalars.SetValue(j * 64 + i, 0 if i < 32 else 255)
    map_path = os.path.join(args.output_dir, "TestPluginLights-half-map.png")
    writer = vtkPNGWriter()
    writer.SetFileName(map_path)
    writer.SetInputData(half)
    writer.Write()
    display.LightMapFile = map_path
    mapped = shot("light-map")
    kept = mean(mapped, "beam") / max(beam, 1e-6)
    print("half-black light map: the beam keeps %.1f %% (between %g and %g %%)"
          % (100.0 * kept, 100.0 * LIGHT_MAP_KEPT[0], 100.0 * LIGHT_MAP_KEPT[1]))
    if not LIGHT_MAP_KEPT[0] <= kept <= LIGHT_MAP_KEPT[1]:
        failures.append("the half-black light map kept %.1f %% of the beam" % (100.0 * kept))
    if errors.messages:
        failures.append("a valid light map gave errors: %s" % errors.messages)

    # 6. Light-map files that cannot be read: an error naming each, the beam still drawn.
    not_an_image = os.path.join(args.output_dir, "TestPluginLights-not-an-image.png")
    with open(not_an_image, "w") as stream:
        stream.write("this is not a PNG\n")
    for bad in (os.path.join(args.output_dir, "no-such-light-map.png"), not_an_image):
        before = len(errors.messages)
        display.LightMapFile = bad
        image = shot("bad-map-%d" % before)
        named = [m for m in errors.messages[before:] if os.path.basename(bad) in m]
        beam_after = mean(image, "beam")
        print("bad light map %s: %d error(s) naming it; beam %.5f (lit %.5f)"
              % (os.path.basename(bad), len(named), beam_after, beam))
        if not named:
            failures.append("no error for the light-map file %s" % bad)
        if abs(beam_after - beam) > 0.02 * beam:
            failures.append("after the bad light map %s the beam is %.5f, without a map %.5f"
                            % (bad, beam_after, beam))
    # A name being typed in the GUI's field (no such file, no image extension yet): no
    # error, no map.
    before = len(errors.messages)
    display.LightMapFile = os.path.join(args.output_dir, "partial-na")
    partial = mean(shot("partial-name"), "beam")
    print("partial name: %d error(s); beam %.5f" % (len(errors.messages) - before, partial))
    if len(errors.messages) != before or abs(partial - beam) > 0.02 * beam:
        failures.append("a partial name gave errors %s or changed the beam (%.5f)"
                        % (errors.messages[before:], partial))
    display.LightMapFile = ""

    for failure in failures:
        print("FAILED:", failure)
    print("lights test", "FAILED" if failures else "passed")
    # Release the view's OpenGL context while the X connection is still open.
    Delete(display)
    Delete(view)
    del display, view
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
