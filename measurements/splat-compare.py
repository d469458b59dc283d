"""Billboard splatting (vtkNimbusCloudSplatMapper, 002 §3.3) against the references.

For each ball count N a cloud of N metaballs (centres uniform in an ellipsoid of
semi-axes 1200, 1200, 500 m centred 1600 m up, radius R = 250 m (1000 / N)^(1/3), so
that every count fills the same volume with the same mean density) is

  * drawn by splatting (the accumulation texture and, for N <= --readback-max, the
    read-back variant), timed as the median of --repeats frames that redo the sun pass;
  * voxelised by vtkNimbusMetaballCloudSource (AddBall, no growth, no flat base) on a
    --grid grid, written as a .vti and drawn by
      - vtkNimbusCloudVolumeMapper (shadow-view slices, single scattering: no k_multi,
        no multiple-scattering method, no air, no ground), timed likewise;
      - the reference renderer: converged single scattering ("single", the same physics
        as splatting) and the path tracer (multiple scattering, --path-seconds).

With --multiple-scattering, two more rows per count draw the splats with the mapper's
MultipleScattering option (the balls splatted onto a --ms-grid-size grid, the sun's light
of all orders solved there and added per sample): "splat-texture-ms" (SunLightSamples
--samples) and "splat-texture-centre-ms" (0: at each ball's centre), their frame exposed
by the path tracer's brightest pixel (the single reference's would saturate the 8-bit
frame); their seconds per frame include a solve (every frame marks the balls modified),
given apart as ms_solve_seconds; and unless --splats-only, "svs-ms": the SVS mapper with
its own multiple scattering (DiscreteDirections, its automatic grid) on the voxelised grid. --splats-only leaves out the read-back and the SVS rows.

Errors over the cloud (pixels where the single-scattering reference exceeds 1e-3 of its
99th percentile): the ratio of means (image / reference) and the RMSE (in the sun's
relative radiance units), each renderer against each reference. One CSV row per
(N, renderer). Run through Testing/with-display.sh (or NIMBUS_OFFSCREEN=egl), under
flock /tmp/nimbus-measure.lock.

    flock /tmp/nimbus-measure.lock Testing/with-display.sh /usr/bin/python3 \
        measurements/splat-compare.py --counts 1000 10000 100000 1000000 --output build/splats

With --sky-bench only the cost of the sky's terms is timed (sky_bench): the balls over a
Nimbus sky, the mapper following it or not, camera moves and sun moves:

    flock /tmp/nimbus-measure.lock Testing/with-display.sh /usr/bin/python3 \
        measurements/splat-compare.py --sky-bench --counts 1000 10000 --repeats 5
"""
import argparse
import csv
import json
import os
import statistics
import sys
import time

import numpy as np

import nimbus
from nimbus import harness
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints, vtkFloatArray
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

VTK_SCALE = harness.VTK_SCALE
CAMERA = {"position": [0, -6000, 1500], "focal_point": [0, 0, 1550], "view_up": [0, 0, 1],
          "view_angle": 30, "width": 320, "height": 240}
# The sun behind the cloud, 30 degrees up (scattering angle about 35 degrees toward the
# camera): forward scattering, where single scattering is bright enough to compare.
SUN = {"azimuth_degrees": 20, "elevation_degrees": 30, "illuminance": 1,
       "temperature_kelvin": 5778}
EXTINCTION = 0.02
ALBEDO = 0.99
G = 0.85
BALL_DENSITY = 0.25
BOUNDS = [-1600, 1600, -1600, 1600, 900, 2300]


def make_balls(count, seed=1):
    random = np.random.default_rng(seed)
    radius = 250.0 * (1000.0 / count) ** (1.0 / 3.0)
    points = []
    while sum(len(p) for p in points) < count:
        candidates = random.uniform(-1.0, 1.0, size=(count, 3))
        points.append(candidates[np.sum(candidates ** 2, axis=1) <= 1.0])
    unit = np.concatenate(points)[:count]
    centres = unit * np.array([1200.0, 1200.0, 500.0]) + np.array([0.0, 0.0, 1600.0])
    return centres, radius


def balls_polydata(centres, radius):
    points = vtkPoints()
    points.SetData(numpy_to_vtk(centres.astype(np.float32), deep=True))
    poly = vtkPolyData()
    poly.SetPoints(points)
    for name, value in (("radius", radius), ("density", BALL_DENSITY)):
        array = vtkFloatArray()
        array.SetName(name)
        array.SetNumberOfTuples(len(centres))
        array.Fill(value)
        poly.GetPointData().AddArray(array)
    return poly


def voxelise(centres, radius, grid):
    source = nimbus.vtkNimbusMetaballCloudSource()
    source.SetDimensions(*grid)
    source.SetBounds(*BOUNDS)
    source.SetNumberOfLevels(0)
    source.SetFlatBase(False)
    for c in centres:
        source.AddBall(float(c[0]), float(c[1]), float(c[2]), radius, BALL_DENSITY)
    source.Update()
    return source.GetOutput()


def write_scene(directory, vti_name):
    scene = {
        "nimbus_scene": 2, "name": "splat-compare", "camera": CAMERA,
        "medium": {"density": {"type": "file", "path": vti_name, "array": "density"},
                   "extinction_per_density": EXTINCTION,
                   "single_scattering_albedo": ALBEDO,
                   "phase": [{"type": "cornette_shanks", "g": G, "weight": 1}]},
        "sun": SUN, "atmosphere": {"enabled": False}, "ground": {"enabled": False},
        "background": {"type": "black"}, "spectral_samples": 16}
    path = os.path.join(directory, "scene.json")
    with open(path, "w") as stream:
        json.dump(scene, stream, indent=1)
    return path


def render_window(size):
    from vtkmodules.vtkRenderingCore import vtkRenderWindow, vtkRenderer
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
    renderer = vtkRenderer()
    renderer.SetBackground(0, 0, 0)
    camera = renderer.GetActiveCamera()
    camera.SetPosition(*CAMERA["position"])
    camera.SetFocalPoint(*CAMERA["focal_point"])
    camera.SetViewUp(*CAMERA["view_up"])
    camera.SetViewAngle(CAMERA["view_angle"])
    camera.SetClippingRange(100.0, 1e5)
    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    return window, renderer


def render_splats(poly, method, repeats, sun_size, layers, exposure=VTK_SCALE, samples=8,
                  multiple_scattering=False, ms_grid_size=32):
    from vtkmodules.vtkRenderingCore import vtkActor, vtkWindowToImageFilter
    mapper = nimbus.vtkNimbusCloudSplatMapper()
    mapper.SetInputData(poly)
    mapper.SetSunAzimuthDegrees(SUN["azimuth_degrees"])
    mapper.SetSunElevationDegrees(SUN["elevation_degrees"])
    mapper.SetExtinctionPerDensity(EXTINCTION)
    mapper.SetAlbedo(ALBEDO)
    mapper.SetCloudG(G)
    mapper.SetExposure(exposure)
    mapper.SetSunLightMethod(method)
    mapper.SetSunTextureSize(sun_size)
    mapper.SetSunTextureLayers(layers)
    mapper.SetSunLightSamples(samples)
    mapper.SetTimePasses(True)
    mapper.SetMultipleScattering(multiple_scattering)
    mapper.SetMultipleScatteringGridSize(ms_grid_size)
    actor = vtkActor()
    actor.SetMapper(mapper)
    window, renderer = render_window((CAMERA["width"], CAMERA["height"]))
    renderer.AddActor(actor)
    window.Render()  # first frame: shaders, textures, uploads
    times, suns, solves, views = [], [], [], []
    for _ in range(repeats):
        mapper.Modified()  # the balls again: the sun pass and the sort are redone
        start = time.perf_counter()
        window.Render()
        times.append(time.perf_counter() - start)
        suns.append(mapper.GetLastSunPassSeconds())
        solves.append(mapper.GetLastMultipleScatteringSeconds() if multiple_scattering else 0.0)
        views.append(mapper.GetLastViewPassSeconds())
    image = harness.read_framebuffer(window, vtkWindowToImageFilter, 3) / exposure
    window.Finalize()
    render_splats.extra = {"ms_solve_seconds": statistics.median(solves),
                           "view_pass_seconds": statistics.median(views),
                           "solves": mapper.GetNumberOfMultipleScatteringSolves()}
    return image, statistics.median(times), statistics.median(suns)


def render_svs(grid, repeats, multiple_scattering=False):
    mapper = nimbus.vtkNimbusCloudVolumeMapper()
    mapper.SetInputData(grid)
    mapper.SetExtinctionPerDensity(EXTINCTION)
    mapper.SetAlbedo(ALBEDO)
    mapper.SetCloudG(G)
    mapper.SetMultipleScattering(0.0)
    # 3: DiscreteDirections, the solver the splats' option uses (the mapper's own grid).
    mapper.SetMultipleScatteringMethod(3 if multiple_scattering else 0)
    mapper.SetAtmosphere(False)
    mapper.SetAirMultipleScattering(False)
    mapper.SetGround(False)
    mapper.SetSunAzimuthDegrees(SUN["azimuth_degrees"])
    mapper.SetSunElevationDegrees(SUN["elevation_degrees"])
    mapper.SetCaptureRadiance(True)
    from vtkmodules.vtkRenderingCore import vtkVolume
    volume = vtkVolume()
    volume.SetMapper(mapper)
    window, renderer = render_window((CAMERA["width"], CAMERA["height"]))
    renderer.AddVolume(volume)
    window.Render()
    times = []
    for _ in range(repeats):
        mapper.Modified()
        start = time.perf_counter()
        window.Render()
        times.append(time.perf_counter() - start)
    radiance = mapper.GetRadianceImage()
    width, height, _ = radiance.GetDimensions()
    rgba = vtk_to_numpy(radiance.GetPointData().GetScalars()).reshape(height, width, 4)
    window.Finalize()
    return rgba[..., :3].astype(np.float32).copy(), statistics.median(times)


def errors(image, reference, mask):
    a = image[mask].astype(np.float64)
    b = reference[mask].astype(np.float64)
    return {"mean_ratio": float(a.mean() / max(b.mean(), 1e-30)),
            "rmse": float(np.sqrt(np.mean((a - b) ** 2))),
            "reference_mean": float(b.mean())}


def sky_bench(counts, repeats, ms_grid_size):
    """The cost of the sky's terms (--sky-bench): per count, the balls over a Nimbus sky
    (vtkNimbusSkyBackground drawn first in both rows) with the mapper following it
    (SetSkyBackground: the sky's light, the air, the sun's tint, the sRGB composite) and
    without; the median of `repeats` frames that move the camera (2 degrees) and of
    `repeats` frames that move the sky's sun (0.5 degrees: the sun pass, the tint and the
    sky light's solve again). Prints one CSV row per (count, row)."""
    from vtkmodules.vtkRenderingCore import vtkActor
    print("balls,row,camera_move_s,view_pass_s,air_s,sun_move_s,solve_s")
    for count in counts:
        centres, radius = make_balls(count)
        poly = balls_polydata(centres, radius)
        for follow in (False, True):
            background = nimbus.vtkNimbusSkyBackground()
            background.GetSky().SetSunElevationDegrees(SUN["elevation_degrees"])
            background.GetSky().SetSunAzimuthDegrees(SUN["azimuth_degrees"])
            mapper = nimbus.vtkNimbusCloudSplatMapper()
            mapper.SetInputData(poly)
            mapper.SetSunElevationDegrees(SUN["elevation_degrees"])
            mapper.SetSunAzimuthDegrees(SUN["azimuth_degrees"])
            mapper.SetExtinctionPerDensity(EXTINCTION)
            mapper.SetMultipleScatteringGridSize(ms_grid_size)
            mapper.SetTimePasses(True)
            if follow:
                mapper.SetSkyBackground(background)
            actor = vtkActor()
            actor.SetMapper(mapper)
            window, renderer = render_window((CAMERA["width"], CAMERA["height"]))
            renderer.AddViewProp(background)
            renderer.AddActor(actor)
            window.Render()
            camera_times, views, airs, sun_times, solves = [], [], [], [], []
            for _ in range(repeats):
                renderer.GetActiveCamera().Azimuth(2.0)
                start = time.perf_counter()
                window.Render()
                camera_times.append(time.perf_counter() - start)
                views.append(mapper.GetLastViewPassSeconds())
                airs.append(mapper.GetLastAirSeconds())
            sky = background.GetSky()
            for k in range(repeats):
                sky.SetSunElevationDegrees(SUN["elevation_degrees"] + 0.5 * (1 + k % 2))
                mapper.SetSunElevationDegrees(sky.GetSunElevationDegrees())
                start = time.perf_counter()
                window.Render()
                sun_times.append(time.perf_counter() - start)
                solves.append(mapper.GetLastMultipleScatteringSeconds() if follow else 0.0)
            window.Finalize()
            print("%d,%s,%.4f,%.4f,%.4f,%.4f,%.4f" % (
                count, "sky" if follow else "no-sky", statistics.median(camera_times),
                statistics.median(views), statistics.median(airs),
                statistics.median(sun_times), statistics.median(solves)))
            sys.stdout.flush()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[1000, 10000, 100000])
    parser.add_argument("--grid", type=int, nargs=3, default=[160, 160, 72])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--readback-max", type=int, default=10000)
    parser.add_argument("--sun-size", type=int, default=256)
    parser.add_argument("--layers", type=int, default=32)
    parser.add_argument("--path-seconds", type=float, default=60.0)
    parser.add_argument("--samples", type=int, default=8,
                        help="SunLightSamples of the splat-texture rows (splat-texture-centre: 0)")
    parser.add_argument("--multiple-scattering", action="store_true",
                        help="add the rows drawn with the mapper's MultipleScattering option")
    parser.add_argument("--ms-grid-size", type=int, default=32,
                        help="MultipleScatteringGridSize of those rows")
    parser.add_argument("--splats-only", action="store_true",
                        help="leave out the read-back and the SVS rows")
    parser.add_argument("--no-references", action="store_true")
    parser.add_argument("--reuse-references", action="store_true",
                        help="load the references an earlier run saved in --output")
    parser.add_argument("--output", default="build/splats")
    parser.add_argument("--sky-bench", action="store_true",
                        help="only time the sky's terms (over a Nimbus sky, followed or not)")
    args = parser.parse_args()
    if args.sky_bench:
        sky_bench(args.counts, args.repeats, args.ms_grid_size)
        return
    os.makedirs(args.output, exist_ok=True)
    rows = []
    for count in args.counts:
        directory = os.path.join(args.output, f"n{count}")
        os.makedirs(directory, exist_ok=True)
        centres, radius = make_balls(count)
        poly = balls_polydata(centres, radius)
        start = time.perf_counter()
        grid = voxelise(centres, radius, args.grid)
        voxel_seconds = time.perf_counter() - start
        writer = vtkXMLImageDataWriter()
        writer.SetFileName(os.path.join(directory, "density.vti"))
        writer.SetInputData(grid)
        writer.Write()
        scene = write_scene(directory, "density.vti")
        reference_seconds = {}
        references = {}
        seconds_path = os.path.join(directory, "reference-seconds.json")
        if args.reuse_references and os.path.exists(seconds_path):
            with open(seconds_path) as stream:
                reference_seconds = json.load(stream)
            for name in reference_seconds:
                references[name] = np.load(os.path.join(directory, f"{name}.npy"))
        elif not args.no_references:
            for name, settings in (
                    ("single", harness.REFERENCE_SETTINGS["single"]),
                    ("path", dict(harness.REFERENCE_SETTINGS["path"],
                                  time_limit=args.path_seconds))):
                start = time.perf_counter()
                image, _ = harness.render_reference_mode(scene, settings)
                reference_seconds[name] = time.perf_counter() - start
                references[name] = image
                np.save(os.path.join(directory, f"{name}.npy"), image)
            with open(seconds_path, "w") as stream:
                json.dump(reference_seconds, stream)
        images = {}
        seconds = {}
        suns = {}
        extras = {}
        exposures = {}
        # The 8-bit framebuffer's exposure: the single-scattering reference's brightest
        # pixel near white (a step of 1/255 of it), else VTK_SCALE.
        exposure = (0.9 / float(references["single"].max()) if "single" in references
                    else VTK_SCALE)
        # With multiple scattering the cloud is about 5 times brighter: exposed by the
        # path tracer's brightest pixel.
        ms_exposure = (0.9 / float(references["path"].max()) if "path" in references
                       else exposure / 8.0)
        runs = [("splat-texture", args.samples, False, exposure),
                ("splat-texture-centre", 0, False, exposure)]
        if args.multiple_scattering:
            runs += [("splat-texture-ms", args.samples, True, ms_exposure),
                     ("splat-texture-centre-ms", 0, True, ms_exposure)]
        for name, samples, ms, run_exposure in runs:
            images[name], seconds[name], suns[name] = render_splats(
                poly, 0, args.repeats, args.sun_size, args.layers, run_exposure, samples,
                ms, args.ms_grid_size)
            extras[name] = render_splats.extra
            exposures[name] = run_exposure
        if count <= args.readback_max and not args.splats_only:
            images["splat-readback"], seconds["splat-readback"], _ = render_splats(
                poly, 1, 1, args.sun_size, args.layers, exposure, 0)
        if not args.splats_only:
            images["svs"], seconds["svs"] = render_svs(grid, args.repeats)
            if args.multiple_scattering:
                images["svs-ms"], seconds["svs-ms"] = render_svs(grid, args.repeats, True)
        mask = None
        if "single" in references:
            luminance = references["single"].mean(axis=2)
            mask = luminance > 1e-3 * np.percentile(luminance, 99)
        for name, image in images.items():
            np.save(os.path.join(directory, f"{name}.npy"), image)
            row_exposure = exposures.get(name, exposure)
            harness.write_png(image, os.path.join(directory, f"{name}.png"),
                              exposure=row_exposure)
            row = {"balls": count, "radius_m": radius, "renderer": name,
                   "seconds": seconds[name],
                   "sun_pass_seconds": suns.get(name, ""),
                   "voxelise_seconds": voxel_seconds, "exposure": row_exposure}
            row.update(extras.get(name, {}))
            for reference_name, reference in references.items():
                for key, value in errors(image, reference, mask).items():
                    row[f"{reference_name}_{key}"] = value
            rows.append(row)
            print(json.dumps(row), flush=True)
        for name, image in references.items():
            harness.write_png(image, os.path.join(directory, f"{name}.png"),
                              exposure=0.9 / max(float(image.max()), 1e-30))
            row = {"balls": count, "radius_m": radius, "renderer": name,
                   "seconds": reference_seconds[name]}
            if name == "path":
                for key, value in errors(image, references["single"], mask).items():
                    row[f"single_{key}"] = value
            rows.append(row)
            print(json.dumps(row), flush=True)
    keys = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    with open(os.path.join(args.output, "splat-compare.csv"), "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)


if __name__ == "__main__":
    sys.exit(main())
