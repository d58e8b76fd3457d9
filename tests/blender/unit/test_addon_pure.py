# SPDX-License-Identifier: Apache-2.0
"""Plain-Python tests of the add-on's bpy-free modules (python3 -m unittest, no Blender needed)."""

import json
import os
import re
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "blender_addon"))

from chromatrace import bands, batch_args, cache, camera_math, components, defaults, floats, manifest, node_rules, ply, spectra  # noqa: E402
from chromatrace import cameras, cycles_setup, planning, scene_parts, tool  # noqa: E402
from types import SimpleNamespace  # noqa: E402
from chromatrace.errors import BadInput  # noqa: E402
from chromatrace.journal import Journal  # noqa: E402


class Bands(unittest.TestCase):
    def test_groups_of_three_and_one_interleave_the_bands(self):
        # Each render spans the spectrum (core/band_plan.h, cycles_render_groups, groups them alike).
        self.assertEqual(bands.band_groups(7), [[0, 3, 6], [1, 4], [2, 5]])
        self.assertEqual(bands.band_groups(6), [[0, 2, 4], [1, 3, 5]])
        self.assertEqual(bands.band_groups(5, 2), [[0, 3], [1, 4], [2]])
        self.assertEqual(bands.band_groups(2, 1), [[0], [1]])
        self.assertEqual([bands.plan_group_of(7, b) for b in range(7)], [0, 1, 2, 0, 1, 2, 0])
        self.assertEqual(bands.describe_band_range([400, 450, 500, 550, 600], [0, 2]), "400-450, 500-550 nm")
        self.assertEqual(bands.describe_band_range([400, 450, 500, 550, 600], [1, 2]), "450-550 nm")
        with self.assertRaises(ValueError):
            bands.band_groups(3, 4)

    def test_group_samples_follow_the_plans_groups_of_three(self):
        # No samples in the plan: every render the request's. With them: each render its group's, and a render of
        # bands from two groups (two bands per render) the more of theirs; one band per render its own group's.
        self.assertEqual(bands.group_samples(bands.band_groups(7), None, 128), [128, 128, 128])
        self.assertEqual(bands.group_samples(bands.band_groups(7), [256, 64, 16], 128), [256, 64, 16])
        # Two a render: [0, 4], [1, 5], [2, 6], [3] of the plan's groups [0, 3, 6], [1, 4], [2, 5].
        self.assertEqual(bands.group_samples(bands.band_groups(7, 2), [256, 64, 16], 128), [256, 64, 256, 256])
        # One a render: the plan's groups of 4 bands are [0, 2] and [1, 3].
        self.assertEqual(bands.group_samples(bands.band_groups(4, 1), [256, 64], 128), [256, 64, 256, 64])

    def test_group_colour_fills_channels_in_order_and_zero_pads(self):
        values = [0.1, 0.2, 0.3, 0.4]
        self.assertEqual(bands.group_colour(values, [0, 1, 2]), (0.1, 0.2, 0.3))
        self.assertEqual(bands.group_colour(values, [3]), (0.4, 0.0, 0.0))
        self.assertEqual(bands.group_colour(values, [3], replicate=True), (0.4, 0.4, 0.4))
        self.assertEqual(bands.channel_of([3, 4, 5], 5), "B")


class Cameras(unittest.TestCase):
    SOURCE = os.path.join(os.path.dirname(__file__), "..", "..", "..")

    def test_every_shipped_camera_by_its_name(self):
        """The panel's camera list is every curve sensor_sim/cameras/ ships, named as its README names them, and
        the CIE observer; the sensor list is docs/sensor.md's presets."""
        folder = os.path.join(self.SOURCE, "sensor_sim", "cameras")
        shipped = sorted(f[:-4] for f in os.listdir(folder) if f.endswith(".csv"))
        self.assertEqual(sorted(k for k, _ in cameras.CURVES if k != "cie1931"), shipped)
        with open(os.path.join(folder, "README.md")) as f:
            readme = f.read()
        for key, name in cameras.CURVES:
            if key != "cie1931":
                self.assertIn(f"| `{key}.csv` | {name} |", readme)
        with open(os.path.join(self.SOURCE, "docs", "sensor.md")) as f:
            presets = re.findall(r"^\| `([a-z0-9_]+)` \| [0-9.]+ µm", f.read(), re.M)
        self.assertEqual(sorted(k for k, _, _ in cameras.SENSORS), sorted(presets))


class FindExecutable(unittest.TestCase):
    def test_a_preference_naming_no_executable_is_an_error_not_skipped(self):
        """The add-on preference, when set, is the executable; one naming no file (or a file that cannot run) says
        so, instead of silently running another chromatrace from the environment or PATH."""
        self.assertEqual(tool.find_executable(sys.executable), sys.executable)
        with tempfile.TemporaryDirectory() as d:
            missing = os.path.join(d, "chromatrace")
            with self.assertRaises(BadInput) as refused:
                tool.find_executable(missing)
            self.assertIn(f"'chromatrace executable' is {missing}, which is not a file", str(refused.exception))
            with open(missing, "w") as f:
                f.write("#!/bin/sh\n")
            with self.assertRaises(BadInput) as refused:
                tool.find_executable(missing)
            self.assertIn("not executable", str(refused.exception))


class Defaults(unittest.TestCase):
    def test_the_files_the_library_embeds(self):
        """The add-on's render defaults and illuminant names are core/data/defaults.json's, the C++ library's."""
        with open(os.path.join(os.path.dirname(__file__), "..", "..", "..", "core", "data", "defaults.json")) as f:
            shared = json.load(f)
        self.assertEqual(defaults.RENDER, shared["render"])
        self.assertEqual(spectra.ILLUMINANTS, shared["illuminants"] + ["D"])
        self.assertEqual(defaults.band_range(), (380.0, 780.0, 10.0))
        self.assertEqual(defaults.band_range("400:700:20"), (400.0, 700.0, 20.0))


class Components(unittest.TestCase):
    def test_parse_every_case_of_the_shared_table(self):
        """The --components grammar from the table the tracer's parser is tested against too."""
        with open(os.path.join(os.path.dirname(__file__), "..", "..", "data", "component_grammar.json")) as f:
            table = json.load(f)
        self.assertGreaterEqual(len(table["cases"]), 10)
        for case in table["cases"]:
            with self.subTest(input=case["input"]):
                if "error" in case:
                    with self.assertRaises(components.ComponentError) as raised:
                        components.parse_components(case["input"])
                    self.assertEqual(str(raised.exception), "--components: " + case["error"])
                else:
                    self.assertEqual(sorted(components.parse_components(case["input"])), case["families"])

    def test_variants_count_scattering_events_not_cycles_bounces(self):
        self.assertEqual(components.render_variants(3, False), {"main": 2})
        self.assertEqual(components.render_variants(3, True), {"k1": 0, "k2": 1, "main": 2})
        self.assertEqual(components.render_variants(0, True), {"main": 0})

    def test_bounce_terms_telescope_to_the_main_total(self):
        _total, planned = components.component_plan({"bounces"}, [], 3)
        by_name = {c["name"]: c["terms"] for c in planned}
        self.assertEqual(list(by_name), ["bounce.0", "bounce.1", "bounce.2", "bounce.3"])
        # Sum of all terms, as signed (file, pass) counts, must be main.Combined alone.
        count = {}
        for terms in by_name.values():
            for t in terms:
                key = (t.get("file", "main"), tuple(t["passes"]))
                count[key] = count.get(key, 0) + t.get("sign", 1)
        self.assertEqual({k: v for k, v in count.items() if v}, {("main", ("Combined",)): 1})

    def test_a_lit_world_seen_directly_is_emission(self):
        _total, planned = components.component_plan({"paths", "bounces"}, [], 2, environment=True)
        by_name = {c["name"]: c["terms"] for c in planned}
        self.assertEqual(by_name["emission"], [{"passes": ["Emit"]}, {"passes": ["Env"]}])
        self.assertEqual(by_name["bounce.0"], [{"passes": ["Emit"], "file": "k1"}, {"passes": ["Env"], "file": "k1"}])
        self.assertEqual(by_name["bounce.1"][1:], [{"passes": ["Emit"], "file": "k1", "sign": -1},
                                                   {"passes": ["Env"], "file": "k1", "sign": -1}])

    def test_paths_and_lights(self):
        _total, planned = components.component_plan({"paths", "lights"}, ["ceiling", "lamp_2"], 8)
        names = [c["name"] for c in planned]
        self.assertEqual(names, ["emission", "diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect",
                                 "light.ceiling", "light.lamp_2"])
        self.assertEqual(planned[1]["terms"], [{"passes": ["DiffDir", "DiffCol"]}])
        self.assertIn("Combined_lamp_2", components.passes_needed(planned))
        _total, with_glass = components.component_plan({"paths"}, [], 8, transmission=True)
        self.assertEqual(len(with_glass), 7)


class Manifest(unittest.TestCase):
    def test_every_band_filed_under_its_file_and_channel(self):
        groups = bands.band_groups(4)
        total, planned = components.component_plan({"paths"}, [], 2)
        m = manifest.build_manifest([400, 450, 500, 550, 600], groups, ["main"], "ViewLayer", total, planned,
                                    object_names={2: "b", 1: "a"}, attributes={"chromatrace.samples": "4"})
        self.assertEqual(m["format"], "chromatrace-assemble/1")
        self.assertEqual([b["channel"] for b in m["bands"]], ["R", "R", "G", "G"])  # renders [0, 2] and [1, 3]
        self.assertEqual(m["bands"][3]["files"], {"main": "g001_main.exr"})
        self.assertEqual(m["object_names"], {"1": "a", "2": "b"})
        self.assertEqual(m["object_ids"]["channel"], "ViewLayer.IndexOB.X")
        self.assertEqual(m["object_ids"]["file"], manifest.IDS_FILE)  # the centre-sampled id render
        replicated = manifest.build_manifest([400, 450, 500], bands.band_groups(2, 1), ["main"], "V", total, planned,
                                             replicate=True)
        self.assertEqual([b["channel"] for b in replicated["bands"]], ["R", "R"])
        self.assertNotIn("reconstruction", m)  # a step function unless the band plan carries a reconstruction
        fitted = {"lo_nm": 400, "step_nm": 100, "matrix": [[1, 0], [0, 1]]}
        self.assertEqual(manifest.build_manifest([400, 450, 500], bands.band_groups(2), ["main"], "V", total, planned,
                                                 reconstruction=fitted)["reconstruction"], fitted)

    def test_pass_names_are_those_the_running_blender_writes(self):
        # Blender 5.0 spells its passes out: the manifest names the channels as they are in the files.
        total, planned = components.component_plan({"paths"}, [], 2)
        names = {"DiffDir": "Diffuse Direct", "DiffCol": "Diffuse Color", "Emit": "Emission", "IndexOB": "Object Index"}
        m = manifest.build_manifest([400, 450, 500], bands.band_groups(2), ["main"], "VL", total, planned,
                                    object_names={1: "a"}, pass_names=names)
        wanted = manifest.channels_by_file(m)
        self.assertIn("VL.Diffuse Direct.R", wanted["g000_main.exr"])
        self.assertIn("VL.Emission.G", wanted["g000_main.exr"])
        self.assertNotIn("VL.DiffDir.R", wanted["g000_main.exr"])
        self.assertIn("VL.GlossDir.R", wanted["g000_main.exr"])  # a name left as it is
        self.assertEqual(wanted["ids.exr"], {"VL.Object Index.X"})
        self.assertEqual(planned[1]["terms"][0]["passes"], ["DiffDir", "DiffCol"])  # the plan itself is unchanged

    def test_channels_by_file_are_what_assemble_reads(self):
        total, planned = components.component_plan({"paths", "bounces"}, [], 2)
        variants = list(components.render_variants(2, True))
        m = manifest.build_manifest([400, 450, 500, 550, 600], bands.band_groups(4), variants, "VL", total, planned,
                                    object_names={1: "a"})
        wanted = manifest.channels_by_file(m)
        self.assertEqual(set(wanted), {"g000_main.exr", "g000_k1.exr", "g001_main.exr", "g001_k1.exr", "ids.exr"})
        self.assertEqual(wanted["ids.exr"], {"VL.IndexOB.X"})
        # The second render holds bands 1 and 3, in R and G; its K = 1 render gives bounce.0 (Emit) and bounce.1
        # (Combined).
        self.assertEqual(wanted["g001_k1.exr"], {"VL.Combined.R", "VL.Combined.G", "VL.Emit.R", "VL.Emit.G"})
        self.assertEqual({c[-1] for c in wanted["g000_main.exr"]}, {"R", "G"})
        for passes in ("Combined", "Emit", "DiffDir", "DiffInd", "DiffCol", "GlossDir", "GlossInd", "GlossCol"):
            self.assertIn(f"VL.{passes}.R", wanted["g001_main.exr"])

    def test_guided_groups_name_their_bands_for_the_assembly(self):
        total, planned = components.component_plan({"paths"}, [], 2)
        guided = bands.guided_bands(7, [1, 2])
        self.assertEqual(guided, [1, 2, 4, 5])  # the plan's groups of 7 bands: [0, 3, 6], [1, 4], [2, 5]
        self.assertEqual(bands.guided_bands(7, None), [])
        edges = [400 + 25 * i for i in range(8)]
        m = manifest.build_manifest(edges, bands.band_groups(7), ["main"], "V", total, planned, guided_bands=guided)
        self.assertEqual(m["guided"], {"bands": [1, 2, 4, 5]})
        self.assertNotIn("guided", manifest.build_manifest(edges, bands.band_groups(7), ["main"], "V", total, planned))

    def test_guided_groups_sample_adaptively_up_to_their_guides_when_the_plan_gives_a_threshold(self):
        groups = bands.band_groups(7)  # three renders: bands 0, 3, 6; 1, 4; 2, 5
        self.assertEqual(bands.guided_adaptive(groups, [300, 40, 30], [1, 2], 0.01), [None, (0.01, 300), (0.01, 300)])
        # The most samples of any guiding group, not of a guided one.
        self.assertEqual(bands.guided_adaptive(groups, [40, 300, 500], [0, 2], 0.02), [(0.02, 300), None, (0.02, 300)])
        for threshold, guided in ((None, [1, 2]), (0.01, None), (0.01, [])):
            self.assertEqual(bands.guided_adaptive(groups, [300, 40, 30], guided, threshold), [None] * 3)
        total, planned = components.component_plan({"paths"}, [], 2)
        edges = [400 + 25 * i for i in range(8)]
        m = manifest.build_manifest(edges, groups, ["main"], "V", total, planned, guided_bands=[1, 2, 4, 5],
                                    guided_adaptive=(0.01, 300))
        self.assertEqual(m["guided"], {"bands": [1, 2, 4, 5], "adaptive": {"threshold": 0.01, "max_samples": 300}})

    def test_missing_renders(self):
        with tempfile.TemporaryDirectory() as d:
            groups = bands.band_groups(6)
            open(os.path.join(d, manifest.render_file_name(0, "main")), "w").close()
            self.assertEqual(manifest.missing_renders(d, groups, ["main"]), [(1, "main")])


class JournalTest(unittest.TestCase):
    def test_restores_first_values_newest_first_even_after_a_failure(self):
        class Thing:
            pass
        a, b = Thing(), Thing()
        a.x, a.colour, b.y = 1, [0.1, 0.2], "keep"
        journal = Journal()
        removed = []
        journal.set(a, "x", 2)
        journal.set(a, "x", 3)
        journal.set(a, "colour", (1.0, 1.0))
        journal.call_on_restore(lambda: removed.append("group"))
        journal.call_on_restore(lambda: 1 / 0)  # a failing undo must not stop the others
        journal.set(b, "y", "changed")
        with self.assertRaises(ZeroDivisionError):
            journal.restore()
        self.assertEqual((a.x, tuple(a.colour), b.y, removed), (1, (0.1, 0.2), "keep", ["group"]))
        journal.restore()  # nothing left: harmless
        self.assertEqual(len(journal), 0)


class BatchArgs(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.scene = os.path.join(self.dir.name, "s.json")
        open(self.scene, "w").close()
        self.out = os.path.join(self.dir.name, "out.exr")

    def tearDown(self):
        self.dir.cleanup()

    def test_good(self):
        a = batch_args.parse_batch_args(["--scene", self.scene, "--out", self.out, "--samples", "4", "--resolution",
                                         "64x32", "--components", "paths,bounces", "--max-bounces", "0"])
        self.assertEqual((a.samples, a.resolution, a.components, a.max_bounces), (4, (64, 32), {"paths", "bounces"}, 0))

    def test_band_group_is_one_group_or_none(self):
        self.assertIsNone(batch_args.parse_batch_args(["--scene", self.scene, "--out", self.out]).band_group)
        self.assertEqual(batch_args.parse_batch_args(["--scene", self.scene, "--out", self.out, "--band-group", "2"])
                         .band_group, 2)

    def test_explain_needs_no_output_and_writes_to_stdout_or_a_file(self):
        a = batch_args.parse_batch_args(["--scene", self.scene, "--explain"])
        self.assertEqual((a.explain, a.out), ("-", None))
        a = batch_args.parse_batch_args(["--scene", self.scene, "--preflight", self.out, "--on-world", "omit"])
        self.assertEqual((a.explain, a.on_world), (self.out, "omit"))
        with self.assertRaises(BadInput) as caught:
            batch_args.parse_batch_args(["--scene", self.scene, "--explain", "/no/such/dir/p.json"])
        self.assertIn("--explain", str(caught.exception))

    def test_bad_input_is_one_line_naming_the_option(self):
        cases = [
            (["--out", self.out], "--scene"),
            (["--scene", self.scene], "--out"),
            (["--scene", self.scene + "x", "--out", self.out], "--scene"),
            (["--scene", self.scene, "--blend", self.scene, "--out", self.out], "--blend"),
            (["--scene", self.scene, "--out", "/no/such/dir/o.exr"], "--out"),
            (["--scene", self.scene, "--out", self.out, "--samples", "0"], "--samples"),
            (["--scene", self.scene, "--out", self.out, "--samples", "many"], "--samples"),
            (["--scene", self.scene, "--out", self.out, "--max-bounces", "-1"], "--max-bounces"),
            (["--scene", self.scene, "--out", self.out, "--resolution", "64"], "--resolution"),
            (["--scene", self.scene, "--out", self.out, "--components", "all,glow"], "--components"),
            (["--scene", self.scene, "--out", self.out, "--bands", "1:2:1", "--bands-file", self.scene], "--bands-file"),
            (["--scene", self.scene, "--out", self.out, "--bands-per-render", "4"], "--bands-per-render"),
            (["--scene", self.scene, "--out", self.out, "--frobnicate"], "--frobnicate"),
            (["--scene", self.scene, "--out", self.out, "--band-group", "-1"], "--band-group"),
            (["--scene", self.scene, "--out", self.out, "--band-group", "x"], "--band-group"),
            (["--scene", self.scene, "--explain", "--band-group", "0"], "--band-group"),
            (["--scene", self.scene, "--out", self.out, "--bounce-limit", "k1"], "--bounce-limit"),
            (["--scene", self.scene, "--out", self.out, "--plan", "-1"], "--plan"),
            (["--scene", self.scene, "--out", self.out, "--plan", "1", "--samples", "8"], "--samples"),
            (["--scene", self.scene, "--out", self.out, "--plan", "1", "--bands-file", self.scene], "--bands-file"),
            (["--scene", self.scene, "--out", self.out, "--plan", "1", "--max-bounces", "3"], "--max-bounces"),
            (["--scene", self.scene, "--out", self.out, "--plan", "1", "--band-group", "0"], "--band-group"),
            (["--scene", self.scene, "--plan", "1", "--explain"], "--explain"),
            (["--scene", self.scene, "--out", self.out, "--plan-edge-step", "5"], "--plan-edge-step"),
            (["--scene", self.scene, "--out", self.out, "--plan-out", self.out + ".json"], "--plan-out"),
            (["--scene", self.scene, "--out", self.out, "--plan-reference-spp", "4096"], "--plan-reference-spp"),
            (["--scene", self.scene, "--out", self.out, "--plan", "1", "--plan-reference-spp", "0"], "--plan-reference-spp"),
        ]
        for argv, option in cases:
            with self.assertRaises(BadInput, msg=argv) as caught:
                batch_args.parse_batch_args(argv)
            self.assertIn(option, str(caught.exception))
            self.assertNotIn("\n", str(caught.exception))


class Planning(unittest.TestCase):
    def test_pilots_keep_the_renders_aspect_at_32_pixels_on_the_longer_side(self):
        self.assertEqual(planning.pilot_resolution(1920, 1080), [32, 18])
        self.assertEqual(planning.pilot_resolution(1080, 1920), [18, 32])
        self.assertEqual(planning.pilot_resolution(64, 64), [32, 32])
        self.assertEqual(planning.pilot_resolution(4000, 10), [32, 1])

    def test_the_plan_said_and_kept_in_the_header(self):
        report = {"target_de00": 1.0, "camera": "cie1931",
                  "settings": {"band_count": 6, "max_bounces": 5, "cycles_samples": [212, 186]},
                  "prediction": {"mean_de00": 0.31,
                                 "cycles": {"mean_de00": 0.998, "mean_de00_range": [0.79, 1.28],
                                            "noise_only_mean_de00": 0.95,
                                            "noise_ratio_to_tracer": 0.746, "tracer_noise_at_one_sample": 18.1}}}
        planned = planning.Planned("plan.json", report)
        self.assertEqual(planned.summary(), "plan for a mean ΔE00 of 1: 6 bands, max 5 bounces, samples per band "
                                            "group 212, 186; predicted mean ΔE00 1.00 (0.79-1.28), Cycles' noise "
                                            "0.75 × the tracer's on the pilots")
        self.assertEqual(planned.notes, [])
        self.assertEqual(planning.Planned("plan.json", dict(report, notes=["materials.floor is an image texture"])).notes,
                         ["materials.floor is an image texture"])
        header = json.loads(planned.header())
        self.assertEqual(header["cycles_samples"], [212, 186])
        self.assertEqual(header["predicted_range"], [0.79, 1.28])
        self.assertEqual(header["tracer_noise_at_one_sample"], 18.1)
        self.assertEqual((header["predicted_noise_mean_de00"], header["predicted_bands_mean_de00"]), (0.95, 0.31))
        self.assertIsNone(header["worst_object"])
        self.assertIsNone(header["guide_band_group"])  # the report names none: no pilots measured the groups
        report["prediction"]["cycles"]["guide_band_group"] = 1
        self.assertEqual(json.loads(planning.Planned("plan.json", report).header())["guide_band_group"], 1)
        # Planned for the target as compare measures it against a tracer reference: said beside the render's own.
        against = {"samples": 4096, "the_target": True, "mean_de00": 0.997, "mean_de00_range": [0.85, 1.31]}
        report["prediction"]["cycles"]["against_tracer_reference"] = against
        self.assertIn("predicted mean ΔE00 1.00 (0.79-1.28) (1.00 (0.85-1.31) against a tracer reference of 4096 paths, "
                      "the target), Cycles' noise", planning.Planned("plan.json", report).summary())
        against["the_target"] = False  # only predicted (plan --reference-spp alone): not said
        self.assertNotIn("reference", planning.Planned("plan.json", report).summary())

    def test_the_worst_object_said_with_the_samples_it_took(self):
        objects = [{"name": "floor", "object_id": 1, "mean_de00": 0.8}, {"name": "ceiling", "object_id": 2, "mean_de00": 1.96}]
        cycles = {"mean_de00": 0.81, "mean_de00_range": [0.6, 1.1], "noise_only_mean_de00": 0.7, "noise_ratio_to_tracer": 0.8,
                  "tracer_noise_at_one_sample": 18.1, "objects": objects, "object_limit_mean_de00": 2.0}
        report = {"target_de00": 1.0, "camera": "cie1931",
                  "settings": {"band_count": 6, "max_bounces": 5, "cycles_samples": [262, 236]},
                  "prediction": {"mean_de00": 0.3, "cycles": dict(cycles, samples_raised_for_objects=1.24)}}
        planned = planning.Planned("plan.json", report)
        self.assertTrue(planned.summary().endswith("; worst object ceiling 1.96 (objects held to 2, samples × 1.24 for "
                                                   "it)"), planned.summary())
        self.assertEqual(json.loads(planned.header())["worst_object"]["name"], "ceiling")
        report["prediction"]["cycles"] = dict(cycles, samples_raised_for_objects=1.0)
        self.assertTrue(planning.Planned("plan.json", report).summary().endswith("(objects held to 2)"))

    def test_the_light_tree_is_left_off_where_its_pilots_need_fewer_samples_without_it(self):
        """plan_render with a scene that uses Cycles' light tree: pilots with it and without it, and the plan of
        fewer samples in all taken (the scene's own where they tie), its band file and summary saying so."""
        class Tool:  # chromatrace plan: samples from the pilots' light tree, as `samples` gives them
            def __init__(self, samples):
                self.samples, self.calls = samples, 0

            def plan(self, scene_file, target, out, report_file, pilots=None, edge_step=None, reference_spp=None):
                self.calls += 1
                self.reference_spp = reference_spp
                light_tree = None
                if pilots:
                    with open(pilots[0]) as f:
                        light_tree = json.load(f).get("cycles_light_tree")
                samples = self.samples[light_tree] if pilots else None
                with open(out, "w") as f:
                    json.dump({"format": "chromatrace-bands/1", "edges_nm": [400, 500, 600, 700],
                               **({"cycles_samples": samples} if samples else {})}, f)
                cycles = {"mean_de00": 0.99, "mean_de00_range": [0.8, 1.3], "noise_only_mean_de00": 0.9,
                          "noise_ratio_to_tracer": 0.5, "tracer_noise_at_one_sample": 20.0}
                with open(report_file, "w") as f:
                    json.dump({"target_met": True, "notes": [], "target_de00": target, "camera": "cie1931",
                               "settings": {"band_count": 3, "max_bounces": 3, "cycles_samples": samples},
                               "prediction": {"mean_de00": 0.4, **({"cycles": cycles} if pilots else {})}}, f)

        def render_pilot(bands_file, seed, output):  # the pilot "renders" the bands file it was given
            rendered.append((bands_file, seed))
            with open(bands_file) as f, open(output, "w") as out:
                out.write(f.read())

        for samples, light_tree, chosen in (({None: [300], False: [150]}, True, False),
                                            ({None: [150], False: [300]}, True, None),
                                            ({None: [200], False: [200]}, True, None),
                                            ({None: [300], False: [150]}, False, None)):
            with tempfile.TemporaryDirectory() as work:
                rendered, tool = [], Tool(samples)
                planned = planning.plan_render("scene.json", 1.0, work, render_pilot, tool, light_tree=light_tree,
                                               reference_spp=4096)
                self.assertEqual(tool.reference_spp, 4096)  # every plan is for the target against that reference
                self.assertEqual(len(rendered), 4 if light_tree else 2)
                self.assertEqual(tool.calls, 3 if light_tree else 2)
                self.assertEqual(planned.light_tree, chosen)
                self.assertEqual(planned.samples, samples[chosen])
                with open(planned.bands_file) as f:
                    document = json.load(f)
                self.assertEqual(document.get("cycles_light_tree", "absent"), "absent" if chosen is None else chosen)
                self.assertEqual(json.loads(planned.header())["cycles_light_tree"], chosen)
                if chosen is False:
                    self.assertTrue(planned.summary().endswith("; Cycles' light tree off: 150 samples in all (300 with "
                                                               "it as the scene has it)"), planned.summary())
                else:
                    self.assertNotIn("light tree", planned.summary())
                self.assertTrue(os.path.isfile(planned.report_file))


class Ply(unittest.TestCase):
    def test_round_trip_binary_and_ascii(self):
        mesh = ply.Mesh([(0, 0, 0), (1, 0, 0), (1, 1, 0.5), (0, 1, 0)], [(0, 0, 1)] * 4, [(0, 1, 2), (0, 2, 3)])
        back = ply.parse_ply(ply.format_ply(mesh))
        self.assertEqual((back.positions, back.normals, back.triangles),
                         ([tuple(map(float, p)) for p in mesh.positions], [(0.0, 0.0, 1.0)] * 4, mesh.triangles))
        text = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
               b"element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"
        quad = ply.parse_ply(text)
        self.assertEqual(quad.triangles, [(0, 1, 2), (0, 2, 3)])  # a fan from the first vertex, as core splits
        self.assertEqual(quad.normals, [])
        self.assertEqual(quad.uvs, [])

    def test_texture_coordinates_round_trip_and_alternative_names(self):
        uvs = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.25)]
        mesh = ply.Mesh([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2), (0, 2, 3)], uvs)
        back = ply.parse_ply(ply.format_ply(mesh))
        self.assertEqual((back.normals, back.uvs), ([], uvs))
        smooth = ply.Mesh(mesh.positions, [(0, 0, 1)] * 4, mesh.triangles, uvs)
        self.assertEqual(ply.parse_ply(ply.format_ply(smooth)).uvs, uvs)
        header = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        faces = b"element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        text = header + b"property float s\nproperty float t\n" + faces + b"0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n"
        self.assertEqual(ply.parse_ply(text).uvs, [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)])
        with self.assertRaises(ply.PlyError):
            ply.parse_ply(header + b"property float u\n" + faces + b"0 0 0 0\n1 0 0 1\n0 1 0 0\n3 0 1 2\n")


class NodeRules(unittest.TestCase):
    def test_shader_rules_allow_the_fallback_and_volumes_do_not(self):
        nodes = [
            {"name": "Principled BSDF", "type": "ShaderNodeBsdfPrincipled", "props": {"distribution": "GGX"},
             "inputs": {"Specular": 0.5, "Specular Tint": 0.5, "Sheen": 0.0, "Sheen Tint": 0.5, "Subsurface": 0.0}},
            {"name": "Glossy", "type": "ShaderNodeBsdfGlossy", "props": {"distribution": "MULTI_GGX"}},
            {"name": "SSS", "type": "ShaderNodeSubsurfaceScattering"},
            {"name": "Diffuse", "type": "ShaderNodeBsdfDiffuse"},
        ]
        issues = node_rules.tree_issues("wall", nodes, volume_linked=True)
        found = {(i["node"], i["fallback"]) for i in issues}
        self.assertEqual(found, {("Material Output", False), ("Principled BSDF", True), ("Glossy", True),
                                 ("SSS", True)})
        self.assertIn('material "wall", node "Principled BSDF"', node_rules.summarise(issues[1:]))
        tinted_white = {"name": "P", "type": "ShaderNodeBsdfPrincipled", "inputs": {"Specular Tint": (1, 1, 1, 1)}}
        self.assertEqual(node_rules.node_issues(tinted_white), [])
        no_sheen = {"name": "P", "type": "ShaderNodeBsdfPrincipled", "inputs": {"Sheen": 0.0, "Sheen Tint": 0.5}}
        self.assertEqual(node_rules.node_issues(no_sheen), [])  # Blender 3's default: a tint without a lobe

    def test_multiscatter_and_tints_as_each_cycles_has_them(self):
        # Cycles 4.0+ scales each channel by its own Fresnel's albedo: Multiscatter GGX multiplexes exactly, so the
        # default Principled BSDF of 4.x renders as it is; up to 3.x the channels share one random walk.
        v2 = {"name": "P", "type": "ShaderNodeBsdfPrincipled",
              "props": {"distribution": "MULTI_GGX", "multiscatter": "albedo-scaling"},
              "inputs": {"Specular IOR Level": 0.5, "Specular Tint": (1, 1, 1, 1), "Sheen Weight": 0.0,
                         "Sheen Tint": (1, 1, 1, 1), "Subsurface Weight": 0.0}}
        self.assertEqual(node_rules.node_issues(v2), [])
        walk = dict(v2, props={"distribution": "MULTI_GGX", "multiscatter": "random-walk"})
        self.assertEqual(node_rules.node_issues(walk), [("Multiscatter GGX couples the colour channels", True)])
        # A coloured v2 tint: Cycles weighs the layers below by its strongest channel; one band per render helps.
        tinted = dict(v2, inputs=dict(v2["inputs"], **{"Specular Tint": (1.0, 0.8, 0.6, 1.0)}))
        (reason, fallback), = node_rules.node_issues(tinted)
        self.assertIn("strongest channel", reason)
        self.assertTrue(fallback)
        sheen_off = dict(v2, inputs=dict(v2["inputs"], **{"Sheen Tint": (0.2, 0.4, 0.9, 1.0)}))
        self.assertEqual(node_rules.node_issues(sheen_off), [])  # no sheen weight, no sheen lobe

    def test_colour_paths_convert_pass_on_or_refuse_and_unknown_nodes_refuse(self):
        def kind(t, **props):
            rule = node_rules.colour_node({"name": "n", "type": t, "props": props})
            return rule["kind"], rule["issue"][1] if rule["issue"] else None
        self.assertEqual(kind("ShaderNodeRGB"), ("constant", None))
        self.assertEqual(kind("ShaderNodeBlackbody"), ("blackbody", None))
        self.assertEqual(kind("ShaderNodeMix", data_type="RGBA", blend_type="MULTIPLY"), ("pass", None))
        self.assertEqual(kind("ShaderNodeMixRGB", blend_type="HUE"), ("pass", True))  # the one-band fallback
        self.assertEqual(kind("ShaderNodeHueSaturation"), ("pass", True))
        self.assertEqual(kind("ShaderNodeGamma"), ("pass", None))
        self.assertEqual(kind("ShaderNodeTexImage"), ("image", None))  # every texel upsampled
        self.assertEqual(kind("ShaderNodeTexEnvironment"), ("image", None))
        for refused in ("ShaderNodeTexNoise", "ShaderNodeTexSky", "ShaderNodeValToRGB",
                        "ShaderNodeVertexColor", "ShaderNodeAttribute", "ShaderNodeWavelength",
                        "ShaderNodeCombineColor", "ShaderNodeSomethingNew"):
            self.assertEqual(kind(refused), ("refused", False), refused)
        self.assertEqual(node_rules.colour_node({"type": "ShaderNodeMixRGB", "props": {}})["inputs"],
                         ("Color1", "Color2"))

    def test_issue_lines_name_the_owner_node_and_socket(self):
        issue = {"kind": "light", "material": "Area", "node": "Group > Image", "socket": '"Emission"/"Color"',
                 "reason": "an RGB texture's colours are not spectra", "fallback": False}
        self.assertEqual(node_rules.describe_issue(issue), 'light "Area", node "Group > Image" (into "Emission"/"Color"): '
                         "an RGB texture's colours are not spectra")


class Spectra(unittest.TestCase):
    def test_sources_round_trip(self):
        scene_dir = "/data/scenes/paper"
        for source in ["lamp", {"constant": 0.5}, {"csv": "../spectra/a.csv", "column": "red"},
                       {"csv": "../spectra/a.csv", "column": "red", "extend": "clamp"}, {"rgb": [0.5, 0.2, 0.1]},
                       {"illuminant": "D65"}, {"illuminant": "D", "cct_k": 5000}, {"blackbody_k": 3200},
                       {"samples": [[400, 0.1], [700, 0.9]], "extend": "clamp"}, {"texture": "textures/wood.png"},
                       {"texture": "../hdri/sky.exr", "colour_space": "linear", "scale": 2.5}]:
            kind, values = spectra.source_values(source, scene_dir)
            full = {"name": "", "library": "", "constant": 0, "csv_path": "", "csv_column": "", "extend": "zero",
                    "rgb": (0, 0, 0), "use_current_colour": False, "illuminant": "D65", "cct_k": 6504,
                    "blackbody_k": 0, "samples": [], "texture_path": "", "texture_colour_space": "auto",
                    "texture_scale": 1.0}
            full.update(values)
            self.assertEqual(spectra.source_json(kind, full, base_dir=scene_dir), source)

    def test_current_colour_and_emission_normalisation(self):
        values = {"rgb": (0.1, 0.1, 0.1), "use_current_colour": True}
        self.assertEqual(spectra.source_json("RGB", values, current_rgb=(0.5, 0.25, 0.0)), {"rgb": [0.5, 0.25, 0.0]})
        self.assertEqual(spectra.rgb_for_upsampling((4.0, 2.0, 1.0)), ([1.0, 0.5, 0.25], 4.0))

    def test_library_lists_the_projects_spectra(self):
        entries = spectra.library_entries()
        self.assertIn("cornell_box.csv:red", entries)
        self.assertIn("synthetic_reflectances.csv:yellow", entries)


class Floats(unittest.TestCase):
    def test_single_precision_values_come_back_as_typed(self):
        import struct
        as32 = lambda x: struct.unpack("<f", struct.pack("<f", x))[0]  # noqa: E731
        for typed in (0.1, 0.78, 0.08, 0.35, 6504, 1e-30, 2.5e-5):
            self.assertEqual(floats.short_float(as32(typed)), typed)
        self.assertIsInstance(floats.short_float(as32(380.0)), int)
        self.assertEqual(floats.short_float(1e300), 1e300)


class Cache(unittest.TestCase):
    def test_key_depends_on_content_only(self):
        self.assertEqual(cache.cache_key({"a": 1, "b": [1, 2]}), cache.cache_key({"b": [1, 2], "a": 1}))
        self.assertNotEqual(cache.cache_key({"a": 1}), cache.cache_key({"a": 2}))


    def test_a_render_enters_the_cache_only_when_it_reads_back(self):
        with tempfile.TemporaryDirectory() as d:
            partial, final = os.path.join(d, "g000_main.exr.partial"), os.path.join(d, "g000_main.exr")
            with open(final, "w") as f:
                f.write("the previous render")
            with open(partial, "w") as f:
                f.write("cut short")
            with self.assertRaisesRegex(RuntimeError, "g000_main.exr completely .*: ends early"):
                cache.commit(partial, final, lambda path: "ends early")
            self.assertEqual(os.listdir(d), ["g000_main.exr"])
            with open(final) as f:
                self.assertEqual(f.read(), "the previous render")
            with open(partial, "w") as f:
                f.write("whole")
            cache.commit(partial, final, lambda path: None)
            self.assertEqual(os.listdir(d), ["g000_main.exr"])
            with open(final) as f:
                self.assertEqual(f.read(), "whole")

    def test_json_written_whole_or_not_at_all(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "manifest.json")
            cache.write_json(path, {"a": [1, 2]})
            with open(path) as f:
                self.assertEqual(json.load(f), {"a": [1, 2]})
            with self.assertRaises(TypeError):  # fails part-way through the dump
                cache.write_json(path, {"a": [1, 2], "b": object()})
            self.assertEqual(os.listdir(d), ["manifest.json"])
            with open(path) as f:
                self.assertEqual(json.load(f), {"a": [1, 2]})


class CameraMath(unittest.TestCase):
    def test_basis_looks_down_minus_z(self):
        rows = camera_math.camera_basis([0, -3.5, 1], [0, 0, 1], [0, 0, 1])
        columns = [[rows[i][j] for i in range(3)] for j in range(3)]
        self.assertEqual([round(c, 12) for c in columns[0]], [1, 0, 0])   # right
        self.assertEqual([round(c, 12) for c in columns[1]], [0, 0, 1])   # image up
        self.assertEqual([round(c, 12) for c in columns[2]], [0, -1, 0])  # back


    def test_camera_description_of_a_50mm_lens_on_a_full_frame_sensor(self):
        # 36 mm across and 50 mm focal length: 2·atan(18/50) = 39.598° across, 2·atan(18/50 · 1080/1920) = 22.895°
        # up (the familiar "normal lens" angles); Blender's identity camera looks down -Z with +Y up.
        identity = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
        data = SimpleNamespace(sensor_fit="AUTO", sensor_width=36.0, sensor_height=24.0, lens=50.0)
        scene = SimpleNamespace(camera=SimpleNamespace(data=data, matrix_world=identity))
        d = camera_math.camera_description(scene, [1920, 1080])
        self.assertEqual(d["position"], [0, 0, 0])
        self.assertEqual(d["look_at"], [0, 0, -1])
        self.assertEqual(d["up"], [0, 1, 0])
        self.assertAlmostEqual(d["horizontal_fov_deg"], 39.5978, places=4)
        self.assertAlmostEqual(d["vertical_fov_deg"], 22.8952, places=4)
        self.assertEqual(d["sensor_width_mm"], 36.0)


class SceneParts(unittest.TestCase):
    @staticmethod
    def thing(name, kind="MESH", pass_index=0, materials=(), lightgroup=""):
        slots = [SimpleNamespace(material=m) for m in materials]
        return SimpleNamespace(name=name, type=kind, pass_index=pass_index, material_slots=slots, lightgroup=lightgroup)

    def test_used_materials_each_once_in_slot_order(self):
        a, b = SimpleNamespace(name="a"), SimpleNamespace(name="b")
        objects = [self.thing("x", materials=(b, None, a)), self.thing("y", materials=(a, b))]
        self.assertEqual(scene_parts.used_materials(objects), [b, a])

    def test_object_ids_are_distinct_pass_indices_or_else_numbered_by_name(self):
        lamp = self.thing("lamp", kind="LIGHT", pass_index=9)
        objects = [self.thing("wall", pass_index=5), self.thing("box", pass_index=2), lamp]
        self.assertEqual(scene_parts.object_ids(objects, True), {"wall": 5, "box": 2})
        objects = [self.thing("wall", pass_index=1), self.thing("box", pass_index=1), lamp]
        self.assertEqual(scene_parts.object_ids(objects, True), {"box": 1, "wall": 2})
        self.assertEqual(scene_parts.object_ids(objects, False), {})

    def test_light_groups_put_every_emitter_in_one_and_a_lit_world_last(self):
        glow = SimpleNamespace(name="glow")
        objects = [self.thing("lamp", kind="LIGHT"), self.thing("panel.1", materials=(glow,)),
                   self.thing("wall", materials=(SimpleNamespace(name="paint"),)),
                   self.thing("bulb", kind="LIGHT", lightgroup="panel_1")]
        scene = SimpleNamespace(world=SimpleNamespace(lightgroup=""))
        view_layer = SimpleNamespace(lightgroups={})
        groups, assignments, world = scene_parts.light_groups(scene, {"lights"}, view_layer, objects, {"glow"},
                                                              {"status": "lit"})
        # An unnamed world's group is the scene format's default, as Export writes it.
        self.assertEqual(groups, ["lamp", "panel_1", "environment"])
        self.assertEqual(assignments, {"lamp": "lamp", "panel.1": "panel_1", "bulb": "panel_1"})
        self.assertEqual(world, "environment")
        self.assertEqual(scene_parts.light_groups(scene, {"paths"}, view_layer, objects, {"glow"}, {"status": "lit"}),
                         ([], {}, None))


class WorldMap(unittest.TestCase):
    def test_an_environment_image_gets_a_map_of_its_width_within_cycles_bounds_where_cycles_would_choose(self):
        self.assertEqual(cycles_setup.world_map_resolution("AUTOMATIC", [64]), 1024)  # no coarser than 1024
        self.assertEqual(cycles_setup.world_map_resolution("AUTOMATIC", [2048, 512]), 2048)  # the widest image
        self.assertEqual(cycles_setup.world_map_resolution("AUTOMATIC", [16384]), 4096)  # Cycles' own at most
        # The artist's own choice, or a world without an image (0: an image without pixels), is left alone.
        for method in ("MANUAL", "NONE"):
            self.assertIsNone(cycles_setup.world_map_resolution(method, [64]))
        self.assertIsNone(cycles_setup.world_map_resolution("AUTOMATIC", []))
        self.assertIsNone(cycles_setup.world_map_resolution("AUTOMATIC", [0]))


if __name__ == "__main__":
    unittest.main()
