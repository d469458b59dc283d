"""The Cloud representation rendered by 2-4 pvbatch ranks against one rank (docs/parallel.md).

    python3 TestParallelCloud.py --mpiexec mpiexec --pvbatch pvbatch --plugin Nimbus.so \
        --ranks 2 --output-dir DIR [--max-rmse 2.0] [--max-p99 12]

Renders the same metaball cloud (a .vti, read in pieces) as the Cloud representation
with the defaults (sun, air, ground, multiple scattering) with one rank and with
--ranks ranks, and compares the two 8-bit images: the RMSE and the 99th percentile of
the absolute difference over all channels, in 8-bit levels. The bounds are measured
(docs/parallel.md): the pieces' multiple scattering solves see only their own piece
and the other pieces' shadow comes from a coarse copy of the density. A second pair
of renders with an empty cloud checks that the air and the ground are drawn once:
those images must agree to within 1 level (no double air, no missing ground). A third
pair puts the cloud over a Nimbus Sky ("Sky Background", drawn by one rank only).
"""
import argparse
import os
import subprocess
import sys

import numpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from image_compare import read_png  # noqa: E402




def render(args, ranks, output, data, extra=()):
    command = [args.mpiexec, "-n", str(ranks)] + args.mpiexec_flags.split() + [
        args.pvbatch, "--force-offscreen-rendering", os.path.join(HERE, "ParallelCloudRender.py"),
        "--plugin", args.plugin, "--output", output, "--data", data] + list(extra)
    print(" ".join(command), flush=True)
    subprocess.run(command, check=True, timeout=600)


def compare(a, b):
    difference = numpy.abs(read_png(a) - read_png(b))
    return (float(numpy.sqrt(numpy.mean(difference ** 2))),
            float(numpy.percentile(difference, 99)), float(difference.max()))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--mpiexec-flags", default="")
    parser.add_argument("--pvbatch", required=True)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--ranks", type=int, required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--max-rmse", type=float, default=2.0)
    parser.add_argument("--max-p99", type=float, default=12.0)
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    prefix = os.path.join(args.output_dir, "ParallelCloud")
    data = prefix + "-cloud.vti"
    failures = []

    # The empty cloud first: the air and the ground alone, drawn once.
    empty = prefix + "-empty.vti"
    if not os.path.exists(empty):
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkCommonCore import vtkFloatArray
        from vtkmodules.vtkIOXML import vtkXMLImageDataWriter
        image = vtkImageData()
        image.SetDimensions(48, 48, 24)
        image.SetSpacing(50.0, 50.0, 50.0)
        image.SetOrigin(-1200.0, -1200.0, 1000.0)
        values = vtkFloatArray()
        values.SetName("density")
        values.SetNumberOfTuples(image.GetNumberOfPoints())
        values.Fill(0.0)
        image.GetPointData().SetScalars(values)
        writer = vtkXMLImageDataWriter()
        writer.SetInputData(image)
        writer.SetFileName(empty)
        writer.Write()
    def render_pair(name, data_file, extra=()):
        """One rank's and --ranks ranks' pictures of the same scene, and their difference."""
        one = "%s-%s-1.png" % (prefix, name)
        many = "%s-%s-%d.png" % (prefix, name, args.ranks)
        render(args, 1, one, data_file, extra)
        render(args, args.ranks, many, data_file, extra)
        rmse, p99, largest = compare(one, many)
        print("%s, %d ranks vs 1: RMSE %.3f, 99th percentile %.1f, max %.0f levels"
              % (name, args.ranks, rmse, p99, largest))
        if numpy.mean(read_png(many)) < 1.0:
            failures.append("the %d-rank image of %s is black" % (args.ranks, name))
        return rmse, p99, largest

    def within_bounds(name, rmse, p99):
        if rmse > args.max_rmse or p99 > args.max_p99:
            failures.append("%s with %d ranks is off: RMSE %.3f (bound %.3f), 99th percentile "
                            "%.1f (bound %.1f)" % (name, args.ranks, rmse, args.max_rmse, p99,
                                                   args.max_p99))

    _, _, largest = render_pair("empty", empty)
    if largest > 1.0:
        failures.append("the air and the ground differ with %d ranks (max %.0f levels)"
                        % (args.ranks, largest))
    rmse, p99, _ = render_pair("cloud", data)
    within_bounds("the cloud", rmse, p99)
    # Over a Nimbus sky ("Sky Background"): the sky drawn by one rank, the cloud
    # following its sun, air and display settings on every rank.
    rmse, p99, _ = render_pair("sky", data, ["--sky"])
    within_bounds("the cloud over a sky", rmse, p99)
    for failure in failures:
        print("FAIL: " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
