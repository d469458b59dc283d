"""The trade harness runs end to end on a tiny scene: references (cached on the
second run; path-traced for multiple-scattering settings, single scattering for the
others), VTK's GPU mapper, the SVS mapper and the reference renderer's own trade
curve, CSV with every metric, plots; the RMSE's correction for a noisy reference."""
import csv
import json
import math
import os
import shutil
import sys
import tempfile
import unittest

import numpy as np

from nimbus import harness

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data", "tiny_scene.json")


# The light of the lit test scenes: a soft-edged spot 5 m up, pointing down.
SPOT = {"type": "spot", "position": [0, 0, 5], "direction": [0, 0, -1], "cone_angle_degrees": 40,
        "edge_degrees": 10, "intensity": 20, "temperature_kelvin": 3000}


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

    def test_psnr_of_a_robust_peak(self):
        # One pixel 100 times brighter than the rest (the pixel next to a light) sets the
        # peak of psnr_db, not that of psnr_p999_db.
        reference = np.full((40, 50, 3), 0.1)
        reference[7, 9] = 10.0
        image = reference + 0.001
        metrics = harness.error_metrics(image, reference)
        self.assertAlmostEqual(metrics["psnr_db"], 20.0 * math.log10(10.0 / 0.001), places=6)
        self.assertAlmostEqual(metrics["psnr_p999_db"], 20.0 * math.log10(0.1 / 0.001), places=6)

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
        # Lights (scene format version 3) are the path tracer's and, for points and spots,
        # the SVS mapper's: VTK's GPU mapper refuses them by name, and the SVS mapper
        # refuses the lightning channels (polylines) instead of rendering without them.
        with open(SCENE) as stream:
            text = stream.read()
        text = text.replace('"nimbus_scene": 2', '"nimbus_scene": 3')
        point = text.replace(
            '"spectral_samples": 8',
            '"spectral_samples": 8, "lights": [{"type": "point", "position": [0, 0, 1500], '
            '"intensity": 1e5}]')
        polyline = text.replace(
            '"spectral_samples": 8',
            '"spectral_samples": 8, "lights": [{"type": "polyline", "vertices": '
            '[[0, 0, 100], [0, 0, 900]], "intensity_per_metre": 1e3}]')
        paths = {}
        for name, content in (("point", point), ("polyline", polyline)):
            paths[name] = os.path.join(self.output, name + ".json")
            with open(paths[name], "w") as stream:
                stream.write(content)
        scene = harness.load_scene(paths["point"])
        self.assertEqual(harness.version3_features(scene),
                         ["point and polyline lights (scene.lights)"])
        self.assertEqual(harness.version3_features(harness.load_scene(SCENE)), [])
        self.assertEqual(harness.svs_unsupported_features(scene), [])
        with self.assertRaisesRegex(ValueError, "does not render point and polyline lights"):
            harness.VtkGpuRenderer(paths["point"], None)
        with self.assertRaisesRegex(ValueError, "does not render polyline lights"):
            harness.SvsRenderer(paths["polyline"])

    # --- the view's own lights (scene format version 4) ----------------------------------

    def write_lit_scene(self, name="lit", **changes):
        """A small night scene in fog: a soft-edged spot 5 m up, pointing down, a black box
        in its beam, an empty medium (extinction 0); `changes` replace top-level keys."""
        scene = {
            "nimbus_scene": 4, "name": name,
            "camera": {"position": [0, -12, 1.5], "focal_point": [0, 0, 2],
                       "view_angle": 50, "width": 48, "height": 36},
            "medium": {"density": {"type": "metaball_cloud", "parameters": {
                "Dimensions": [8, 8, 4], "Bounds": [-6, 6, -6, 6, 0, 6],
                "NumberOfLevels": 0, "BallDensity": 0}}, "extinction_per_density": 0},
            "sun": {"azimuth_degrees": 0, "elevation_degrees": -30},
            "atmosphere": {"mie_scattering_per_metre": 0.01},
            "ground": {"albedo": 0.2},
            "spectral_samples": 8,
            "lights": [SPOT],
            "occluders": [{"type": "box", "min": [0.5, -1.5, 0], "max": [0.8, -1.2, 3],
                           "albedo": 0}],
        }
        scene.update(changes)
        path = os.path.join(self.output, name + ".json")
        with open(path, "w") as stream:
            json.dump(scene, stream)
        return path

    def test_blackbody_colour(self):
        # The lights' colour: a blackbody in linear sRGB at luminance 1 (CIE 1931, Planck).
        for kelvin in (1000.0, 3000.0, 5778.0, 6500.0, 20000.0):
            r, g, b = harness.blackbody_linear_srgb(kelvin)
            self.assertAlmostEqual(0.2126 * r + 0.7152 * g + 0.0722 * b, 1.0, delta=1e-3)
        # Warm lamps are red, hot stars blue; 6500 K is close to sRGB's white (D65).
        warm, white, blue = (harness.blackbody_linear_srgb(k) for k in (3000.0, 6500.0, 20000.0))
        self.assertGreater(warm[0], warm[1])
        self.assertGreater(warm[1], warm[2])
        self.assertGreater(blue[2], blue[0])
        for c in white:
            self.assertAlmostEqual(c, 1.0, delta=0.08)
        # The colour-matching functions peak where CIE 1931's do.
        x, y, z = harness.cie_xyz_bar_1931(np.array([599.8, 555.0, 442.0]))
        self.assertAlmostEqual(x[0], 1.056 + 0.362 * math.exp(-0.5 * (157.8 / 26.7) ** 2)
                               - 0.065 * math.exp(-0.5 * (98.7 / 26.2) ** 2), places=9)
        self.assertAlmostEqual(y[1], 1.0, delta=0.02)

    def test_scene_lights_and_occluders(self):
        point = {"type": "point", "position": [1, 2, 3], "intensity": 7,
                 "temperature_kelvin": 4000}
        scene = harness.load_scene(self.write_lit_scene(lights=[point, SPOT]))
        point_light, spot = harness.scene_vtk_lights(scene)
        for light, description in ((point_light, point), (spot, scene["lights"][1])):
            self.assertTrue(light.GetPositional())
            self.assertTrue(light.GetSwitch())
            self.assertEqual(light.GetPosition(), tuple(float(x) for x in description["position"]))
            # Intensity x DiffuseColor: the radiant intensity per channel (Y/sr).
            expected = description["intensity"] * harness.blackbody_linear_srgb(
                description["temperature_kelvin"])
            got = light.GetIntensity() * np.array(light.GetDiffuseColor())
            np.testing.assert_allclose(got, expected, rtol=1e-12)
            self.assertLessEqual(max(light.GetDiffuseColor()), 1.0)
        self.assertEqual(point_light.GetConeAngle(), 180.0)  # not a spot
        self.assertEqual(spot.GetConeAngle(), 40.0)
        self.assertEqual(spot.GetFocalPoint(), (0.0, 0.0, 4.0))
        self.assertEqual(harness.spot_edge_degrees(scene), 10.0)
        self.assertIsNone(harness.spot_light_map_path(scene))
        (actor,) = harness.occluder_actors(scene)
        np.testing.assert_allclose(actor.GetBounds(), (0.5, 0.8, -1.5, -1.2, 0.0, 3.0))
        self.assertEqual(actor.GetProperty().GetColor(), (0.0, 0.0, 0.0))
        # A mesh, scaled then translated.
        mesh = os.path.join(self.output, "tri.obj")
        with open(mesh, "w") as stream:
            stream.write("v 0 0 0\nv 1 0 0\nv 0 1 1\nf 1 2 3\n")
        meshes = self.write_lit_scene("mesh", occluders=[{
            "type": "mesh", "path": "tri.obj", "albedo": 0.5, "scale": 2,
            "translate": [10, 0, 0]}])
        (actor,) = harness.occluder_actors(harness.load_scene(meshes))
        np.testing.assert_allclose(actor.GetBounds(), (10, 12, 0, 2, 0, 2))
        self.assertEqual(actor.GetProperty().GetColor(), (0.5, 0.5, 0.5))

    def test_light_map_rows_and_decoding(self):
        # Both renderers put the picture's bottom row at v = 0 (thrown upright), and the
        # mapper's v = 0 is the first row of VTK's data, which VTK's readers make the
        # picture's bottom: the rows stay as read. 8-bit PNG is decoded from sRGB, colours
        # give Y of linear sRGB.
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkIOImage import vtkPNGWriter
        top = [255, 255, 255]
        bottom = [128, 0, 0]
        pixels = np.array([bottom] * 3 + [top] * 3, dtype=np.uint8)  # VTK: bottom row first
        data = vtkImageData()
        data.SetDimensions(3, 2, 1)
        data.GetPointData().SetScalars(numpy_to_vtk(pixels, deep=True))
        path = os.path.join(self.output, "map.png")
        writer = vtkPNGWriter()
        writer.SetFileName(path)
        writer.SetInputData(data)
        writer.Write()
        light_map = harness.read_light_map(path)
        self.assertEqual(light_map.GetDimensions(), (3, 2, 1))
        from vtkmodules.util.numpy_support import vtk_to_numpy
        values = vtk_to_numpy(light_map.GetPointData().GetScalars()).reshape(2, 3)
        red = ((128 / 255 + 0.055) / 1.055) ** 2.4
        np.testing.assert_allclose(values[0], 0.2126 * red, rtol=1e-5)  # the bottom first
        np.testing.assert_allclose(values[1], 1.0, rtol=1e-6)
        with self.assertRaisesRegex(ValueError, "no such file"):
            harness.read_light_map(os.path.join(self.output, "missing.png"))

    def test_features_the_renderers_refuse(self):
        lit = harness.load_scene(self.write_lit_scene())
        self.assertEqual(harness.svs_unsupported_features(lit), [])
        self.assertEqual(harness.version4_features(lit),
                         ["spot lights (scene.lights[i] of type spot)",
                          "occluders (scene.occluders)"])
        with self.assertRaisesRegex(ValueError, "VTK GPU mapper does not render .*spot lights"):
            harness.refuse_unsupported_features("lit", lit, "vtk-gpu")
        spot = lit["lights"][0]
        cases = {
            "different soft edges": dict(lights=[spot, dict(spot, edge_degrees=5)]),
            "different light maps": dict(lights=[spot, dict(spot, light_map="x.png")]),
            "occluders in sunlight": dict(sun={"azimuth_degrees": 0, "elevation_degrees": 20}),
            "more than 8 lights": dict(lights=[spot] * 9),
        }
        for words, changes in cases.items():
            scene = dict(lit, **changes)
            if "illuminance" not in scene["sun"]:
                scene["sun"] = dict(scene["sun"], illuminance=1.0)
            with self.assertRaisesRegex(ValueError, "SVS mapper does not render .*" + words):
                harness.refuse_unsupported_features("lit", scene, "svs")
        # run() skips the scenes a renderer refuses (a glob of Data/Scenes holds both
        # kinds) and fails only when nothing is left.
        path = self.write_lit_scene()
        for renderer in ("vtk-gpu", "single"):
            self.assertEqual(harness.run([path, "--renderer", renderer, "--output-dir",
                                          self.output]), 1)
        self.assertFalse(os.path.exists(os.path.join(self.output, "trade.csv")))
        # The sun below the horizon or dark: occluders are fine.
        dark = dict(lit, sun={"azimuth_degrees": 0, "elevation_degrees": 20, "illuminance": 0})
        self.assertEqual(harness.svs_unsupported_features(dark), [])

    def test_svs_draws_the_lights_as_the_path_tracer(self):
        # The spot, its shafts in the fog, its shadow of the box and the lit ground, by the
        # mapper's two shaft methods, against the path tracer's single scattering (its
        # multiple scattering is what the mapper leaves out). At night: the sun 30 degrees
        # below the horizon.
        path = self.write_lit_scene()
        renderer = harness.SvsRenderer(path)
        try:
            with self.assertRaisesRegex(ValueError, "only the ray march draws"):
                renderer.render({"slices": 64})
            image = renderer.render({"method": "march"})
            self.assertEqual(renderer.mapper.GetNumberOfLightsLastRender(), 1)
            self.assertEqual(renderer.mapper.GetNumberOfShadowCastersLastRender(), 1)
            self.assertEqual(renderer.mapper.GetSunElevationDegrees(), -30.0)
            # Dark where the beam is not: the top corners see the night sky.
            self.assertLess(float(image[-3:, :3].max()), 1e-6)
            self.assertGreater(float(image.max()), 1e-3)
        finally:
            renderer.close()
        settings = os.path.join(self.output, "lights.json")
        with open(settings, "w") as stream:
            # The slices' row is skipped (only the ray march draws lights).
            # supersample 2: drawn at 96 x 72 and averaged over 2 x 2 blocks.
            json.dump([{"method": "march", "light_samples": 32}, {"slices": 64},
                       {"method": "march", "light_method": "planes", "virtual_planes": 64},
                       {"method": "march", "supersample": 2}],
                      stream)
        self.assertEqual(harness.run([path, "--renderer", "svs", "--settings", settings,
                                      "--reference", "path-single", "--reference-seconds", "4",
                                      "--repeats", "1", "--side-by-side",
                                      "--display-exposure", "20",
                                      "--output-dir", self.output]), 0)
        with open(os.path.join(self.output, "trade.csv")) as stream:
            rows = list(csv.DictReader(stream))
        self.assertEqual(len(rows), 3)
        for row in rows:
            self.assertRegex(row["reference"], r"^path-single \(")
            # Measured on llvmpipe: 37.7 and 37.2 dB (a 4 s reference, 1250 samples per pixel),
            # 44.9 dB supersampled: the rest is mostly the pixel's area, which the path
            # tracer integrates and the mapper samples at its centre.
            self.assertGreater(float(row["psnr_db"]), 30.0, row)
        # Multiple scattering's share: the path tracer stopped at the first scattering
        # against the full one (the fog's higher orders add light: the ratio is below 1).
        self.assertEqual(harness.run([path, "--compare-references", "path-single", "path",
                                      "--reference-seconds", "4", "--output-dir",
                                      self.output]), 0)
        with open(os.path.join(self.output, "reference-pairs.csv")) as stream:
            (pair,) = list(csv.DictReader(stream))
        self.assertRegex(pair["image"], r"^path-single \(")
        self.assertRegex(pair["reference"], r"^path \(")
        self.assertLess(float(pair["mean_ratio"]), 1.0)
        self.assertGreater(float(pair["mean_ratio"]), 0.5)
        # Reference, image and difference side by side, 2 pixels apart.
        from vtkmodules.vtkIOImage import vtkPNGReader
        reader = vtkPNGReader()
        reader.SetFileName(os.path.join(self.output, "lit-svs-2-side.png"))
        reader.Update()
        self.assertEqual(reader.GetOutput().GetDimensions(), (3 * 48 + 4, 36, 1))


if __name__ == "__main__":
    result = unittest.main(exit=False, verbosity=2).result
    sys.exit(0 if result.wasSuccessful() else 1)
