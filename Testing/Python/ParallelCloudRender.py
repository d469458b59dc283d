"""Renders a metaball cloud as the "Cloud" representation in pvbatch, on as many
ranks as pvbatch runs with (docs/parallel.md), and saves the picture and the timings.

    mpiexec -n N pvbatch --force-offscreen-rendering ParallelCloudRender.py \
        --plugin Nimbus.so --output image.png [--size 320 240] [--grid 96]
        [--data cloud.vti] [--frames 3] [--timings timings.json]

--sky adds a Nimbus Sky shown as "Sky Background" (the cloud then follows its sun
and air). The density comes from a .vti file (--data; written on the first run, serial, by the
Nimbus Metaball Cloud source) through ParaView's XML image reader, which gives each
rank its own piece of the extent: the representation then renders one piece per
rank and IceT composites them in visibility order. The timings (seconds): the first
still render (data delivery, the coarse all-gather, the uploads and solves) and the
mean of the next --frames still renders after an azimuth change of the camera
(passes and compositing only), with the peak resident memory of every rank (MiB).
"""
import argparse
import json
import os
import resource
import time

from paraview import servermanager
from paraview.simple import (CreateRenderView, GetActiveCamera, LoadPlugin, Render,
                             SaveData, SaveScreenshot, Show, XMLImageDataReader)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--data", default=None)
    parser.add_argument("--size", type=int, nargs=2, default=[320, 240])
    parser.add_argument("--grid", type=int, default=96)
    parser.add_argument("--frames", type=int, default=2)
    parser.add_argument("--timings", default=None)
    parser.add_argument("--srgb", type=int, default=1)
    parser.add_argument("--sky", action="store_true",
                        help="show a Nimbus Sky (Sky Background) behind the cloud")
    args = parser.parse_args()

    LoadPlugin(args.plugin, ns=globals())
    data = args.data or os.path.splitext(args.output)[0] + "-cloud.vti"
    if not os.path.exists(data):
        source = NimbusMetaballCloud()  # noqa: F821 (from the plugin)
        source.Dimensions = [args.grid, args.grid, args.grid // 2]
        SaveData(data, proxy=source)
    reader = XMLImageDataReader(FileName=[data])

    view = CreateRenderView()
    view.ViewSize = args.size
    view.OrientationAxesVisibility = 0
    view.Background = [0.0, 0.0, 0.0]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    if args.sky:
        sky = NimbusSky(SunElevationDegrees=45.0)  # noqa: F821 (from the plugin)
        Show(sky, view)
    display = Show(reader, view)
    display.SetRepresentationType("Cloud")
    display.EncodeSrgb = args.srgb
    # The pieces of a distributed cloud are drawn by slicing (the ray march draws only a
    # whole cloud): the one-rank reference is drawn the same way.
    display.RenderingMethod = 0
    # From the south-west, a little above the cloud's base: the pieces lie behind
    # one another along the view as well as beside one another.
    info = reader.GetDataInformation().GetBounds()
    centre = [0.5 * (info[0] + info[1]), 0.5 * (info[2] + info[3]), 0.5 * (info[4] + info[5])]
    size = max(info[1] - info[0], info[3] - info[2], info[5] - info[4])
    camera = GetActiveCamera()
    camera.SetFocalPoint(centre)
    camera.SetPosition(centre[0] - 1.6 * size, centre[1] - 2.2 * size, info[4] + 0.1 * size)
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(40.0)

    start = time.perf_counter()
    Render(view)
    first = time.perf_counter() - start
    frames = []
    for _ in range(args.frames):
        camera.Azimuth(0.5)
        start = time.perf_counter()
        Render(view)
        frames.append(time.perf_counter() - start)
    camera.Azimuth(-0.5 * args.frames)
    Render(view)
    SaveScreenshot(args.output, view, ImageResolution=args.size)

    controller = servermanager.vtkProcessModule.GetProcessModule().GetGlobalController() \
        if hasattr(servermanager, "vtkProcessModule") else None
    ranks = controller.GetNumberOfProcesses() if controller else 1
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    if args.timings:
        with open(args.timings, "w") as stream:
            json.dump({"ranks": ranks, "first_render_s": first,
                       "frame_s": sum(frames) / max(len(frames), 1),
                       "rank0_peak_rss_mib": peak}, stream, indent=1)
    print("ranks %d: first render %.3f s, frame %.3f s, rank-0 peak %.0f MiB"
          % (ranks, first, sum(frames) / max(len(frames), 1), peak))


if __name__ == "__main__":
    main()
