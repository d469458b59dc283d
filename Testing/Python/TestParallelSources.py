"""The Cloud representation of Nimbus's sources and readers on several pvbatch ranks against
one rank, on the first render of a view whose camera a script set.

    python3 TestParallelSources.py --mpiexec mpiexec --pvbatch pvbatch --plugin Nimbus.so \
        --output-dir DIR --runs 2:all 4:metaball [--offscreen] [--timeout 120] \
        [--max-rmse 3.3] [--max-p99 14] [--max-uncovered 0.005]

Each run N:SOURCES renders SOURCES (`all`, or names separated by commas: metaball,
automaton, image, smoke, openvdb, vti) with ParallelSourceRender.py on N ranks; the same
sources on one rank are the reference. Checks, for every source:

- the air and the ground are there: the view's background (black) shows in at most
  --max-uncovered of the pixels more than on one rank. When the ranks disagreed on which of
  them draws the air and the ground (the camera reached the other ranks only when the
  renderer started), none drew them: the cloud over the background, 60-95 % of the pixels;
- the picture is one rank's: RMSE and 99th percentile of the absolute difference over all
  channels, in 8-bit levels, within --max-rmse and --max-p99 (measured: docs/parallel.md);
- the image cloud and the smoke, which compute the whole grid on every rank, say so once
  per rank on several ranks and never on one;
- no run hangs: each pvbatch run is stopped after --timeout seconds (SIGTERM to mpiexec,
  which passes it to its ranks, then SIGKILL to the whole process group) and fails.

--offscreen renders with no X server: DISPLAY removed, NIMBUS_OFFSCREEN=egl and pvbatch's
--force-offscreen-rendering, as on a cluster's nodes. Without it, pvbatch renders on the
DISPLAY (with-display.sh gives one). The data the readers need (a .vti, a .vdb and a PNG
for the image cloud, about 32 points a side) are written first into --output-dir, with
the nimbus Python package (PYTHONPATH).
"""
import argparse
import os
import signal
import subprocess
import sys
import time

import numpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from image_compare import read_png  # noqa: E402
from ParallelSourceRender import SOURCES  # noqa: E402


def write_data(directory):
    """cloud.vti and cloud.vdb (two metaball clouds, 32 x 32 x 22 and 31 x 31 x 21 points)
    and intensity.png (a 32 x 24 8-bit blob) for the readers and the image cloud."""
    import nimbus
    from vtkmodules.vtkCommonCore import vtkUnsignedCharArray
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

    cloud = nimbus.vtkNimbusMetaballCloudSource()
    cloud.SetDimensions(32, 32, 22)
    cloud.SetSeed(5)
    cloud.Update()
    writer = vtkXMLImageDataWriter()
    writer.SetInputData(cloud.GetOutput())
    writer.SetFileName(os.path.join(directory, "cloud.vti"))
    if not writer.Write():
        raise RuntimeError("could not write cloud.vti")
    # 31 x 31 x 21 points: cubic 100 m voxels, as OpenVDB stores them.
    cloud.SetDimensions(31, 31, 21)
    cloud.SetSeed(9)
    cloud.Update()
    vdb = nimbus.vtkNimbusOpenVDBWriter()
    vdb.SetInputData(cloud.GetOutput())
    vdb.SetFileName(os.path.join(directory, "cloud.vdb"))
    if not vdb.Write():
        raise RuntimeError("could not write cloud.vdb")
    image = vtkImageData()
    image.SetDimensions(32, 24, 1)
    values = vtkUnsignedCharArray()
    values.SetName("intensity")
    values.SetNumberOfTuples(32 * 24)
    for j in range(24):
        for i in range(32):
            r2 = ((i - 14.0) / 9.0) ** 2 + ((j - 11.0) / 7.0) ** 2
            value = 255.0 * max(0.0, 1.0 - r2) + 6.0 * ((i * 7 + j * 3) % 5)
            values.SetValue(j * 32 + i, int(min(255.0, value)))
    image.GetPointData().SetScalars(values)
    png = vtkPNGWriter()
    png.SetInputData(image)
    png.SetFileName(os.path.join(directory, "intensity.png"))
    png.Write()


def run_pvbatch(args, ranks, prefix, sources):
    """Renders `sources` on `ranks` ranks; its output (stdout and stderr of every rank),
    or None when it failed or was stopped."""
    command = [args.mpiexec, "-n", str(ranks)] + args.mpiexec_flags.split() + [args.pvbatch]
    environment = dict(os.environ)
    if args.offscreen:
        environment.pop("DISPLAY", None)
        environment["NIMBUS_OFFSCREEN"] = "egl"
        command.append("--force-offscreen-rendering")
    command += [os.path.join(HERE, "ParallelSourceRender.py"), "--plugin", args.plugin,
                "--output-prefix", prefix, "--data-dir", args.output_dir,
                "--sources"] + sources
    print(("NIMBUS_OFFSCREEN=egl (no DISPLAY) " if args.offscreen else "") + " ".join(command),
          flush=True)
    start = time.perf_counter()
    # A process group of its own, so that a hang is ended whole: mpiexec and its ranks.
    log = open(prefix + ".log", "w+")
    process = subprocess.Popen(command, env=environment, start_new_session=True, stdout=log,
                               stderr=subprocess.STDOUT)
    try:
        status = process.wait(timeout=args.timeout)
    except subprocess.TimeoutExpired:
        print("FAIL: %d ranks still running after %.0f s: stopped (a hang)"
              % (ranks, args.timeout), flush=True)
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            pass
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait()
        return None
    finally:
        log.seek(0)
        output = log.read()
        log.close()
        sys.stdout.write(output)
    print("%d ranks: %.1f s, exit status %d" % (ranks, time.perf_counter() - start, status),
          flush=True)
    return output if status == 0 else None


# The warning of the sources that compute the whole grid on every rank: once per rank on
# several ranks, never on one.
WHOLE_GRID_WARNINGS = {"image": "Image cloud on %d ranks", "smoke": "Smoke on %d ranks"}


def check_warnings(output, ranks, names, failures):
    for name, text in WHOLE_GRID_WARNINGS.items():
        count = output.count(text % ranks) if name in names else 0
        others = output.count(text.split(" on ")[0] + " on ") - count
        expected = ranks if ranks > 1 and name in names else 0
        if count != expected or others:
            failures.append("%s on %d ranks: %d warnings that it computes the whole grid on "
                            "every rank, expected %d (one per rank, none on one rank)"
                            % (name, ranks, count + others, expected))


def uncovered(pixels):
    """The fraction of pixels that show the view's black background: nothing drawn there."""
    return float(numpy.mean(numpy.all(pixels <= 1.0, axis=2)))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--mpiexec", required=True)
    parser.add_argument("--mpiexec-flags", default="")
    parser.add_argument("--pvbatch", required=True)
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output-dir", required=True)
    parser.add_argument("--runs", nargs="+", required=True,
                        help="RANKS:SOURCES, SOURCES `all` or names separated by commas")
    parser.add_argument("--offscreen", action="store_true")
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--max-rmse", type=float, default=3.3)
    parser.add_argument("--max-p99", type=float, default=14.0)
    parser.add_argument("--max-uncovered", type=float, default=0.005)
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    write_data(args.output_dir)

    runs = []
    for run in args.runs:
        ranks, names = run.split(":")
        runs.append((int(ranks), SOURCES if names == "all" else names.split(",")))
    reference_sources = [s for s in SOURCES if any(s in names for _, names in runs)]
    prefix = os.path.join(args.output_dir, "ParallelSources")
    failures = []
    output = run_pvbatch(args, 1, prefix + "-1", reference_sources)
    if output is None:
        print("FAIL: the one-rank reference did not render")
        return 1
    check_warnings(output, 1, reference_sources, failures)
    for ranks, names in runs:
        output = run_pvbatch(args, ranks, "%s-%d" % (prefix, ranks), names)
        if output is None:
            failures.append("%d ranks did not finish" % ranks)
            continue
        check_warnings(output, ranks, names, failures)
        for name in names:
            one = read_png("%s-1-%s.png" % (prefix, name))
            many = read_png("%s-%d-%s.png" % (prefix, ranks, name))
            difference = numpy.abs(one - many)
            rmse = float(numpy.sqrt(numpy.mean(difference ** 2)))
            p99 = float(numpy.percentile(difference, 99))
            bare = uncovered(many) - uncovered(one)
            print("%s, %d ranks vs 1: RMSE %.3f, 99th percentile %.1f, max %.0f levels; "
                  "background %.2f %% of the pixels (1 rank: %.2f %%)"
                  % (name, ranks, rmse, p99, difference.max(), 100.0 * uncovered(many),
                     100.0 * uncovered(one)), flush=True)
            if bare > args.max_uncovered:
                failures.append("%s, %d ranks: no air or ground on %.1f %% of the picture"
                                % (name, ranks, 100.0 * bare))
            if rmse > args.max_rmse or p99 > args.max_p99:
                failures.append("%s, %d ranks: RMSE %.3f (bound %.3f), 99th percentile %.1f "
                                "(bound %.1f)" % (name, ranks, rmse, args.max_rmse, p99,
                                                  args.max_p99))
    for failure in failures:
        print("FAIL: " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
