"""Writes the data files of the light scenes (Data/Scenes/lights/):

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 \
        measurements/make-light-scenes.py [--output-dir Data/Scenes/lights]

  window_gobo.png   a gobo for gobo_haze.json: a window of four panes behind a cross of
                    bars, 256 x 256 pixels, 8-bit grey (white = the light passes, black =
                    the bars). One pane, the top left as an image viewer shows it, has one
                    more horizontal bar, so that a flip or a turn of the map shows.
  post.ply          the post of streetlight_fog.json: a capped cylinder of 16 sides,
                    radius 0.12 m, from z = 0 to z = 4 m about the z axis, triangles,
                    ASCII PLY (the scene places it with "translate").

Both are computed from the constants below (no randomness): running this again gives
the same bytes.
"""
import argparse
import math
import os

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

GOBO_NAME = "window_gobo.png"
GOBO_SIZE = 256          # pixels a side
GOBO_BAR = 28            # width of the cross's bars, pixels
GOBO_FRAME = 20          # width of the window's frame, pixels
GOBO_MARK = 10           # width of the extra bar in the top-left pane, pixels

POST_NAME = "post.ply"
POST_RADIUS = 0.12       # m
POST_HEIGHT = 4.0        # m
POST_SIDES = 16


def gobo_pixels():
    """The gobo as rows from the top (as an image viewer shows it), 0 or 255."""
    n = GOBO_SIZE
    image = np.full((n, n), 255, dtype=np.uint8)
    image[:GOBO_FRAME, :] = 0
    image[-GOBO_FRAME:, :] = 0
    image[:, :GOBO_FRAME] = 0
    image[:, -GOBO_FRAME:] = 0
    middle = n // 2
    image[middle - GOBO_BAR // 2:middle + GOBO_BAR // 2, :] = 0
    image[:, middle - GOBO_BAR // 2:middle + GOBO_BAR // 2] = 0
    # The top-left pane's extra bar, halfway down that pane.
    pane_middle = (GOBO_FRAME + middle - GOBO_BAR // 2) // 2
    image[pane_middle - GOBO_MARK // 2:pane_middle + GOBO_MARK // 2, :middle] = 0
    return image


def write_gobo(path):
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter
    pixels = gobo_pixels()
    data = vtkImageData()
    data.SetDimensions(GOBO_SIZE, GOBO_SIZE, 1)
    # VTK's rows count from the bottom: the viewer's top row is VTK's last.
    data.GetPointData().SetScalars(numpy_to_vtk(pixels[::-1].reshape(-1), deep=True))
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(data)
    writer.Write()


def post_triangles():
    """Vertices and triangles (outward, counter-clockwise) of the capped cylinder."""
    vertices = []
    for z in (0.0, POST_HEIGHT):
        for k in range(POST_SIDES):
            angle = 2.0 * math.pi * k / POST_SIDES
            vertices.append((POST_RADIUS * math.cos(angle), POST_RADIUS * math.sin(angle), z))
    bottom_centre = len(vertices)
    vertices.append((0.0, 0.0, 0.0))
    top_centre = len(vertices)
    vertices.append((0.0, 0.0, POST_HEIGHT))
    triangles = []
    for k in range(POST_SIDES):
        a, b = k, (k + 1) % POST_SIDES
        triangles.append((a, b, POST_SIDES + b))
        triangles.append((a, POST_SIDES + b, POST_SIDES + a))
        triangles.append((bottom_centre, b, a))
        triangles.append((top_centre, POST_SIDES + a, POST_SIDES + b))
    return vertices, triangles


def write_post(path):
    vertices, triangles = post_triangles()
    with open(path, "w", newline="\n") as stream:
        stream.write("ply\nformat ascii 1.0\n")
        stream.write("comment Nimbus streetlight_fog post: measurements/make-light-scenes.py\n")
        stream.write(f"element vertex {len(vertices)}\n")
        stream.write("property float x\nproperty float y\nproperty float z\n")
        stream.write(f"element face {len(triangles)}\n")
        stream.write("property list uchar int vertex_indices\nend_header\n")
        for x, y, z in vertices:
            stream.write(f"{x:.6f} {y:.6f} {z:.6f}\n")
        for a, b, c in triangles:
            stream.write(f"3 {a} {b} {c}\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--output-dir", default=os.path.join(REPO, "Data", "Scenes", "lights"))
    args = parser.parse_args()
    os.makedirs(args.output_dir, exist_ok=True)
    for name, write in ((GOBO_NAME, write_gobo), (POST_NAME, write_post)):
        path = os.path.join(args.output_dir, name)
        write(path)
        print(path)


if __name__ == "__main__":
    main()
