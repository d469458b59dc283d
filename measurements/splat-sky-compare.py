"""Cloud Splats against the Cloud representation under the same view sky (pvpython).

The Nimbus Metaball Cloud's defaults: its density (port 0) drawn by the Cloud
representation (its defaults: the ray march, multiple scattering by discrete directions
with the sky's and the ground's light, the air) and its balls (port 1, "Metaballs") drawn
by Cloud Splats, each alone over the same Nimbus Sky (Sky Background, turbidity 2,
automatic exposure off so that every picture has the same display scale), the sun at
--elevations degrees (azimuth --azimuth), seen from a near and a far camera. Splats are
drawn in four ways:

  * "plain":   the new terms off (Sky and Ground Light off, Air Between Camera and Cloud
               off; the sun still reddened by the air and the frame the sky's);
  * "sky+air": the sky's light and the air on (the defaults);
  * "ms":      and Light Scattered More Than Once on (the Cloud representation's default
               draws all orders);
  * "ms-plain": multiple scattering on, the sky's light and the air off.

Over the cloud's pixels (where some splat picture differs from the sky alone by more
than 6 of 255 in some channel; the Cloud representation draws its own ground, so its
picture differs from the sky's everywhere below the horizon) the ratio of the mean linear (sRGB-decoded)
colours, splats / Cloud, per channel and of the luminance, over all of them and over the
darker half (the Cloud picture's pixels below its median luminance there: the shadowed
and sky-lit sides); also the mean colour itself (linear, x 1000). One row per (camera,
elevation, splat variant). Pictures: <output>/<camera>-e<elevation>-<name>.png and a
side-by-side strip <camera>-e<elevation>-strip.png.

    flock /tmp/nimbus-measure.lock Testing/with-display.sh pvpython \\
        measurements/splat-sky-compare.py \\
        --plugin build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so --output build/splat-sky
"""
import argparse
import os
import sys

import numpy as np
from paraview.simple import (CreateRenderView, Delete, Hide, LoadPlugin, OutputPort, Render,
                             SaveScreenshot, Show)
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter

SIZE = [320, 240]
CAMERAS = {
    # The GUI's first look at Nimbus data: about 10 km away, looking north and down.
    "near": ([0.0, -9817.0, 3408.0], [0.0, 0.0, 1500.0]),
    # The same cloud 30 km away, near the horizon: the air between dims and blues it.
    "far": ([0.0, -30000.0, 1800.0], [0.0, 0.0, 1700.0]),
}
VARIANTS = {
    "plain": dict(SplatSkyLight=0, SplatAerialPerspective=0, SplatMultipleScattering=0),
    "sky+air": dict(SplatSkyLight=1, SplatAerialPerspective=1, SplatMultipleScattering=0),
    "ms": dict(SplatSkyLight=1, SplatAerialPerspective=1, SplatMultipleScattering=1),
    "ms-plain": dict(SplatSkyLight=0, SplatAerialPerspective=0, SplatMultipleScattering=1),
}


def read_png(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    w, h, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)
    return pixels[::-1, :, :3].astype(np.float64)


def decode(pixels):
    c = pixels / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def luminance(linear):
    return linear @ np.array([0.2126, 0.7152, 0.0722])


def save(view, directory, name):
    path = os.path.join(directory, name + ".png")
    Render(view)
    SaveScreenshot(path, view, ImageResolution=SIZE)
    return read_png(path)


def write_strip(path, images):
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.util.numpy_support import numpy_to_vtk
    strip = np.concatenate(images, axis=1)[::-1].astype(np.uint8)
    h, w, _ = strip.shape
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    data.GetPointData().SetScalars(numpy_to_vtk(strip.reshape(-1, 3), deep=True))
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(data)
    writer.Write()


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--elevations", type=float, nargs="+", default=[10.0, 60.0])
    parser.add_argument("--azimuth", type=float, default=135.0)
    parser.add_argument("--cameras", nargs="+", default=list(CAMERAS))
    args = parser.parse_args()
    os.makedirs(args.output, exist_ok=True)
    LoadPlugin(args.plugin, ns=globals())

    cloud = NimbusMetaballCloud()  # noqa: F821 (from the plugin)
    sky = NimbusSky(SunAzimuthDegrees=args.azimuth)  # noqa: F821
    # Two views, one per representation: a view that also shows polygonal data (the
    # Metaballs) holds a second, hidden sky background prop (the Sky Background
    # sub-representation of that data's display), which the renderer then names, and the
    # Cloud representation follows the named one (it would draw with its own sun and air).
    views = []
    for port, kind in ((0, "Cloud"), (1, "Cloud Splats")):
        view = CreateRenderView()
        view.ViewSize = SIZE
        view.OrientationAxesVisibility = 0
        sky_display = Show(sky, view)
        if hasattr(sky_display, "AutomaticExposure"):
            sky_display.AutomaticExposure = 0
        display = Show(OutputPort(cloud, port), view)
        display.SetRepresentationType(kind)
        Hide(OutputPort(cloud, port), view)
        Render(view)  # paraview.simple resets the camera at a view's first render
        views.append((view, display, port))
    (cloud_view, _, _), (splat_view, balls, _) = views

    print("camera,elevation,renderer,ratio_r,ratio_g,ratio_b,ratio_luminance,"
          "dark_ratio_luminance,mean_r_x1000,mean_g_x1000,mean_b_x1000,cloud_pixels")
    for camera in args.cameras:
        position, focal = CAMERAS[camera]
        for view, _, _ in views:
            view.CameraPosition = position
            view.CameraFocalPoint = focal
            view.CameraViewUp = [0.0, 0.0, 1.0]
            view.CameraViewAngle = 30.0
        for elevation in args.elevations:
            sky.SunElevationDegrees = elevation
            stem = "%s-e%g" % (camera, elevation)
            sky_only = save(splat_view, args.output, stem + "-sky")
            Show(OutputPort(cloud, 0), cloud_view)
            reference = save(cloud_view, args.output, stem + "-cloud")
            Hide(OutputPort(cloud, 0), cloud_view)
            pictures = [reference]
            splats = {}
            Show(OutputPort(cloud, 1), splat_view)
            for name, settings in VARIANTS.items():
                for key, value in settings.items():
                    setattr(balls, key, value)
                splats[name] = save(splat_view, args.output, stem + "-splats-" + name)
                pictures.append(splats[name])
            Hide(OutputPort(cloud, 1), splat_view)
            # The cloud's pixels: where any splat picture differs from the sky alone (the
            # Cloud representation also draws its own ground, so its picture differs
            # everywhere below the horizon).
            mask = np.zeros(sky_only.shape[:2], dtype=bool)
            for image in splats.values():
                mask |= np.abs(image - sky_only).max(axis=2) > 6.0
            ref_linear = decode(reference)[mask]
            ref_lum = luminance(ref_linear)
            dark = ref_lum < np.median(ref_lum)
            rows = [("cloud", ref_linear)] + [
                ("splats-" + name, decode(image)[mask]) for name, image in splats.items()]
            write_strip(os.path.join(args.output, stem + "-strip.png"), pictures)
            for name, linear in rows:
                ratio = linear.mean(axis=0) / np.maximum(ref_linear.mean(axis=0), 1e-9)
                lum = luminance(linear)
                print("%s,%g,%s,%.3f,%.3f,%.3f,%.3f,%.3f,%.1f,%.1f,%.1f,%d" % (
                    camera, elevation, name, ratio[0], ratio[1], ratio[2],
                    lum.mean() / max(ref_lum.mean(), 1e-9),
                    lum[dark].mean() / max(ref_lum[dark].mean(), 1e-9),
                    1000 * linear.mean(axis=0)[0], 1000 * linear.mean(axis=0)[1],
                    1000 * linear.mean(axis=0)[2], int(mask.sum())))
            sys.stdout.flush()
    for view, _, _ in views:
        Delete(view)
    del views, cloud_view, splat_view
    return 0


if __name__ == "__main__":
    sys.exit(main())
