"""The Cloud representation rendered by 2-4 pvbatch ranks against one rank (issue 18).

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
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader

HERE = os.path.dirname(os.path.abspath(__file__))


def read_png(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars())
    return pixels[:, :3].astype(float)


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
    one_empty = prefix + "-empty-1.png"
    many_empty = prefix + "-empty-%d.png" % args.ranks
    render(args, 1, one_empty, empty)
    render(args, args.ranks, many_empty, empty)
    rmse, p99, largest = compare(one_empty, many_empty)
    print("empty cloud, %d ranks vs 1: RMSE %.3f, 99th percentile %.1f, max %.0f levels"
          % (args.ranks, rmse, p99, largest))
    if largest > 1.0:
        failures.append("the air and the ground differ with %d ranks (max %.0f levels)"
                        % (args.ranks, largest))

    one = prefix + "-1.png"
    many = prefix + "-%d.png" % args.ranks
    render(args, 1, one, data, ["--timings", prefix + "-1.json"])
    render(args, args.ranks, many, data, ["--timings", prefix + "-%d.json" % args.ranks])
    rmse, p99, largest = compare(one, many)
    print("cloud, %d ranks vs 1: RMSE %.3f, 99th percentile %.1f, max %.0f levels"
          % (args.ranks, rmse, p99, largest))
    if rmse > args.max_rmse or p99 > args.max_p99:
        failures.append("the cloud with %d ranks is off: RMSE %.3f (bound %.3f), 99th "
                        "percentile %.1f (bound %.1f)" % (args.ranks, rmse, args.max_rmse,
                                                          p99, args.max_p99))
    if numpy.mean(read_png(many)) < 1.0:
        failures.append("the %d-rank image is black" % args.ranks)

    # Over a Nimbus sky ("Sky Background"): the sky drawn by one rank, the cloud
    # following its sun, air and display settings on every rank.
    one_sky = prefix + "-sky-1.png"
    many_sky = prefix + "-sky-%d.png" % args.ranks
    render(args, 1, one_sky, data, ["--sky"])
    render(args, args.ranks, many_sky, data, ["--sky"])
    rmse, p99, largest = compare(one_sky, many_sky)
    print("cloud over a sky, %d ranks vs 1: RMSE %.3f, 99th percentile %.1f, max %.0f levels"
          % (args.ranks, rmse, p99, largest))
    if rmse > args.max_rmse or p99 > args.max_p99:
        failures.append("the cloud over a sky with %d ranks is off: RMSE %.3f (bound %.3f), "
                        "99th percentile %.1f (bound %.1f)" % (args.ranks, rmse, args.max_rmse,
                                                               p99, args.max_p99))
    for failure in failures:
        print("FAIL: " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
