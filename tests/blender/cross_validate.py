# SPDX-License-Identifier: Apache-2.0
"""Cycles (through the add-on, real Blender) held to the reference tracer with `chromatrace compare`.

    python3 cross_validate.py agree SCENE.json        # every object × band × component must agree
    python3 cross_validate.py agree-point SCENE.json  # the same with the scene's pixels point samples
    python3 cross_validate.py filter-glossy SCENE.json  # Cycles' default Filter Glossy and Clamp Indirect left on: must fail
    python3 cross_validate.py reflectance SCENE.json OBJECT  # OBJECT's reflectance changed for Cycles: must fail there
    python3 cross_validate.py turned SCENE.json  # the environment turned 90° more for Cycles: must fail
    python3 cross_validate.py agree-blend MODE  # make_artist_scene.py MODE's .blend rendered by Cycles, and the
                                                # scene file it exports rendered by the tracer: must agree

Environment: CHROMATRACE_EXE, BLENDER (the executable), BLENDER_VERSION (its version: the scene's GGX masking is
Cycles' in that version, tests/blender/scene_for_blender.py), and optionally CROSS_SIZE (32x32), CROSS_BANDS
(400:760:60), CROSS_SPP (tracer and Cycles samples per pixel), CROSS_KEEP (a folder to keep the files in).
Exit 0 when the assertion holds, 1 otherwise, with the compare verdict on stderr.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

from scene_for_blender import scene_for_blender

EXE = os.environ["CHROMATRACE_EXE"]
BLENDER = os.environ.get("BLENDER", "blender")
BLENDER_VERSION = os.environ.get("BLENDER_VERSION", "3.4")
SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SIZE = os.environ.get("CROSS_SIZE", "32x32")
BANDS = os.environ.get("CROSS_BANDS", "400:760:60")
SPP = os.environ.get("CROSS_SPP", "2048")


def run(args, env=None):
    start = time.monotonic()
    result = subprocess.run(args, capture_output=True, text=True, env=env)
    if result.returncode != 0:
        sys.exit(f"failed ({result.returncode}): {' '.join(args)}\n{result.stderr}")
    return result, time.monotonic() - start


def render_tracer(scene, out, seed=1):
    _, seconds = run([EXE, "render", scene, "-o", out, "--spp", SPP, "--resolution", SIZE, "--bands", BANDS,
                      "--seed", str(seed), "--components", "paths,lights", "-q"])
    return seconds


def render_cycles(scene, out, work, env_extra=None):
    env = dict(os.environ, CHROMATRACE_EXE=EXE)
    env.update(env_extra or {})
    source = "--blend" if scene.endswith(".blend") else "--scene"
    _, seconds = run([BLENDER, "--background", "--factory-startup", "--python",
                      os.path.join(SOURCE, "blender_addon", "batch.py"), "--", source, scene, "--out", out,
                      "--samples", SPP, "--resolution", SIZE, "--bands", BANDS, "--components", "paths,lights",
                      "--seed", "7", "--cache-dir", os.path.join(work, "cache"), "-q"], env)
    return seconds


def compare(a, b, out, pixels="interior"):
    # Interior pixels give each object's standard error from its smooth inside; "matched" adds the edge
    # pixels, which mean the same in both since both renderers take a pixel's id at its centre
    # (docs/blender.md).
    result, _ = run([EXE, "compare", a, b, "-o", out, "--pixels", pixels])
    sys.stderr.write(result.stderr)
    with open(os.path.join(out, "compare.json")) as f:
        return json.load(f)


def scene_copy(scene, work, change=None, name="changed.json"):
    """A copy of the scene file as this Blender's Cycles renders it (scene_for_blender.py) with change(document)
    applied, its relative paths kept valid."""
    return scene_for_blender(scene, BLENDER_VERSION, os.path.join(work, name), change)


def scene_groups(scene):
    with open(scene) as f:
        document = json.load(f)
    groups = {light["group"] for light in document["lights"]}
    if "environment" in document:
        groups.add(document["environment"].get("group", "environment"))
    return sorted(groups)


def check(condition, message):
    if not condition:
        sys.exit("FAIL: " + message)


def blend_and_export(mode, work):
    """make_artist_scene.py's MODE as a .blend, and the scene file Export writes of it (what it holds only
    approximately printed)."""
    blend, scene = os.path.join(work, f"{mode}.blend"), os.path.join(work, "exported.json")
    here = os.path.dirname(os.path.abspath(__file__))
    run([BLENDER, "--background", "--factory-startup", "--python", os.path.join(here, "make_artist_scene.py"), "--",
         mode, blend])
    result, _ = run([BLENDER, blend, "--background", "--factory-startup", "--python-exit-code", "1", "--python",
                     os.path.join(here, "export_blend.py"), "--", scene],
                    dict(os.environ, CHROMATRACE_EXE=EXE, CHROMATRACE_SOURCE_DIR=SOURCE))
    approximations = [line for line in result.stdout.splitlines() if line.startswith("approximately:")]
    sys.stderr.write("".join(line + "\n" for line in approximations))
    return blend, scene, approximations


def main():
    case, scene = sys.argv[1], sys.argv[2]
    work = tempfile.mkdtemp(prefix="cross_validate_")
    try:
        tracer, cycles = os.path.join(work, "tracer.exr"), os.path.join(work, "cycles.exr")
        blend = None
        if case == "agree-blend":  # Cycles renders the .blend, the tracer the scene file exported from it
            blend, scene, approximations = blend_and_export(scene, work)
            # What the file holds only approximately (a point light's Soft Falloff, said) must not be a material.
            check(not any("material" in line for line in approximations), f"the export approximated: {approximations}")
            case = "agree"
        else:
            scene = scene_copy(os.path.abspath(scene), work, name="scene.json")  # both renderers render this one
        point = case == "agree-point"
        if point:  # point pixels: Cycles' narrow Gaussian against the tracer's pixel centres
            scene = scene_copy(scene, work, lambda d: d.setdefault("render", {}).update(pixel_filter="point"))
            case = "agree"
        t_seconds = render_tracer(scene, tracer)
        if case == "agree":
            c_seconds = render_cycles(blend or scene, cycles, work)
            doc = compare(cycles, tracer, os.path.join(work, "compare"))
            # Every component family the issue names is compared.
            expected = {"total", "emission", "diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect"}
            expected |= {f"light.{g}" for g in scene_groups(scene)}
            check(expected <= set(doc["components"]), f"components compared {doc['components']}, expected {sorted(expected)}")
            # The test has power: on every object of at least 60 interior pixels, the standard error of the
            # total's difference in the brightest band is below the object's tolerance (1 % or 2 %), so a
            # bias of a few per cent would be caught.
            power = 0.0  # the largest standard error of an object's total as a share of its tolerance
            for o in doc["objects"]:
                if o["object_id"] < 0 or o["pixels"] < 60:
                    continue
                cells = [c for c in doc["cells"] if c["object_id"] == o["object_id"] and c["component"] == "total"]
                best = max(cells, key=lambda c: c["mean_b"])
                se = best["se"] / best["mean_b"]
                check(se < o["tolerance"], f"{o['object']}: relative standard error {se:.4f} of the total is too large to test")
                power = max(power, se / o["tolerance"])
            failed = [c for c in doc["cells"] if not c["pass"]]
            check(not failed, f"{len(failed)} cells disagree, e.g. {failed[:3]}")
            # And with the edge pixels: an object's pixels are the same set in both files, so its means agree.
            matched = compare(cycles, tracer, os.path.join(work, "compare-matched"), "matched")
            failed = [c for c in matched["cells"] if not c["pass"]]
            check(not failed, f"with the edge pixels, {len(failed)} cells disagree, e.g. {failed[:3]}")
            if point:
                # A point sample sees an emitter only where the pixel's centre lies on it, so no other object's
                # pixels hold emission: none in the tracer's (exact centres); in Cycles', whose point is a
                # Gaussian 0.01 pixel wide, at most that width's share of an emitter along its edge, under 1 %
                # of the emitter's radiance over an object larger than the edge. A pixel-wide filter gives the
                # pixels around a lamp a share of it several times that.
                emitter = {}
                for c in matched["cells"]:
                    if c["component"] == "emission" and c["brdf"] == "emitter":
                        emitter[c["band"]] = max(emitter.get(c["band"], 0.0), c["mean_b"])
                lit = [(c["object"], c["band"], c["mean_a"], c["mean_b"]) for c in matched["cells"]
                       if c["component"] == "emission" and c["brdf"] not in ("emitter", "image")
                       and (c["mean_b"] != 0 or c["mean_a"] > 0.01 * emitter.get(c["band"], 0.0))]
                check(not lit, f"emission on pixels of objects that emit none (object, band, Cycles, tracer): {lit[:4]}")
            print(f"agree: {len(doc['cells'])} cells, ΔE00 mean {doc['image']['delta_e00']['mean']:.3f}, "
                  f"largest standard error of an object's total {power:.2f} of its tolerance, "
                  f"tracer {t_seconds:.1f} s, Cycles {c_seconds:.1f} s")
        elif case == "filter-glossy":
            render_cycles(scene, cycles, work, {"CHROMATRACE_TEST_CYCLES_SETTINGS": "blur_glossy=1,sample_clamp_indirect=10"})
            doc = compare(cycles, tracer, os.path.join(work, "compare"))
            failed = [c for c in doc["cells"] if not c["pass"]]
            check(failed, "Cycles with Filter Glossy and Clamp Indirect on must disagree, but every cell passed")
            # Clamping indirect light and blurring glossy bounces change indirect and glossy light only: the
            # offending cells are there, never in emission or direct diffuse light.
            biased = [c for c in failed if c["component"].endswith("_indirect") or c["component"].startswith("glossy_")]
            check(biased, f"the offending cells must include indirect or glossy components: {failed[:5]}")
            wrong = [c for c in failed if c["component"] in ("emission", "diffuse_direct")]
            check(not wrong, f"emission and direct diffuse light must still agree: {wrong[:3]}")
            print(f"disagree as expected: {len(failed)} cells, e.g. "
                  + ", ".join(f"{c['object']} {c['component']} z={c['z']:.1f}" for c in biased[:3]))
        elif case == "reflectance":
            target = sys.argv[3]

            def grey(document):
                material = next(o["material"] for o in document["objects"] if o["name"] == target)
                document["materials"][material] = {"type": "lambert", "reflectance": {"constant": 0.5}}

            render_cycles(scene_copy(scene, work, grey), cycles, work)
            doc = compare(cycles, tracer, os.path.join(work, "compare"))
            failed = [c for c in doc["cells"] if not c["pass"]]
            on_target = [c for c in failed if c["object"] == target and c["component"] == "total"]
            check(len(on_target) >= len({c["band"] for c in doc["cells"]}) // 2,
                  f"{target}'s total must fail in most bands; failed cells: {[(c['object'], c['component'], c['band']) for c in failed[:8]]}")
            print(f"disagree as expected: {len(on_target)} bands of {target}'s total, {len(failed)} cells in all")
        elif case == "turned":
            # The sky turned a quarter turn further for Cycles: the sun lights the objects from another side, so
            # direct light from the environment must disagree on most objects (and the agree case, where the
            # turn is the same, shows that the add-on's Mapping node turns the way the tracer does).
            def turn(document):
                document["environment"]["rotation_deg"] = document["environment"].get("rotation_deg", 0) + 90

            render_cycles(scene_copy(scene, work, turn), cycles, work)
            doc = compare(cycles, tracer, os.path.join(work, "compare"))
            failed = [c for c in doc["cells"] if not c["pass"]]
            objects = {c["object"] for c in failed if c["component"] in ("diffuse_direct", "glossy_direct")}
            named = {o["object"] for o in doc["objects"] if o["object_id"] > 0}
            check(len(objects) * 2 > len(named), f"direct light must disagree on most objects; it does on {sorted(objects)}")
            print(f"disagree as expected: direct light on {sorted(objects)}, {len(failed)} cells in all")
        else:
            sys.exit(f"unknown case {case}")
    finally:
        keep = os.environ.get("CROSS_KEEP")
        if keep:
            shutil.copytree(work, keep, dirs_exist_ok=True)
        shutil.rmtree(work, ignore_errors=True)


main()
