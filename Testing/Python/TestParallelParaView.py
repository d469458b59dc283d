"""MPI test (docs/parallel.md): the plugin's metaball cloud through plain ParaView on 2 ranks.

    mpiexec -n 2 pvbatch --force-offscreen-rendering TestParallelParaView.py --plugin Nimbus.so

(PYTHONPATH must reach the nimbus package, for the serial reference.) pvbatch runs the
script on rank 0 only; the pipeline runs on every rank, each producing its piece. The data
information ParaView gathers from the ranks must describe the serial output: the whole
extent, its number of cells and the density's range. Its number of points is the sum over
the pieces, which share the points of their common face (VTK's pieces partition the cells),
so it must equal what ParaView reports for its own Wavelet source of the same whole extent
(the serial count plus that face). Also checks that the pieces really were split (rank 0's
own piece is smaller than the whole).
"""
import argparse
import sys

from paraview import servermanager
from paraview.simple import LoadPlugin, Wavelet

import nimbus

DIMENSIONS = [40, 36, 28]
SEED = 4


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    args = parser.parse_args()

    ranks = servermanager.ActiveConnection.GetNumberOfDataPartitions()
    if ranks != 2:
        print("expected 2 ranks, got", ranks)
        return 1

    LoadPlugin(args.plugin, ns=globals())
    cloud = NimbusMetaballCloud(Dimensions=DIMENSIONS, Seed=SEED)  # noqa: F821 (plugin)
    cloud.UpdatePipeline()
    info = cloud.GetDataInformation()
    extent = list(info.GetExtent())
    points = info.GetNumberOfPoints()
    cells = info.GetNumberOfCells()
    density_range = list(info.GetPointDataInformation().GetArrayInformation("density")
                         .GetComponentRange(0))

    serial = nimbus.vtkNimbusMetaballCloudSource()
    serial.SetDimensions(DIMENSIONS)
    serial.SetSeed(SEED)
    serial.Update()
    expected_extent = list(serial.GetOutput().GetExtent())
    expected_cells = serial.GetOutput().GetNumberOfCells()
    wavelet = Wavelet(WholeExtent=expected_extent)
    wavelet.UpdatePipeline()
    expected_points = wavelet.GetDataInformation().GetNumberOfPoints()
    if not expected_points > serial.GetOutput().GetNumberOfPoints():
        print("ParaView's Wavelet on %d ranks has %d points: no shared face?"
              % (ranks, expected_points))
        return 1
    expected_range = list(serial.GetOutput().GetPointData().GetArray("density").GetRange(0))

    # The piece rank 0 (this process) holds: a part of the whole, not all of it.
    local = cloud.GetClientSideObject().GetOutputDataObject(0)
    local_points = local.GetNumberOfPoints()

    print("ParaView on %d ranks: extent %s, %d cells, %d points, density range %s; rank 0 "
          "holds %d points" % (ranks, extent, cells, points, density_range, local_points))
    print("serial: extent %s, %d cells, %d points (%d over the pieces, as ParaView's "
          "Wavelet), density range %s"
          % (expected_extent, expected_cells, serial.GetOutput().GetNumberOfPoints(),
             expected_points, expected_range))
    failures = []
    if extent != expected_extent:
        failures.append("extent")
    if cells != expected_cells:
        failures.append("number of cells")
    if points != expected_points:
        failures.append("number of points")
    if density_range != expected_range:
        failures.append("density range")
    if not 0 < local_points < serial.GetOutput().GetNumberOfPoints():
        failures.append("rank 0's piece (%d points) is not a part of the whole" % local_points)
    if failures:
        print("FAILED: " + ", ".join(failures))
        return 1
    print("TestParallelParaView: the 2-rank output describes the serial one")
    return 0


if __name__ == "__main__":
    # Only a failure exits early: a normal end lets pvbatch finalize MPI on every rank.
    if main() != 0:
        sys.exit(1)
