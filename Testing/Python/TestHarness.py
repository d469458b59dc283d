"""The trade harness runs end to end on a tiny scene: references (cached on the
second run; path-traced for multiple-scattering settings, single scattering for the
others), VTK's GPU mapper, the SVS mapper and the reference renderer's own trade
curve, CSV with every metric, plots; the RMSE's correction for a noisy reference."""
import csv
import math
import os
import shutil
import sys
import tempfile
import unittest

import numpy as np

from nimbus import harness

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data", "tiny_scene.json")


class HarnessTest(unittest.TestCase):
    def setUp(self):
        self.output = tempfile.mkdtemp(prefix="nimbus-harness-")

    def tearDown(self):
        shutil.rmtree(self.output, ignore_errors=True)

    def run_harness(self, *extra):
        # A 2 s budget for the path-traced reference (the tiny scene then has ~6 %
        # image-wide error, measured): this test checks the plumbing, not the figures.
        return harness.run([SCENE, "--renderer", "vtk-gpu", "--renderer", "single",
                            "--repeats", "1", "--reference-seconds", "2",
                            "--output-dir", self.output, *extra])

    def test_csv_plot_and_cache(self):
        self.assertEqual(self.run_harness("--markdown", os.path.join(self.output, "t.md")), 0)
        with open(os.path.join(self.output, "trade.csv")) as stream:
            rows = list(csv.DictReader(stream))
        expected = len(harness.DEFAULT_SETTINGS["vtk-gpu"]) + len(harness.DEFAULT_SETTINGS["single"])
        self.assertEqual(len(rows), expected)
        for row in rows:
            for field in ("median_seconds", "rmse", "rmse_raw", "reference_noise",
                          "relative_l1", "max_abs"):
                self.assertTrue(math.isfinite(float(row[field])), (field, row))
                self.assertGreaterEqual(float(row[field]), 0.0)
            self.assertLessEqual(float(row["rmse"]), float(row["rmse_raw"]))
            # --reference auto: single scattering judges the single-scattering renderer,
            # the path tracer (with its error in the label) judges VTK's mapper.
            if row["renderer"] == "single":
                self.assertEqual(row["reference"], "single")
                self.assertEqual(float(row["reference_noise"]), 0.0)
            else:
                self.assertRegex(row["reference"], r"^path \(±[0-9.e+-]+ %\)$")
                self.assertGreater(float(row["reference_noise"]), 0.0)
        single = [float(r["rmse"]) for r in rows if r["renderer"] == "single"]
        # Finer steps approach the reference (the last one is the reference's own step).
        self.assertEqual(single, sorted(single, reverse=True))
        for name in ("trade.png", "tiny_scene-trade.png", "tiny_scene-reference-single.png",
                     "tiny_scene-reference-path.png", "t.md"):
            self.assertTrue(os.path.getsize(os.path.join(self.output, name)) > 0, name)
        with open(os.path.join(self.output, "t.md")) as stream:
            self.assertIn("| reference |", stream.readline())
        cache = os.listdir(os.path.join(self.output, "reference-cache"))
        # single: the image; path and its sky-only version: image + standard error each.
        self.assertEqual(len(cache), 5, cache)
        self.assertEqual(len([name for name in cache if name.endswith("-stderr.npy")]), 2)
        # A second run takes the references from the cache.
        self.assertEqual(self.run_harness(), 0)
        self.assertEqual(sorted(os.listdir(os.path.join(self.output, "reference-cache"))),
                         sorted(cache))

    def test_noise_correction_recovers_the_error_against_the_truth(self):
        # An image with a known error against the truth, judged by references with
        # Gaussian noise of known standard error (and a noisy image part, as vtk-gpu's
        # composited path-traced sky): the corrected RMSE is the RMSE against the truth,
        # whatever the noise, while the raw one grows with it.
        generator = np.random.default_rng(7)
        truth = generator.uniform(0.0, 0.2, size=(96, 128, 3))
        image = truth + generator.normal(0.0, 0.004, size=truth.shape)
        true_rmse = float(np.sqrt(np.mean((image - truth) ** 2)))
        for sigma in (0.001, 0.004, 0.016):
            error = np.full(truth.shape, sigma)
            reference = truth + generator.normal(0.0, 1.0, size=truth.shape) * error
            metrics = harness.error_metrics(image, reference, error)
            self.assertAlmostEqual(metrics["reference_noise"], sigma, places=12)
            self.assertGreater(metrics["rmse_raw"], true_rmse)
            # 36864 values: the mean square's relative sampling error is ~1.5 %.
            self.assertLess(abs(metrics["rmse"] / true_rmse - 1.0), 0.05 if sigma < 0.01 else 0.15,
                            (sigma, metrics, true_rmse))
            noisy = image + generator.normal(0.0, 1.0, size=truth.shape) * error
            both = harness.error_metrics(noisy, reference, error, error)
            self.assertLess(abs(both["rmse"] / true_rmse - 1.0), 0.05 if sigma < 0.01 else 0.2,
                            (sigma, both, true_rmse))
        # Without noise information nothing is subtracted.
        plain = harness.error_metrics(image, truth)
        self.assertAlmostEqual(plain["rmse"], true_rmse, places=12)
        self.assertEqual(plain["rmse"], plain["rmse_raw"])

    def test_svs_mapper_converges_to_the_reference(self):
        settings = os.path.join(self.output, "svs.json")
        with open(settings, "w") as stream:
            # Single scattering (no multiple scattering in the air): judged by the
            # single-scattering reference.
            stream.write('[{"slices": 8, "air_ms": false}, {"slices": 32, "air_ms": false}, '
                         '{"slices": 128, "air_ms": false}]')
        self.assertEqual(harness.run([SCENE, "--renderer", "svs", "--settings", settings,
                                      "--repeats", "1", "--output-dir", self.output]), 0)
        with open(os.path.join(self.output, "trade.csv")) as stream:
            rmse = [float(r["rmse"]) for r in csv.DictReader(stream)]
        # Measured on llvmpipe: 8.6e-4, 3.2e-4, 3.1e-4 (the floor: see docs/svs-mapper.md).
        self.assertEqual(rmse, sorted(rmse, reverse=True))
        self.assertLess(rmse[-1], 4e-4)

    def test_svs_multiple_scattering_rows(self):
        # The multiple-scattering settings are judged by the path tracer and report
        # the solve's time and memory (octaves: the sky light's solve).
        settings = os.path.join(self.output, "ms.json")
        with open(settings, "w") as stream:
            stream.write('[{"ms": "directions", "orders": 4, "directions": 6}, '
                         '{"ms": "octaves", "octaves": 3}, {"slices": 32, "air_ms": false}]')
        self.assertEqual(harness.run([SCENE, "--renderer", "svs", "--settings", settings,
                                      "--repeats", "1", "--reference-seconds", "2",
                                      "--output-dir", self.output]), 0)
        with open(os.path.join(self.output, "trade.csv")) as stream:
            rows = list(csv.DictReader(stream))
        self.assertEqual(len(rows), 3)
        for row in rows[:2]:
            self.assertRegex(row["reference"], r"^path \(")
            self.assertGreater(float(row["precompute_seconds"]), 0.0, row)
            self.assertGreater(float(row["ms_mib"]), 0.0, row)
            self.assertTrue(math.isfinite(float(row["rmse"])))
        self.assertEqual(rows[2]["reference"], "single")
        self.assertEqual(float(rows[2]["precompute_seconds"]), 0.0)

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
