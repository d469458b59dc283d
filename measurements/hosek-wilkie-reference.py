# Reference values of the Hosek & Wilkie 2012 clear sky ("An Analytic Model for Full
# Spectral Sky-Dome Radiance", ACM TOG 31(4)) for Nimbus's sky validation
# (Physics/Testing/TestSky.cxx, Sky.ValidationAgainstHosekWilkie). The model is
# evaluated by an independent implementation: Blender's Cycles ("Sky Texture" node,
# type Hosek / Wilkie, the authors' CIE XYZ data set), rendered as an equirectangular
# panorama of the upper hemisphere and read back at the test's directions.
#
#   blender -b --factory-startup --python measurements/hosek-wilkie-reference.py -- \
#       Physics/Testing/Data/hosek-wilkie-reference.csv
#
# Blender 3.4 (Debian bookworm's `blender`); about 1 minute on 2 cores. Output: one row
# per direction: turbidity, sun elevation (deg), kind (dome | ring | zenith), view
# elevation (deg), azimuth from the sun (deg), CIE 1931 X, Y, Z (relative units: Cycles
# scales the model by 2 pi / 683; the test normalises). Cycles writes scene-linear
# Rec.709 RGB converted from the model's XYZ by the sRGB matrix of Blender's OCIO
# config (luts/srgb_to_xyz.spimtx: the standard D65 one); this script applies that
# matrix back. Ground albedo 0.3 (Nimbus's default).
import math
import sys

import bpy
import numpy as np

TURBIDITIES = (2.0, 3.0, 4.0, 5.0)
SUN_ELEVATIONS = (1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0, 90.0)
GROUND_ALBEDO = 0.3
WIDTH, HEIGHT = 1440, 360  # 0.25 deg pixels, latitudes 0..90 deg
SRGB_TO_XYZ = np.array([[0.4124564, 0.3575761, 0.1804375],
                        [0.2126729, 0.7151522, 0.0721750],
                        [0.0193339, 0.1191920, 0.9503041]])


def direction(elevation, azimuth):
    e, a = math.radians(elevation), math.radians(azimuth)
    return np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])


def test_directions(sun_elevation):
    """The directions of TestSky's CompareSky: the dome grid, rings 3..15 deg around the
    sun (12 each, those above 2 deg elevation) and the zenith; (kind, elevation, azimuth)."""
    out = []
    for i in range(18):
        for j in range(19):
            out.append(("dome", 2.5 + 5.0 * i, 10.0 * j))
    s = direction(sun_elevation, 0.0)
    u = np.cross(s, np.array([1.0, 0.0, 0.0]))
    u /= np.linalg.norm(u)
    v = np.cross(s, u)
    for g in (3.0, 5.0, 8.0, 12.0, 15.0):
        for k in range(12):
            cg, sg = math.cos(math.radians(g)), math.sin(math.radians(g))
            cp, sp = math.cos(math.radians(30.0 * k)), math.sin(math.radians(30.0 * k))
            w = cg * s + sg * (cp * u + sp * v)
            if w[2] < math.sin(math.radians(2.0)):
                continue
            elevation = math.degrees(math.asin(max(-1.0, min(1.0, w[2]))))
            azimuth = math.degrees(math.atan2(w[1], w[0]))
            out.append(("ring", elevation, azimuth))
    out.append(("zenith", 90.0, 0.0))
    return out


def setup_scene():
    scene = bpy.context.scene
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.filter_size = 0.01  # one ray through each pixel's centre
    scene.view_settings.view_transform = 'Standard'
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.image_settings.color_depth = '32'
    camera = bpy.data.cameras.new("panorama")
    camera.type = 'PANO'
    camera.cycles.panorama_type = 'EQUIRECTANGULAR'
    camera.cycles.latitude_min, camera.cycles.latitude_max = 0.0, math.pi / 2
    camera.cycles.longitude_min, camera.cycles.longitude_max = -math.pi, math.pi
    obj = bpy.data.objects.new("panorama", camera)
    obj.rotation_euler = (math.radians(90.0), 0.0, math.radians(-90.0))  # longitude 0 = +x
    scene.collection.objects.link(obj)
    scene.camera = obj
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    scene.world = world
    sky = world.node_tree.nodes.new("ShaderNodeTexSky")
    sky.sky_type = 'HOSEK_WILKIE'
    sky.ground_albedo = GROUND_ALBEDO
    world.node_tree.links.new(sky.outputs[0], world.node_tree.nodes["Background"].inputs[0])
    return scene, sky


def render(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    rgb = np.array(image.pixels[:], dtype=np.float64).reshape(HEIGHT, WIDTH, 4)[..., :3]
    bpy.data.images.remove(image)
    return rgb  # row 0 = latitude 0 (Blender images are stored bottom up)


def bilinear(rgb, elevation, azimuth):
    x = (azimuth + 180.0) / 360.0 * WIDTH - 0.5
    y = min(max(elevation / 90.0 * HEIGHT - 0.5, 0.0), HEIGHT - 1.0)
    x0, y0 = math.floor(x), min(math.floor(y), HEIGHT - 2)
    fx, fy = x - x0, y - y0
    x0, x1 = x0 % WIDTH, (x0 + 1) % WIDTH
    top = (1 - fx) * rgb[y0 + 1, x0] + fx * rgb[y0 + 1, x1]
    bottom = (1 - fx) * rgb[y0, x0] + fx * rgb[y0, x1]
    return (1 - fy) * bottom + fy * top


def main():
    output = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "hosek-wilkie-reference.csv"
    scene, sky = setup_scene()
    rows = []
    for turbidity in TURBIDITIES:
        for sun in SUN_ELEVATIONS:
            sky.turbidity = turbidity
            sky.sun_direction = tuple(direction(sun, 0.0))
            rgb = render(scene, bpy.app.tempdir + "hosek-wilkie.exr")
            # Check the orientation: the circumsolar maximum lies toward azimuth 0.
            for kind, elevation, azimuth in test_directions(sun):
                if kind == "zenith":
                    c = rgb[HEIGHT - 1].mean(axis=0)  # the top row circles the zenith
                else:
                    c = bilinear(rgb, elevation, azimuth)
                xyz = SRGB_TO_XYZ @ c
                rows.append("%.0f,%.0f,%s,%.6f,%.6f,%.8g,%.8g,%.8g" % (
                    turbidity, sun, kind, elevation, azimuth, xyz[0], xyz[1], xyz[2]))
            toward = bilinear(rgb, min(sun + 5.0, 85.0), 0.0)[1]
            away = bilinear(rgb, min(sun + 5.0, 85.0), 180.0)[1]
            if sun < 80.0 and not toward > away:
                raise SystemExit("panorama orientation: the sun is not at azimuth 0")
    with open(output, "w") as f:
        f.write("# Hosek & Wilkie 2012 clear sky, rendered by Blender %s Cycles; "
                "measurements/hosek-wilkie-reference.py\n" % bpy.app.version_string)
        f.write("turbidity,sun_elevation_deg,kind,view_elevation_deg,azimuth_from_sun_deg,X,Y,Z\n")
        f.write("\n".join(rows) + "\n")
    print("wrote %d rows to %s" % (len(rows), output))


main()
