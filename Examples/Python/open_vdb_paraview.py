"""Opens a .vdb in pvpython through the Nimbus plugin, renders it as a volume, saves a copy.

    Testing/with-display.sh pvpython Examples/Python/open_vdb_paraview.py \
        build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so Data/OpenVDB/metaball_cloud.vdb \
        cloud_vdb.png cloud_copy.vdb
"""
import sys

from paraview.simple import *  # noqa: F401,F403

plugin, vdb_file, png, copy = sys.argv[1:5]
LoadPlugin(plugin, ns=globals())
cloud = OpenDataFile(vdb_file)   # picks the Nimbus OpenVDB reader (ReaderFactory hint)
if cloud is None or cloud.GetXMLName() != "NimbusOpenVDBReader":
    sys.exit(f"OpenDataFile did not use the Nimbus reader for {vdb_file}")
display = Show(cloud)
display.SetRepresentationType("Volume")
ColorBy(display, ("POINTS", "density"))
ResetCamera()
SaveScreenshot(png, ImageResolution=[480, 320])
SaveData(copy, proxy=cloud, Tolerance=1e-3)
print(f"{vdb_file}: {cloud.GetDataInformation().GetNumberOfPoints()} points -> {png}, {copy}")
