"""Renders Nimbus's sources and readers as the "Cloud" representation in pvbatch, on as
many ranks as pvbatch runs with, one picture each, as a user's script does it.

    mpiexec -n N pvbatch [--force-offscreen-rendering] ParallelSourceRender.py \
        --plugin Nimbus.so --output-prefix DIR/name --data-dir DIR \
        [--sources metaball automaton image smoke openvdb vti] [--size 160 120] [--defaults]

Each source gets a new render view whose camera is set from the script (on rank 0: the
other ranks receive it only when the renderer starts) and one SaveScreenshot, the first
and only render of that view: the path on which the other ranks once chose the bottom
layer (the air, the ground) with their old camera. Under MPI every source produces its
own piece on each rank (the field sources and the OpenVDB reader honour piece requests;
the image cloud and the smoke compute the whole grid on every rank and cut their piece),
and the .vti is read in pieces by ParaView's XML reader.

The data are tiny (about 32 points a side) so that 1, 2, 4 and 8 ranks stay cheap. The
files the readers need are in --data-dir: cloud.vti, cloud.vdb and intensity.png
(TestParallelSources.py writes them). The view's background is black, so that pixels
no rank drew are easy to count. Writes <prefix>-<source>.png.
"""
import argparse
import os
import time as clock

# paraview.simple, imported in main(): TestParallelSources.py imports SOURCES from here.
pv = None

SOURCES = ["metaball", "automaton", "image", "smoke", "openvdb", "vti"]


def make_source(name, data_dir):
    """The proxy for a source name, the time to show (None: no time) and the Cloud
    representation's settings for it."""
    if name == "metaball":
        return NimbusMetaballCloud(Dimensions=[32, 32, 22], Seed=7), None, {}  # noqa: F821
    if name == "automaton":
        source = NimbusCloudAutomaton(  # noqa: F821 (from the plugin)
            Dimensions=[32, 32, 10], Bounds=[-3200, 3200, -3200, 3200, 1000, 2600],
            Seed=3, SpinUpSteps=12, NumberOfTimeSteps=3, StepDuration=10.0,
            NumberOfFormationRegions=6, FormationRegionRadiusRange=[700, 1200],
            NumberOfThreads=1)
        return source, 10.0, {}
    if name == "image":
        reader = pv.PNGSeriesReader(FileNames=[os.path.join(data_dir, "intensity.png")])
        source = NimbusImageCloud(Input=reader, PixelSize=100.0,  # noqa: F821
                                  VerticalSpacing=60.0, Seed=3, Iterations=4)
        return source, None, {}
    if name == "smoke":
        source = NimbusSmoke(Dimensions=[16, 16, 24], CellSizeMetres=0.25,  # noqa: F821
                             OriginMetres=[-2.0, -2.0, 0.0], EmitterCentreMetres=[0, 0, 0.75],
                             EmitterRadiusMetres=0.75, NumberOfFrames=24, NumberOfThreads=1)
        # A 4 m plume seen as a cloud 200 times larger: optical depth about 3.
        return source, 20 * 0.0416667, {"MetresPerUnit": 200.0}
    if name == "openvdb":
        return NimbusOpenVDBReader(  # noqa: F821 (from the plugin)
            FileNames=[os.path.join(data_dir, "cloud.vdb")]), None, {}
    if name == "vti":
        return pv.XMLImageDataReader(FileName=[os.path.join(data_dir, "cloud.vti")]), None, {}
    raise ValueError("unknown source " + name)


def render(name, args):
    source, time, settings = make_source(name, args.data_dir)
    view = pv.CreateRenderView()
    pv.SetActiveView(view)
    view.ViewSize = args.size
    view.OrientationAxesVisibility = 0
    view.Background = [0.0, 0.0, 0.0]
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    if time is not None:
        view.ViewTime = time
    display = pv.Show(source, view)
    display.SetRepresentationType("Cloud")
    # Slices: pieces are always drawn by slicing (the ray march draws a whole cloud only),
    # the one-rank reference is drawn the same way.
    display.RenderingMethod = 0
    if not args.defaults:
        # What costs seconds per picture on llvmpipe and is not what is tested here (the
        # pieces' layers): the multiple-scattering solves of the cloud and the air, and 256
        # slices (64 here). The air, the ground, the sun's shadows stay.
        display.MultipleScatteringMethod = 0
        display.AirMultipleScattering = 0
        display.NumberOfSlices = 64
    for key, value in settings.items():
        setattr(display, key, value)
    source.UpdatePipeline(time if time is not None else 0.0)
    bounds = source.GetDataInformation().GetBounds()
    centre = [0.5 * (bounds[2 * a] + bounds[2 * a + 1]) for a in range(3)]
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4])
    # From the south-west, a little above the cloud's base: sky, ground and cloud in view,
    # the pieces behind one another along the view as well as beside one another.
    camera = pv.GetActiveCamera()
    camera.SetFocalPoint(centre)
    camera.SetPosition(centre[0] - 1.6 * size, centre[1] - 2.2 * size, bounds[4] + 0.1 * size)
    camera.SetViewUp(0.0, 0.0, 1.0)
    camera.SetViewAngle(40.0)
    output = "%s-%s.png" % (args.output_prefix, name)
    pv.SaveScreenshot(output, view, ImageResolution=args.size)
    print("%s: %s" % (name, output), flush=True)
    pv.Delete(view)
    pv.Delete(source)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output-prefix", required=True)
    parser.add_argument("--data-dir", required=True)
    parser.add_argument("--sources", nargs="+", default=SOURCES, choices=SOURCES)
    parser.add_argument("--size", type=int, nargs=2, default=[160, 120])
    parser.add_argument("--defaults", action="store_true",
                        help="the representation's defaults (multiple scattering, 256 slices)")
    args = parser.parse_args()
    global pv
    from paraview import simple
    pv = simple
    pv.LoadPlugin(args.plugin, ns=globals())
    for name in args.sources:
        start = clock.perf_counter()
        render(name, args)
        print("%s: %.2f s" % (name, clock.perf_counter() - start), flush=True)


if __name__ == "__main__":
    main()
