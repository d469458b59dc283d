#!/usr/bin/env python3
"""Side-by-side images of multiple scattering in the SVS mapper (003, 004).

For each scene: the SVS mapper with single scattering only (k_multi 0, 256 slices, single
scattering in the air too: paper 000), the same with the mapper's default multiple
scattering (discrete directions, and the air's), and the
path-traced reference from the harness's cache (full multiple scattering), each
tone-mapped like the harness's PNGs, with the RMSE and PSNR against the reference
(noise-corrected) under each panel.

    PYTHONPATH=build/lib/python3.11/site-packages Testing/with-display.sh /usr/bin/python3 \
        measurements/multiple-scattering-images.py CACHE_DIR OUTPUT_DIR Data/Scenes/silver_lining.json ...

CACHE_DIR is a harness --cache-dir holding the scenes' path-traced references (run the
harness once with --reference path to make them).
"""
import os
import sys

import numpy as np
from PIL import Image, ImageDraw

from nimbus import harness


def tone_map(image):
    encoded = np.clip(image * harness.DISPLAY_EXPOSURE, 0.0, 1.0)
    encoded = np.where(encoded <= 0.0031308, 12.92 * encoded,
                       1.055 * np.power(encoded, 1.0 / 2.4) - 0.055)
    return (encoded * 255.0 + 0.5).astype(np.uint8)[::-1]  # VTK's rows start at the bottom


def panel(image, title, subtitle):
    picture = Image.fromarray(tone_map(image))
    width, height = picture.size
    framed = Image.new("RGB", (width, height + 34), (255, 255, 255))
    framed.paste(picture, (0, 0))
    draw = ImageDraw.Draw(framed)
    draw.text((4, height + 2), title, fill=(0, 0, 0))
    draw.text((4, height + 17), subtitle, fill=(60, 60, 60))
    return framed


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    cache_dir, output_dir, scenes = argv[0], argv[1], argv[2:]
    os.makedirs(output_dir, exist_ok=True)
    for scene_path in scenes:
        name = os.path.splitext(os.path.basename(scene_path))[0]
        references = harness.SceneReferences(scene_path, name, cache_dir, output_dir,
                                             harness.REFERENCE_SETTINGS["path"]["time_limit"])
        reference, reference_error, label = references.get("path")
        renderer = harness.SvsRenderer(scene_path)
        panels = []
        try:
            for title, settings in (("SVS, single scattering (000)",
                                     {"k_multi": 0.0, "air_ms": False}),
                                    ("SVS + multiple scattering", {"ms": "directions"})):
                image = renderer.render(dict(settings, slices=256))
                metrics = harness.error_metrics(image, reference, reference_error)
                panels.append(panel(image, title, f"RMSE {metrics['rmse']:.4f}, "
                                                  f"PSNR {metrics['psnr_db']:.1f} dB"))
        finally:
            renderer.close()
        panels.append(panel(reference, "path-traced reference", label))
        width = sum(p.size[0] for p in panels)
        row = Image.new("RGB", (width, panels[0].size[1]), (255, 255, 255))
        x = 0
        for p in panels:
            row.paste(p, (x, 0))
            x += p.size[0]
        path = os.path.join(output_dir, f"{name}-multiple-scattering.png")
        row.save(path)
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
