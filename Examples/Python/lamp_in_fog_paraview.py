"""pvpython example: a street lamp in fog at night, a post standing in its beam.

    pvpython Examples/Python/lamp_in_fog_paraview.py \
        build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so [lamp-in-fog.png] \
        [--size 800 500] [--exposure 800] [--fog 80] [--shadow-map 1024]

(Without a display, wrap it: Testing/with-display.sh pvpython ...)

The lamp is one of the view's own lights (AddLight: the Light Inspector's lights),
positional, a 35-degree spotlight at the lamp head, aimed down the street. The air is
drawn by a Cloud display of a grid whose density is zero everywhere: no cloud, only
the air with its fog (Fog Visibility) and the ground. At night (the sun 10 degrees
below the horizon) the lamp alone lights the fog: its beam, the pool of light on the
ground, and the post's shadow on the ground and in the fog behind it. Coordinates in
metres, z up, the ground at z = 0. docs/lights-paraview.md shows the same in the GUI.
"""
import argparse
import math

from paraview.simple import (AddLight, Box, Calculator, ColorBy, Cone, CreateRenderView,
                             LoadPlugin, Render, SaveScreenshot, Show, Wavelet)

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("plugin", nargs="?",
                    default="build/lib/paraview-5.11/plugins/Nimbus/Nimbus.so")
parser.add_argument("screenshot", nargs="?", default="lamp-in-fog.png")
parser.add_argument("--size", type=int, nargs=2, default=[800, 500])
parser.add_argument("--exposure", type=float, default=800.0,
                    help="pixel = exposure x radiance (the sun's units); 100 to 1000 at night")
parser.add_argument("--fog", type=float, default=80.0, help="fog visibility in metres")
parser.add_argument("--shadow-map", type=int, default=1024,
                    help="Light Shadow Map Size in texels (the Cloud display's default: 256)")
args = parser.parse_args()

LoadPlugin(args.plugin, ns=globals())

view = CreateRenderView()
view.ViewSize = args.size
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0.0, 0.0, 0.0]  # the Cloud display draws the night sky over it
view.UseLight = 0  # no light kit: at night the lamp alone lights the scene

# The lamp: 4.5 m up, aimed down the street (+x) at 30 degrees below the horizon.
lamp = [0.0, 0.0, 4.5]
aim = [7.0, 0.0, 0.5]
axis = [a - p for a, p in zip(aim, lamp)]
length = math.sqrt(sum(c * c for c in axis))
axis = [c / length for c in axis]

# The air: a grid over the scene whose density is zero (no cloud; the air, the fog
# and the ground are drawn everywhere in the view, lit by the lamp over the scene).
grid = Wavelet(WholeExtent=[-8, 8, -6, 12, 0, 8])  # 1 m spacing, bounds in metres
air = Calculator(Input=grid, ResultArrayName="density", Function="0")
air_display = Show(air, view)
air_display.SetRepresentationType("Cloud")
ColorBy(air_display, ("POINTS", "density"))
air_display.SunElevationDegrees = -10.0  # night: the sun below the horizon
air_display.FogVisibilityMetres = args.fog
air_display.Exposure = args.exposure
air_display.LightShadowMapSize = args.shadow_map

# The light: positional, a 35-degree spotlight at the lamp head. Intensity I lights a
# surface d metres away as a sun of brightness I / d^2 would (Light Intensity Scale 1).
light = AddLight(view=view)
light.Coords = "Scene"
light.Type = "Positional"
light.Position = lamp
light.FocalPoint = aim
light.ConeAngle = 35.0
light.Intensity = 1.0
light.DiffuseColor = [1.0, 0.85, 0.6]  # a warm white

# The lamp head (a cone whose open base faces the beam, 5 cm behind the light), its arm
# and its pole: behind the light, outside the beam. They are opaque geometry drawn by
# ParaView (not by the Cloud display); a little ambient light keeps their outline.
head = Cone(Radius=0.3, Height=0.5, Resolution=32, Direction=[-c for c in axis],
            Center=[p - 0.3 * c for p, c in zip(lamp, axis)])
pole = Box(XLength=0.18, YLength=0.18, ZLength=4.6, Center=[-0.7, 0.0, 2.3])
arm = Box(XLength=0.8, YLength=0.08, ZLength=0.08, Center=[-0.35, 0.0, 4.65])
# The post in the beam, 1.4 m from the lamp: 0.5 m square, 3.6 m high.
post = Box(XLength=0.5, YLength=0.5, ZLength=3.6, Center=[1.4, 0.0, 1.8])
for part in (head, pole, arm, post):
    display = Show(part, view)
    display.DiffuseColor = [0.35, 0.33, 0.3]
    display.Ambient = 0.5
    display.AmbientColor = [0.1, 0.1, 0.1]

# The first Render resets the camera to the data; the view is set after it: at eye
# height beside the lamp, looking down the street past the post.
Render(view)
view.CameraPosition = [-3.0, -8.0, 1.7]
view.CameraFocalPoint = [4.0, 0.0, 2.5]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.CameraViewAngle = 42.0
Render(view)
SaveScreenshot(args.screenshot, view, ImageResolution=args.size)
print(args.screenshot)
