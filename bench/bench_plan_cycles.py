#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Benchmark: a spectral Cycles render planned for a colour-error target against one plain RGB Cycles render.

    CHROMATRACE_EXE=build/cli/chromatrace python3 bench/bench_plan_cycles.py [--resolution 96] [--samples 256]
        [--reference-spp 8192] [--target 1] [--light d65|f11|both] [--scene box|textured|artist|both|all]
        [--blender blender [--blender build/tests/blender/blender-4.5 ...]] [--reference-dir DIR]
        [--guided FRACTION [--guided-threshold T]]

Each --blender is run in turn (a Blender binary, or a bpy module behind tests/blender/bpy_blender.py, as the
build's build/tests/blender/blender-4.5, blender-5.2 and blender-5.3 are), the scene's GGX masking set to that Cycles' own
(separable up to 3.x, height-correlated from 4.0) for its renders and its reference alike.

For two scenes, each under a smooth light (D65) and under CIE F11 (three narrow peaks):

- the paper box (scenes/paper/box.json) under its own lamp (CIE D65), and with the lamp's spectrum F11;
- the textured scene (scenes/textured/textured.json: image textures, a glossy ball, an HDRI sky, whose RGB texels
  are relative to D65), and the same scene lit instead by an F11 panel overhead (a 6 m square 3 m up, of the HDRI's
  mean luminance; Blender's world takes no measured spectrum).

And an artist's scene, under its own light: a .blend made by each Blender (tests/blender/make_artist_scene.py
artist: Principled BSDFs, a packed image texture, Blender's studio HDRI as the world and an area light coloured by a
Blackbody node), rendered from the .blend as an artist renders it, and its reference rendered by the tracer from the
scene file the add-on's Export writes of it (which holds all of it exactly, blender.cross_validate.principled). With
--reference-dir the .blend and its export are kept there too, one per Blender, so that runs plan and measure the
same scene: two runs of make_artist_scene.py do not make the same meshes to the last bit (the spheres' vertices come
in another order), which moves the plan's preview and pilots by their noise. Remove them there when
make_artist_scene.py changes.

For each:

1. The planned spectral render: the add-on's batch (blender_addon/batch.py) with --plan TARGET --plan-edge-step 5
   --plan-reference-spp REFERENCE_SPP (chromatrace plan, two pilot renders for Cycles' noise, plan again: bands,
   bounce limit and each band group's samples, for the target as compare measures it against the reference below,
   whose own noise counts; where the scene uses Cycles' light tree, the pilots and the plan again without it, and the
   plan of fewer samples taken), path-type components. Its cost: the CPU seconds of its Cycles renders (band groups
   and the one-sample object-id render) from the batch's progress lines, and apart the planning's (the batch's
   "planning:" line: the runs of chromatrace plan and the pilots), which does not grow with the image.
2. One plain RGB Cycles render of the same imported scene, --samples per pixel and the same resolution, the scene's
   bounce limit, in a Blender started the same way (bench_blender.py's PLAIN): what a user renders without
   chromatrace.
3. The planned render's error: `chromatrace compare` of it against a reference-tracer render with 5 nm bands, the
   scene's bounce limit and --reference-spp paths per pixel (one per light and masking, shared by the Blenders): the
   image's mean ΔE00 (CIE 1931 observer) and the worst object's. The reference's own noise is in what compare
   measures, and the plan's prediction against it (the header's chromatrace.plan, against_tracer_reference: the
   bands' error, Cycles' noise and the reference's added pixel by pixel) is printed beside it. Where the plan turned
   the light tree off, the plain render is made that way too and printed beside: how much of the saving that alone
   gives.

A second plain render has the samples of the planned render's largest band group: a plain render as noisy as the
planned one, whose ratio separates the spectral render's own cost from the samples the target asks for.

Both sides are rendered again at one sample (the planned render's band groups at one sample each, with its bands and
bounce limit; the plain render at one sample): what does not grow with the pixels or the samples — loading the
scene, the images, the world's importance map, once per band group. The ratio of what is left is what a large image
costs (at 96 × 96 the fixed part is most of a textured scene's render).

A third plain render, the first's twin with seed 2, gives the plain render's own noise (bench_plain_noise: the ΔE00 between the two
over √2, over the image and per object). From it the floor of an unbiased planned render: every band group is a
Cycles render no less noisy than the plain render at equal samples (the plan's predicted noise over the plain
render's is printed to check it), so each group needs at least the samples at which the plain render's own noise
meets the target, for the mean (with the bands' error) and for the worst object's limit; the planned groups' CPU at
those samples, over the plain render's, is the least an unbiased spectral render can cost here.

With --guided, the plan is rendered again with its group of most samples guiding the others at FRACTION of its
samples, reconstructed from it when assembled (core/guided.h); with --guided-threshold, the guided groups use Cycles'
adaptive sampling up to the guide's samples where a pixel's noise stays above T (objects' edges and highlights, which
the reconstruction leaves at their own samples).

Prints, per Blender and light, the CPU ratio planned spectral / plain RGB with and without the planning, the
predicted and measured mean ΔE00 and the worst object's. Not a test: the machine is shared, so read the figures as
ratios from one run.
"""

import argparse
import hashlib
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_blender import PLAIN, ROOT, _children_cpu  # noqa: E402

SCENES = {"box": os.path.join(ROOT, "scenes", "paper", "box.json"),
          "textured": os.path.join(ROOT, "scenes", "textured", "textured.json")}
DATA = os.path.join(ROOT, "core", "data")


def absolute_paths(node, base):
    """The scene document with every relative `csv` and `file` path made absolute (the copy lives elsewhere)."""
    if isinstance(node, dict):
        return {k: (os.path.join(base, v) if k in ("csv", "file", "texture") and isinstance(v, str)
                    and not os.path.isabs(v) else absolute_paths(v, base)) for k, v in node.items()}
    if isinstance(node, list):
        return [absolute_paths(v, base) for v in node]
    return node


def blender_version(blender):
    r = run([blender, "--background", "--factory-startup", "--python-expr",
             "import bpy; print('BLENDER_VERSION', bpy.app.version_string.split()[0])"])
    return re.search(r"BLENDER_VERSION (\S+)", r.stdout).group(1)


def read_csv(path):
    with open(path) as f:
        rows = [line.strip().split(",") for line in f if line.strip()][1:]
    return {float(r[0]): [float(x) for x in r[1:]] for r in rows}


def f11_luminance():
    """CIE F11's luminance (the CIE 1931 ȳ) relative to the flat spectrum 1's, on F11's 5 nm table."""
    f11, cmf = read_csv(os.path.join(DATA, "illuminants", "F11.csv")), read_csv(os.path.join(DATA, "cie1931_2deg_1nm.csv"))
    y = {nm: v[1] for nm, v in cmf.items()}
    common = [nm for nm in f11 if nm in y]
    return sum(f11[nm][0] * y[nm] for nm in common) / sum(y[nm] for nm in common)


def texture_mean_luminance(path):
    """The mean Rec. 709 luminance of an image's texels (oiiotool --stats)."""
    stats = run(["oiiotool", "--stats", path]).stdout
    r, g, b = (float(x) for x in re.search(r"Stats Avg: (\S+) (\S+) (\S+)", stats).groups())
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def scene_for(scene_name, light, work, masking):
    source = SCENES[scene_name]
    with open(source) as f:
        doc = absolute_paths(json.load(f), os.path.dirname(source))
    if light == "f11" and scene_name == "box":
        doc["spectra"]["lamp"] = {"illuminant": "F11"}
    elif light == "f11":  # the HDRI's place taken by a 6 m square F11 panel 3 m up of the HDRI's mean luminance
        sky = doc.pop("environment")["radiance"]["texture"]
        doc["lights"] = [{"name": "panel_f11", "shape": {"type": "quad", "corner": [-3, -3, 3], "edge1": [0, 6, 0],
                                                          "edge2": [6, 0, 0]},
                          "radiance": {"illuminant": "F11"},
                          "scale": round(texture_mean_luminance(sky) / f11_luminance(), 6)}]
    doc["name"] = f"{scene_name}-{light}"
    for material in doc["materials"].values():
        if material.get("type") == "dichromatic" and material.get("lobe", "ggx") == "ggx":
            material["masking"] = masking
    path = os.path.join(work, f"{scene_name}-{light}-{masking}.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    return path


# A plain RGB Cycles render of the open .blend as bench_blender.PLAIN renders an imported scene: PLAIN without its
# import.
_IMPORT = """for c in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras):
    for item in list(c):
        c.remove(item)
scene = bpy.context.scene
scene_import.import_scene({box!r}, scene, tool.Tool(tool.find_executable()), lambda m: None)
"""
assert _IMPORT in PLAIN, "bench_blender.PLAIN no longer imports the scene as this bench expects"
_RENDER = "scene.render.filepath = "
assert _RENDER in PLAIN, "bench_blender.PLAIN no longer sets the output before it renders"
# The .blend's objects get the export's object ids as pass indices, as the spectral render gives them, so that the
# plain render's noise is measured per object too.
PLAIN_BLEND = PLAIN.replace(_IMPORT, "scene = bpy.context.scene\nids = {ids!r}\nfor ob in scene.objects:\n"
                                     "    ob.pass_index = ids.get(ob.name, ob.pass_index)\n")


def artist_blend(blender_exe, out_dir, version):
    """make_artist_scene.py's artist .blend made by this Blender, and the scene file Export writes of it: in
    `out_dir`, kept and reused where they are already there."""
    os.makedirs(out_dir, exist_ok=True)
    blend, scene = (os.path.join(out_dir, f"artist-{version}.{ext}") for ext in ("blend", "json"))
    if not os.path.exists(scene):
        here = os.path.join(ROOT, "tests", "blender")
        run([blender_exe, "--background", "--factory-startup", "--python", os.path.join(here, "make_artist_scene.py"),
             "--", "artist", blend])
        said = run([blender_exe, blend, "--background", "--factory-startup", "--python-exit-code", "1", "--python",
                    os.path.join(here, "export_blend.py"), "--", scene],
                   env=dict(os.environ, CHROMATRACE_SOURCE_DIR=ROOT))
        if "approximately:" in said.stdout:
            sys.exit("the artist's scene was exported approximately:\n" + said.stdout)
    return blend, scene


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode:
        sys.exit(f"{' '.join(cmd[:3])} ... failed ({r.returncode}): {r.stderr.strip()[-800:]}")
    return r


def header_plan(exe, exr):
    info = json.loads(run([exe, "info", exr, "--json"]).stdout)
    return json.loads(info["metadata"]["chromatrace.plan"])


def _digest(scene, blend):
    """A short digest of the scene file (and .blend) a reference is rendered from, so a kept one is not reused for
    another scene."""
    h = hashlib.sha256()
    for path in (scene, blend):
        if path:
            with open(path, "rb") as f:
                h.update(f.read())
    return h.hexdigest()[:10]


def plain_noise_of(plain_exr, scene, names, exe):
    """One plain render's Monte Carlo noise in ΔE00 (bench_plain_noise on two seeds): {"image": n, objects: {name: n}}.
    `names`: the reference's object names by id."""
    with open(scene) as f:
        lights = {light.get("name") for light in json.load(f).get("lights", [])}
    emitters = ",".join(i for i, name in names.items() if name in lights)
    tool = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(exe))), "bench", "bench_plain_noise")
    said = run([tool, *plain_exr, "--emitters", emitters, "--scene", scene]).stdout.split("\n")
    noise = {"image": float(said[0].split()[1]), "objects": {}}
    for line in said[1:]:
        if line.startswith("object "):
            _, object_id, pixels, n = line.split()
            if int(pixels) >= 16 and names.get(object_id) not in lights:
                noise["objects"][names.get(object_id, object_id)] = float(n)
    return noise


def floor_of(plan, plain_noise, args, spectral_cpu, plain_cpu):
    """What an unbiased planned render costs at the least, from this run's measurements (docs/plan.md, "What sets the
    floor"). Each band group is a Cycles render, no less noisy than the plain render at equal samples (printed: the
    plan's predicted noise over the plain render's at the planned samples), so each group needs at least the samples
    N at which the plain render's own noise meets the target: the image's mean in quadrature with the bands' and
    bounces' predicted error, and the noisiest object's limit (2 × the target) in quadrature with its bands' error
    where the plan judged that object (else its noise alone). The planned
    groups' CPU scaled to N (a lower bound where a group has a fixed cost and N is below its samples), over the plain
    render's."""
    samples = plan["cycles_samples"]
    mean_samples = sum(samples) / len(samples)
    bands = plan.get("predicted_bands_mean_de00", 0.0)
    budget = max(args.target ** 2 - bands ** 2, 1e-9)
    worst_name, worst = max(plain_noise["objects"].items(), key=lambda item: item[1], default=("-", 0.0))
    need_mean = args.samples * plain_noise["image"] ** 2 / budget
    # The object's own band error where the plan judged it (the header keeps the worst object the plan predicted).
    judged = plan.get("worst_object") or {}
    object_bands = judged.get("bands_only_mean_de00", 0.0) if judged.get("name") == worst_name else 0.0
    need_object = args.samples * worst ** 2 / max((2 * args.target) ** 2 - object_bands ** 2, 1e-9)
    need = max(need_mean, need_object)
    noisier = None
    if "predicted_noise_mean_de00" in plan:  # the plan's noise over the plain render's at the planned samples
        noisier = plan["predicted_noise_mean_de00"] / (plain_noise["image"] * math.sqrt(args.samples / mean_samples))
    return dict(need_mean=need_mean, need_object=need_object, worst_name=worst_name, worst=worst, samples=need,
                ratio=spectral_cpu * need / mean_samples / plain_cpu, noisier=noisier, groups=len(samples))


def guided_render(args, plan_file, plan, blender, source, res, out_dir, case, exe, compared_with_reference):
    """The planned render again with the plan's guide group (else its group of most samples) at the most samples of
    any group and the others at --guided of them, reconstructed from it when assembled (core/guided.h): its CPU, its
    error and the refusals."""
    with open(plan_file) as f:
        bands = json.load(f)
    planned = bands["cycles_samples"]
    # The plan's guide (the group whose noise, carried into every band, makes the least ΔE00 on the pilots), with the
    # most samples.
    guide = plan.get("guide_band_group")
    if guide is None:
        guide = planned.index(max(planned))
    most = max(planned)
    few = max(1, math.ceil(most * args.guided))
    bands["cycles_samples"] = [most if g == guide else few for g in range(len(planned))]
    bands["cycles_guided_groups"] = [g for g in range(len(planned)) if g != guide]
    if args.guided_threshold:
        bands["cycles_guided_threshold"] = args.guided_threshold
    guided_file = os.path.join(out_dir, f"{case}-guided-bands.json")
    with open(guided_file, "w") as f:
        json.dump(bands, f)
    exr = os.path.join(out_dir, f"{case}-guided.exr")
    done = run(blender + ["--python", os.path.join(ROOT, "blender_addon", "batch.py"), "--", *source, "--out", exr,
                          "--resolution", res, "--bands-file", guided_file, "--max-bounces", str(plan["max_bounces"]),
                          "--components", "paths", "--cache-dir", os.path.join(out_dir, f"{case}-guided-cache")],
               env=dict(os.environ, CHROMATRACE_EXE=exe))
    cpu = sum(float(cpu) for _what, _wall, cpu in re.findall(
        r"chromatrace: render \d+/\d+ \(([^)]*)\): ([0-9.]+) s, ([0-9.]+) s CPU", done.stderr))
    report = json.loads(json.loads(run([exe, "info", exr, "--json"]).stdout)["metadata"]["chromatrace.guided"])
    mean, worst, worst_name = compared_with_reference(exr, "guided-")
    return dict(guide=guide, samples=bands["cycles_samples"], cpu=cpu, mean=mean, worst=worst, worst_name=worst_name,
                refused=len(report["refused"]), tested=report["tested"])


def bench(scene_name, light, args, work, blender_exe, version, references):
    exe = os.environ["CHROMATRACE_EXE"]
    masking = "height-correlated" if int(version.split(".")[0]) >= 4 else "separable"
    out_dir = os.path.join(work, version)
    os.makedirs(out_dir, exist_ok=True)
    blend = None
    if scene_name == "artist":  # its reference is of its export, which holds this Blender's Principled BSDF
        blend, scene = artist_blend(blender_exe, args.reference_dir or out_dir, version)
        masking = f"principled-v{2 if int(version.split('.')[0]) >= 4 else 1}"  # one reference per Principled BSDF
    else:
        scene = scene_for(scene_name, light, work, masking)
    case = f"{scene_name}-{light}"
    res = f"{args.resolution}x{args.resolution}"
    with open(scene) as f:
        scene_bounces = json.load(f)["render"]["max_bounces"]

    # The reference, once per scene, light and masking (kept in --reference-dir across runs when given).
    reference = os.path.join(args.reference_dir or work,
                             f"{case}-{masking}-{res}-{args.reference_spp}spp-{_digest(scene, blend)}-reference.exr")
    if reference not in references:
        start_cpu = _children_cpu()
        if not os.path.exists(reference):
            run([exe, "render", scene, "-o", reference, "--resolution", res, "--bands", "380:780:5", "--spp",
                 str(args.reference_spp), "--max-bounces", str(scene_bounces), "--seed", "7", "-q"])
        references[reference] = _children_cpu() - start_cpu

    blender = [blender_exe, "--background", "--factory-startup"]
    spectral_exr = os.path.join(out_dir, f"{case}-cycles.exr")
    plan_file = os.path.join(out_dir, f"{case}-plan.json")
    source = ["--blend", blend] if blend else ["--scene", scene]
    spectral = run(blender + ["--python", os.path.join(ROOT, "blender_addon", "batch.py"), "--", *source,
                              "--out", spectral_exr, "--resolution", res, "--plan", repr(args.target),
                              "--plan-edge-step", "5", "--plan-reference-spp", str(args.reference_spp),
                              "--components", "paths", "--plan-out", plan_file,
                              "--cache-dir", os.path.join(out_dir, f"{case}-cache")],
                   env=dict(os.environ, CHROMATRACE_EXE=exe))
    timings = re.findall(r"chromatrace: render \d+/\d+ \(([^)]*)\): ([0-9.]+) s, ([0-9.]+) s CPU", spectral.stderr)
    planning = re.search(r"chromatrace: planning: ([0-9.]+) s, ([0-9.]+) s CPU", spectral.stderr)
    said = re.search(r"chromatrace: (plan for a mean .*)", spectral.stderr)
    if not timings or not planning or not said:
        sys.exit("no render or planning timings in the batch's output:\n" + spectral.stderr[-1200:])
    spectral_cpu = sum(float(cpu) for _what, _wall, cpu in timings)
    planning_cpu = float(planning.group(2))
    plan = header_plan(exe, spectral_exr)
    # Its fixed part: the same renders at one sample a group (what does not grow with the pixels or the samples).
    one_sample = os.path.join(out_dir, f"{case}-one-sample-bands.json")
    edges = json.loads(run([exe, "info", spectral_exr, "--json"]).stdout)["bands"]["edges_nm"]
    with open(one_sample, "w") as f:
        json.dump({"format": "chromatrace-bands/1", "edges_nm": edges, "cycles_samples": [1] * len(plan["cycles_samples"])}, f)
    fixed = run(blender + ["--python", os.path.join(ROOT, "blender_addon", "batch.py"), "--", *source,
                           "--out", os.path.join(out_dir, f"{case}-one-sample.exr"), "--resolution", res,
                           "--bands-file", one_sample, "--max-bounces", str(plan["max_bounces"]), "--components", "paths",
                           "--cache-dir", os.path.join(out_dir, f"{case}-one-sample-cache")],
                env=dict(os.environ, CHROMATRACE_EXE=exe))
    spectral_fixed_cpu = sum(float(cpu) for _what, _wall, cpu in re.findall(
        r"chromatrace: render \d+/\d+ \(([^)]*)\): ([0-9.]+) s, ([0-9.]+) s CPU", fixed.stderr))
    reference_noise = plan["tracer_noise_at_one_sample"] / args.reference_spp ** 0.5
    # The plan's own prediction against the reference (its noise added pixel by pixel), for which it was planned.
    against = plan["against_tracer_reference"]
    predicted, (low, high) = against["mean_de00"], against["mean_de00_range"]
    worst_plan = plan.get("worst_object")
    worst_predicted = (f"{math.hypot(worst_plan['mean_de00'], reference_noise * worst_plan['noise_to_image_noise']):.2f} "
                       f"({worst_plan['name']})") if worst_plan else "-"

    names = json.loads(run([exe, "info", reference, "--json"]).stdout)["object_ids"]["names"]
    ids = {name: int(i) for i, name in names.items()}

    def plain_render(samples, seed, out, light_tree_off=False):
        script = (PLAIN_BLEND if blend else PLAIN).format(root=ROOT, box=scene, samples=samples, seed=seed,
                                                           res=args.resolution, out=out, ids=ids)
        if light_tree_off:  # as the plan renders its groups where its pilots asked for it (docs/plan.md)
            script = script.replace(_RENDER, "scene.cycles.use_light_tree = False\n" + _RENDER)
        plain = run(([blender_exe, blend, "--background", "--factory-startup"] if blend else blender)
                    + ["--python-expr", script])
        found = re.search(r"PLAIN_RENDER_SECONDS ([0-9.]+) ([0-9.]+)", plain.stdout)
        if not found:
            sys.exit("plain RGB render printed no timing:\n" + plain.stdout[-400:] + plain.stderr[-800:])
        return float(found.group(2))

    plain_exr = [os.path.join(out_dir, f"{case}-rgb-{seed}.exr") for seed in (1, 2)]
    # Its noise from the difference of two seeds; its cost the cheaper of the two (the same work: the machine's noise).
    plain_cpu = min(plain_render(args.samples, 1, plain_exr[0]), plain_render(args.samples, 2, plain_exr[1]))
    plain_noise = plain_noise_of(plain_exr, scene, names, exe)
    plain_fixed_cpu = plain_render(1, 1, os.path.join(out_dir, f"{case}-rgb-one-sample.exr"))
    # What grows with the pixels and the samples: each side's CPU less its one-sample render's.
    samples_part = (spectral_cpu - spectral_fixed_cpu) / max(plain_cpu - plain_fixed_cpu, 1e-9)
    # And a plain render as noisy as the planned one: the samples of its largest band group.
    equal_samples = max(plan["cycles_samples"])
    equal_cpu = plain_render(equal_samples, 1, os.path.join(out_dir, f"{case}-rgb-equal.exr"))
    floor = floor_of(plan, plain_noise, args, spectral_cpu, plain_cpu)
    # Where the plan turned Cycles' light tree off, the plain render so too: how much of the saving that alone makes.
    plain_off = None
    if plan.get("cycles_light_tree") is False:
        off_exr = [os.path.join(out_dir, f"{case}-rgb-light-tree-off-{seed}.exr") for seed in (1, 2)]
        off_cpu = min(plain_render(args.samples, seed, exr, light_tree_off=True) for seed, exr in zip((1, 2), off_exr))
        plain_off = dict(cpu=off_cpu, noise=plain_noise_of(off_exr, scene, names, exe)["image"])

    def compared_with_reference(exr, tag):
        compare_dir = os.path.join(out_dir, f"{case}-{tag}compare")
        run([exe, "compare", exr, reference, "-o", compare_dir, "--colour", "own", "-q"])
        with open(os.path.join(compare_dir, "compare.json")) as f:
            compared = json.load(f)
        if not compared["image"]["white"].startswith("the scene's light"):  # as the plan predicts (docs/compare.md)
            sys.exit(f"{exr}: compared under {compared['image']['white']}, not under the scene's light")
        worst_de, worst = max((o["delta_e00_mean"], o["object"]) for o in compared["objects"]
                              if o["object_id"] >= 0 and "delta_e00_mean" in o)
        return compared["image"]["delta_e00"]["mean"], worst_de, worst

    mean_de, worst_de, worst = compared_with_reference(spectral_exr, "")
    guided = guided_render(args, plan_file, plan, blender, source, res, out_dir, case, exe,
                           compared_with_reference) if args.guided else None

    print(f"\nBlender {version}, {scene_name}, {light.upper()}: {said.group(1)}")
    for what, _wall, cpu in timings:
        print(f"  Cycles render ({what}): {float(cpu):.2f} s CPU")
    print(f"  planned spectral, all Cycles renders: {spectral_cpu:.2f} s CPU; planning (plan, pilots, plan again): "
          f"{planning_cpu:.2f} s CPU")
    print(f"  plain RGB Cycles render ({args.samples} samples): {plain_cpu:.2f} s CPU")
    print(f"  ratio planned spectral / plain RGB: {spectral_cpu / plain_cpu:.2f}x CPU "
          f"({(spectral_cpu + planning_cpu) / plain_cpu:.2f}x with the planning)")
    print(f"  at one sample a group: planned {spectral_fixed_cpu:.2f} s CPU, plain {plain_fixed_cpu:.2f} s CPU; "
          f"the parts that grow with the pixels and samples: {samples_part:.2f}x")
    print(f"  plain RGB Cycles render at the planned groups' largest samples ({equal_samples}): {equal_cpu:.2f} s CPU; "
          f"ratio planned spectral / it: {spectral_cpu / equal_cpu:.2f}x")
    made = f"{references[reference]:.0f} s CPU" if references[reference] > 0 else "kept from an earlier run"
    print(f"  mean dE00 against the 5 nm reference ({args.reference_spp} paths per pixel, {made}): measured {mean_de:.2f}, predicted {predicted:.2f} "
          f"({low:.2f}-{high:.2f}); without the reference's noise predicted {plan['predicted_mean_de00']:.2f}; "
          f"worst object {worst} {worst_de:.2f}, predicted {worst_predicted}")
    print(f"  plain RGB render's own noise at {args.samples} samples (seeds 1 and 2): mean dE00 {plain_noise['image']:.2f}, "
          f"worst object {floor['worst_name']} {floor['worst']:.2f}; the plan's noise over it at the planned samples "
          + (f"{floor['noisier']:.2f}" if floor["noisier"] else "-"))
    print(f"  floor: the plain render's noise meets the mean at {floor['need_mean']:.0f} samples and "
          f"{floor['worst_name']}'s limit at {floor['need_object']:.0f}; {floor['groups']} groups of "
          f"{floor['samples']:.0f} samples cost at least {floor['ratio']:.2f}x the plain render")
    if plain_off:
        print(f"  plain RGB render with Cycles' light tree off, as the plan's groups ({args.samples} samples): "
              f"{plain_off['cpu']:.2f} s CPU ({plain_off['cpu'] / plain_cpu:.2f}x the artist's), its noise mean dE00 "
              f"{plain_off['noise']:.2f}; ratio planned spectral / it: {spectral_cpu / plain_off['cpu']:.2f}x")
    if guided:
        print(f"  guided: the plan's group {guided['guide']} at its {guided['samples'][guided['guide']]} samples guides the "
              f"others at {args.guided:g} of that ({', '.join(map(str, guided['samples']))}): {guided['cpu']:.2f} s CPU, "
              f"{guided['cpu'] / plain_cpu:.2f}x the plain render; mean dE00 {guided['mean']:.2f}, worst object "
              f"{guided['worst_name']} {guided['worst']:.2f}; {guided['refused']} of {guided['tested']} object layers and "
              f"bands refused")
    return dict(ratio=spectral_cpu / plain_cpu, with_planning=(spectral_cpu + planning_cpu) / plain_cpu,
                guided=guided and dict(guided, ratio=guided["cpu"] / plain_cpu),
                equal=spectral_cpu / equal_cpu,
                measured=mean_de, predicted=predicted, low=low, high=high, worst=f"{worst_de:.2f} ({worst})",
                worst_predicted=worst_predicted,
                samples=",".join(map(str, plan["cycles_samples"])), plain_noise=plain_noise["image"],
                samples_part=samples_part, fixed=spectral_fixed_cpu, plain_fixed=plain_fixed_cpu,
                plain_worst=f"{floor['worst']:.2f} ({floor['worst_name']})", floor=floor["ratio"], plain_off=plain_off,
                plain_cpu=plain_cpu,
                floor_samples=floor["samples"])


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--resolution", type=int, default=96)
    p.add_argument("--samples", type=int, default=256, help="the plain render's samples per pixel")
    p.add_argument("--reference-spp", type=int, default=8192)
    p.add_argument("--target", type=float, default=1.0, help="the plan's mean dE00")
    p.add_argument("--light", choices=("d65", "f11", "both"), default="both")
    p.add_argument("--scene", choices=("box", "textured", "artist", "both", "all"), default="both",
                   help="both: the box and the textured scene; all: the artist's too")
    p.add_argument("--blender", action="append", help="a Blender (repeatable; default: blender)")
    p.add_argument("--reference-dir", help="keep the tracer's references here and reuse them in later runs")
    p.add_argument("--guided", type=float, metavar="FRACTION",
                   help="also render the plan with its group of most samples guiding the others at this fraction of "
                        "its samples (core/guided.h), and measure it beside the plan")
    p.add_argument("--guided-threshold", type=float, metavar="T",
                   help="with --guided: render the guided groups with Cycles' adaptive sampling at this noise threshold, "
                        "up to the guide's samples where a pixel stays noisier (objects' edges, highlights)")
    args = p.parse_args()
    if args.guided_threshold and not args.guided:
        p.error("--guided-threshold needs --guided")
    if not os.environ.get("CHROMATRACE_EXE"):
        sys.exit("set CHROMATRACE_EXE to the chromatrace executable (e.g. build/cli/chromatrace)")
    print(f"{args.resolution}x{args.resolution}, plain render {args.samples} samples, plan for a mean dE00 "
          f"of {args.target:g}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory(prefix="chromatrace-bench-plan-") as work:
        results, references = [], {}
        for blender_exe in args.blender or ["blender"]:
            version = blender_version(blender_exe)
            scenes = {"both": ("box", "textured"), "all": ("box", "textured", "artist")}.get(args.scene, (args.scene,))
            for scene_name in scenes:
                for light in ("own",) if scene_name == "artist" else (
                        ("d65", "f11") if args.light == "both" else (args.light,)):
                    results.append((version, scene_name, light,
                                    bench(scene_name, light, args, work, blender_exe, version, references)))
        print(f"\nload average at the end {os.getloadavg()[0]:.1f}")
        print("\nBlender  scene     light  samples per group  CPU / plain  with planning  / plain at planned samples  "
              "mean dE00 measured  predicted (range)      worst object measured, predicted")
        for version, scene_name, light, r in results:
            print(f"{version:8s} {scene_name:9s} {light.upper():5s}  {r['samples']:17s}  {r['ratio']:10.2f}x  "
                  f"{r['with_planning']:12.2f}x  {r['equal']:24.2f}x"
                  f"  {r['measured']:17.2f}  {r['predicted']:.2f} ({r['low']:.2f}-{r['high']:.2f})  {r['worst']}, {r['worst_predicted']}")
        if args.guided:
            print(f"\nGuided: the plan's group of most samples guides the others at {args.guided:g} of its samples"
                  + (f", adaptive up to the guide's where their noise stays above {args.guided_threshold:g}"
                     if args.guided_threshold else ""))
            print("Blender  scene     light  samples per group  CPU / plain  mean dE00  worst object        refused")
            for version, scene_name, light, r in results:
                g = r["guided"]
                print(f"{version:8s} {scene_name:9s} {light.upper():5s}  {','.join(map(str, g['samples'])):17s}  "
                      f"{g['ratio']:10.2f}x  {g['mean']:9.2f}  {g['worst']:.2f} ({g['worst_name']}){'':4s}"
                      f"{g['refused']} of {g['tested']}")
        print("\nBlender  scene     light  one-sample CPU: planned, plain  growing part / plain  "
              "plain render's noise: mean, worst object   samples a group needs at the least  floor / plain")
        for version, scene_name, light, r in results:
            print(f"{version:8s} {scene_name:9s} {light.upper():5s}  {r['fixed']:21.2f}, {r['plain_fixed']:5.2f}  "
                  f"{r['samples_part']:19.2f}x  {r['plain_noise']:.2f}, {r['plain_worst']:27s}  "
                  f"{r['floor_samples']:34.0f}  {r['floor']:12.2f}x")
        off = [(version, scene_name, light, r) for version, scene_name, light, r in results if r["plain_off"]]
        if off:
            print("\nWhere the plan turned Cycles' light tree off: the plain render so too")
            print("Blender  scene     light  plain, light tree off: CPU / the artist's  its noise  planned spectral / it")
            for version, scene_name, light, r in off:
                o = r["plain_off"]
                print(f"{version:8s} {scene_name:9s} {light.upper():5s}  {o['cpu'] / r['plain_cpu']:38.2f}x  "
                      f"{o['noise']:9.2f}  {r['ratio'] * r['plain_cpu'] / o['cpu']:20.2f}x")


if __name__ == "__main__":
    main()
