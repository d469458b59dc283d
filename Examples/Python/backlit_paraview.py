"""pvpython: the backlit view of docs/backlit-view.md (the sun in front of the camera).

    pvpython Examples/Python/backlit_paraview.py \
        build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so OUTPUT_DIR

Writes backlit-automatic.png (the Sky Background's automatic exposure, the default),
backlit-exposure10.png (automatic exposure off: the fixed Exposure 10),
backlit-exposure10-no-shafts.png (and Shafts of Light off) and
backlit-exposure10-no-flat-base.png (and the source's Flat Base off).
(Without a display, wrap it: Testing/with-display.sh pvpython ...)
"""
import math
import os
import sys

from paraview.simple import (ColorBy, CreateRenderView, LoadPlugin, Render, SaveScreenshot,
                             Show)

plugin = sys.argv[1] if len(sys.argv) > 1 else "build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so"
output_dir = sys.argv[2] if len(sys.argv) > 2 else "."
os.makedirs(output_dir, exist_ok=True)
LoadPlugin(plugin, ns=globals())

view = CreateRenderView()
view.ViewSize = [480, 300]
view.OrientationAxesVisibility = 0
sky = NimbusSky(SunElevationDegrees=20.0, SunAzimuthDegrees=135.0)  # noqa: F821 (plugin)
sky_display = Show(sky, view)
cloud = NimbusMetaballCloud(Dimensions=[64, 64, 44], Seed=7)  # noqa: F821 (plugin)
cloud_display = Show(cloud, view)
cloud_display.SetRepresentationType("Cloud")
ColorBy(cloud_display, ("POINTS", "density"))
cloud_display.MultipleScatteringMethod = 1  # Octaves: fast; the view does not depend on it
# North-west of the cloud, looking south-east toward the sun, slightly up.
azimuth = math.radians(135.0)
view.CameraPosition = [-7000.0 * math.sin(azimuth), -7000.0 * math.cos(azimuth), 1200.0]
view.CameraFocalPoint = [0.0, 0.0, 1800.0]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.CameraViewAngle = 40.0


def shot(name):
    Render(view)
    path = os.path.join(output_dir, name + ".png")
    SaveScreenshot(path, view, ImageResolution=[480, 300])
    print(path)


shot("backlit-automatic")
sky_display.AutomaticExposure = 0
shot("backlit-exposure10")
cloud_display.Shafts = 0
shot("backlit-exposure10-no-shafts")
cloud_display.Shafts = 1
cloud.FlatBase = 0
shot("backlit-exposure10-no-flat-base")
