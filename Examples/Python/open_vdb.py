"""Opens an OpenVDB file with Nimbus's reader and prints what it holds.

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 \
        Examples/Python/open_vdb.py Data/OpenVDB/metaball_cloud.vdb [output.vti]
"""
import sys

import nimbus
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

reader = nimbus.vtkNimbusOpenVDBReader()
reader.SetFileName(sys.argv[1])
reader.UpdateInformation()                       # grid names and extents, no voxels read
names = reader.GetGridNames()
print("grids:", [names.GetValue(i) for i in range(names.GetNumberOfValues())])
# reader.SetGridArrayStatus("velocity", 0)       # skip a grid
# reader.SetMaximumNumberOfVoxels(256 ** 3)      # refuse bigger images
reader.Update()
image = reader.GetOutput()
print("extent:", image.GetExtent(), "origin:", image.GetOrigin(), "spacing:", image.GetSpacing())
for i in range(image.GetPointData().GetNumberOfArrays()):
    array = image.GetPointData().GetArray(i)
    print(f"  {array.GetName()}: {array.GetNumberOfComponents()} component(s), "
          f"range {array.GetRange(-1 if array.GetNumberOfComponents() > 1 else 0)}")
if image.GetNumberOfPoints() == 0:
    sys.exit("nothing read")
if len(sys.argv) > 2:
    writer = vtkXMLImageDataWriter()
    writer.SetInputData(image)
    writer.SetFileName(sys.argv[2])
    writer.Write()
    print("wrote", sys.argv[2])
