"""Writes a metaball cloud as an OpenVDB file (how Data/OpenVDB/metaball_cloud.vdb was made).

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 \
        Examples/Python/write_metaball_vdb.py Data/OpenVDB/metaball_cloud.vdb

The density of vtkNimbusMetaballCloudSource (dimensionless, >= 0) becomes a FloatGrid
"density" of class fog volume; voxels below 1e-3 are inactive (not stored).
"""
import sys

import nimbus

path = sys.argv[1] if len(sys.argv) > 1 else "metaball_cloud.vdb"
cloud = nimbus.vtkNimbusMetaballCloudSource()
cloud.SetDimensions(97, 97, 65)                        # grid points: 31.25 m voxels
cloud.SetBounds(-1500, 1500, -1500, 1500, 800, 2800)   # metres, z up
cloud.SetSeed(7)
cloud.SetNumberOfLevels(3)
cloud.Update()

writer = nimbus.vtkNimbusOpenVDBWriter()
writer.SetInputConnection(cloud.GetOutputPort(0))
writer.SetFileName(path)
writer.SetTolerance(1e-3)          # |density| <= 1e-3: inactive
if not writer.Write():
    sys.exit(f"could not write {path}")
print(f"wrote {path}: {writer.GetNumberOfActiveVoxels()} active voxels")
