"""The trade harness runs end to end on a tiny scene: reference (cached on the
second run), VTK's GPU mapper, the SVS mapper and the reference renderer's own
trade curve, CSV with every metric, plots."""
import csv
import math
import os
import shutil
import sys
import tempfile
import unittest

from nimbus import harness

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data", "tiny_scene.json")


class HarnessTest(unittest.TestCase):
    def setUp(self):
        self.output = tempfile.mkdtemp(prefix="nimbus-harness-")

    def tearDown(self):
        shutil.rmtree(self.output, ignore_errors=True)

    def run_harness(self, *extra):
        return harness.run([SCENE, "--renderer", "vtk-gpu", "--renderer", "single",
                            "--repeats", "1", "--output-dir", self.output, *extra])

    def test_csv_plot_and_cache(self):
        self.assertEqual(self.run_harness("--markdown", os.path.join(self.output, "t.md")), 0)
        with open(os.path.join(self.output, "trade.csv")) as stream:
            rows = list(csv.DictReader(stream))
        expected = len(harness.DEFAULT_SETTINGS["vtk-gpu"]) + len(harness.DEFAULT_SETTINGS["single"])
        self.assertEqual(len(rows), expected)
        for row in rows:
            for field in ("median_seconds", "rmse", "relative_l1", "max_abs"):
                self.assertTrue(math.isfinite(float(row[field])), (field, row))
                self.assertGreaterEqual(float(row[field]), 0.0)
        single = [float(r["rmse"]) for r in rows if r["renderer"] == "single"]
        # Finer steps approach the reference (the last one is the reference's own step).
        self.assertEqual(single, sorted(single, reverse=True))
        for name in ("trade.png", "tiny_scene-trade.png", "tiny_scene-reference.png", "t.md"):
            self.assertTrue(os.path.getsize(os.path.join(self.output, name)) > 0, name)
        cache = os.listdir(os.path.join(self.output, "reference-cache"))
        self.assertEqual(len(cache), 2)  # the reference and the sky-only reference
        # A second run takes the references from the cache.
        self.assertEqual(self.run_harness(), 0)
        self.assertEqual(sorted(os.listdir(os.path.join(self.output, "reference-cache"))),
                         sorted(cache))

    def test_svs_mapper_converges_to_the_reference(self):
        settings = os.path.join(self.output, "svs.json")
        with open(settings, "w") as stream:
            stream.write('[{"slices": 8}, {"slices": 32}, {"slices": 128}]')
        self.assertEqual(harness.run([SCENE, "--renderer", "svs", "--settings", settings,
                                      "--repeats", "1", "--output-dir", self.output]), 0)
        with open(os.path.join(self.output, "trade.csv")) as stream:
            rmse = [float(r["rmse"]) for r in csv.DictReader(stream)]
        # Measured on llvmpipe: 8.6e-4, 3.2e-4, 3.1e-4 (the floor: see docs/svs-mapper.md).
        self.assertEqual(rmse, sorted(rmse, reverse=True))
        self.assertLess(rmse[-1], 4e-4)

    def test_fast_renderers_refuse_version3_features(self):
        # Lights (scene format version 3) are the path tracer's: the GPU mappers say so by
        # name instead of rendering the scene without them.
        with open(SCENE) as stream:
            text = stream.read()
        text = text.replace('"nimbus_scene": 2', '"nimbus_scene": 3').replace(
            '"spectral_samples": 8',
            '"spectral_samples": 8, "lights": [{"type": "point", "position": [0, 0, 1500], '
            '"intensity": 1e5}]')
        path = os.path.join(self.output, "lit.json")
        with open(path, "w") as stream:
            stream.write(text)
        scene = harness.load_scene(path)
        self.assertEqual(harness.version3_features(scene),
                         ["point and polyline lights (scene.lights)"])
        self.assertEqual(harness.version3_features(harness.load_scene(SCENE)), [])
        for make in (lambda: harness.VtkGpuRenderer(path, None),
                     lambda: harness.SvsRenderer(path)):
            with self.assertRaisesRegex(ValueError, "does not render point and polyline lights"):
                make()


if __name__ == "__main__":
    result = unittest.main(exit=False, verbosity=2).result
    sys.exit(0 if result.wasSuccessful() else 1)
