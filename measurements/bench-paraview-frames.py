"""Frame times of the Cloud representation in ParaView (pvpython), beside ParaView's own
Volume representation, in one run (interactive speed).

    Testing/with-display.sh pvpython measurements/bench-paraview-frames.py \
        --plugin build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so [--size 1280 800] \
        [--dimensions 128] [--repeats 5] [--method {march,slices}] [--json out.json]

With `import nimbus` on PYTHONPATH (build/lib/python3.11/site-packages) it also measures the
unlit-slice floor (the mapper's Unlit mode at full quality: the slices without light, the
least a still frame of this cloud can cost) and reports the quality the mapper chose.

Every timed frame follows a one-degree camera turn, so nothing is reused from the frame
before, except the "unchanged" row: a render after a change that does not touch the cloud
(a scalar bar shown), which must reuse the last cloud image. Times are medians in seconds.
"""
import argparse
import json
import statistics
import sys
import time

from paraview.simple import (ColorBy, CreateRenderView, Delete, GetColorTransferFunction,
                             GetScalarBar, LoadPlugin, SetActiveView, Show)


def cloud_mapper(view):
    try:
        import nimbus
    except ImportError:
        return None
    return nimbus.find_cloud_mapper(view.SMProxy.GetRenderer())


def timed(view, interactive, repeats, turn=True):
    times = []
    for _ in range(repeats):
        if turn:
            view.GetActiveCamera().Azimuth(1.0)
        start = time.perf_counter()
        if interactive:
            view.InteractiveRender()
        else:
            view.StillRender()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--size", type=int, nargs=2, default=[1280, 800])
    parser.add_argument("--dimensions", type=int, default=128)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--method", choices=["march", "slices"], default="march",
                        help="the Cloud representation's rendering method: ray marching "
                             "(march, the representation's default) or shadow-view "
                             "slicing (slices)")
    parser.add_argument("--json")
    arguments = parser.parse_args()

    LoadPlugin(arguments.plugin, ns=globals())
    n = arguments.dimensions
    cloud = globals()["NimbusMetaballCloud"](Dimensions=[n, n, n], Seed=7, NumberOfLevels=3)
    view = CreateRenderView()
    view.ViewSize = arguments.size
    view.OrientationAxesVisibility = 0
    SetActiveView(view)
    display = Show(cloud, view)
    display.SetRepresentationType("Cloud")
    if arguments.method == "slices":
        display.RenderingMethod = 0  # shadow-view slicing; 1 (the default) ray marches
    ColorBy(display, ("POINTS", "density"))
    display.SetScalarBarVisibility(view, False)
    view.ResetCamera()
    camera = view.GetActiveCamera()
    camera.Elevation(-80.0)  # a side view, the ground below
    camera.OrthogonalizeViewUp()
    view.ResetCamera()
    rows = {}
    start = time.perf_counter()
    view.StillRender()  # uploads, the multiple-scattering solve, the sky model
    rows["first_still"] = time.perf_counter() - start
    rows["cloud_still"] = timed(view, False, arguments.repeats)
    rows["cloud_interactive"] = timed(view, True, arguments.repeats)
    mapper = cloud_mapper(view)
    if mapper is not None and hasattr(mapper, "GetLastFrameQuality"):
        view.GetActiveCamera().Azimuth(1.0)
        view.InteractiveRender()
        rows["interactive_quality"] = mapper.GetLastFrameQuality()
        rows["interactive_image_scale"] = mapper.GetLastFrameImageScale()
        rows["interactive_cloud_passes"] = mapper.GetLastFrameSeconds()
        view.StillRender()
        rows["still_quality"] = mapper.GetLastFrameQuality()
    if mapper is not None and hasattr(mapper, "GetRenderingMethod"):
        rows["mapper_rendering_method"] = mapper.GetRenderingMethod()  # 0 slices, 1 march
    # A change that does not touch the cloud: the colour legend.
    bar = GetScalarBar(GetColorTransferFunction("density"), view)
    times = []
    for k in range(arguments.repeats):
        bar.Visibility = k % 2 == 0
        begin = time.perf_counter()
        view.StillRender()
        times.append(time.perf_counter() - begin)
    rows["cloud_unchanged"] = statistics.median(times)
    bar.Visibility = 0
    if mapper is not None:
        mapper.SetUnlit(True)
        rows["unlit_floor_still"] = timed(view, False, arguments.repeats)
        mapper.SetUnlit(False)
    display.SetRepresentationType("Volume")
    view.StillRender()
    rows["volume_still"] = timed(view, False, arguments.repeats)
    rows["volume_interactive"] = timed(view, True, arguments.repeats)
    rows["size"] = arguments.size
    rows["dimensions"] = n
    rows["method"] = arguments.method
    for key, value in rows.items():
        print(f"{key:22s} {value}")
    if "unlit_floor_still" in rows:
        print(f"{'still / unlit floor':22s} {rows['cloud_still'] / rows['unlit_floor_still']:.2f}")
    if arguments.json:
        with open(arguments.json, "w") as stream:
            json.dump(rows, stream, indent=1)
    # The view goes while its X display is still open (left to the interpreter's exit,
    # ParaView 5.11 releases its FXAA filter's GL objects after the display is gone).
    mapper = None
    Delete(display)
    Delete(view)
    return 0


if __name__ == "__main__":
    sys.exit(main())
