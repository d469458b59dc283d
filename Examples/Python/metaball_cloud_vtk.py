"""VTK Python example: generate a metaball cloud with Nimbus and save it.

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 \
        Examples/Python/metaball_cloud_vtk.py [output.vti]

Uses Debian's /usr/bin/python3 (python3-paraview provides vtkmodules). The .vti
opens in ParaView; the density array is called "density".
"""
import sys

import nimbus
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

output = sys.argv[1] if len(sys.argv) > 1 else "metaball_cloud.vti"

cloud = nimbus.vtkNimbusMetaballCloudSource()
cloud.SetDimensions(64, 64, 44)     # grid points
cloud.SetBounds(-1500, 1500, -1500, 1500, 800, 2800)  # metres, z up
cloud.SetBaseHeight(1000)           # flat cloud base (m)
cloud.SetNumberOfLevels(3)          # fractal growth levels
cloud.SetSeed(7)
cloud.Update()

density = vtk_to_numpy(cloud.GetOutput().GetPointData().GetArray("density"))
balls = cloud.GetOutputDataObject(1)
print(f"{balls.GetNumberOfPoints()} metaballs, density max {density.max():.3f}, "
      f"cloudy fraction {(density > 0.5).mean():.3f}")

writer = vtkXMLImageDataWriter()
writer.SetFileName(output)
writer.SetInputConnection(cloud.GetOutputPort(0))
if not writer.Write():
    sys.exit(f"could not write {output}")
print(output)
