#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Benchmark: a spectral Cycles render planned by `chromatrace plan` against one plain RGB Cycles render.

    CHROMATRACE_EXE=build/cli/chromatrace python3 bench/bench_plan_cycles.py [--resolution 96] [--samples 256]
        [--reference-spp 2048] [--light d65|f11|both] [--no-reconstruction]
        [--blender blender [--blender build/tests/blender/blender-4.5 ...]]

Each --blender is run in turn (a Blender binary, or a bpy module behind tests/blender/bpy_blender.py, as the
build's build/tests/blender/blender-4.5, blender-5.2 and blender-5.3 are), the scene's GGX masking set to that Cycles' own
(separable up to 3.x, height-correlated from 4.0) for its renders and its reference alike.

For the paper box under its own smooth light (CIE D65) and under CIE F11 (three narrow peaks):

1. `chromatrace plan --renderer cycles --edge-step 5 --target-de00 1`: the fewest bands (in whole groups of three)
   and bounces for a mean ΔE00 of 1; edges on multiples of 5 nm, so the plan nests in the 5 nm reference.
2. The planned spectral render: the add-on's batch (blender_addon/batch.py) with the plan's bands and bounce
   limit, path-type components only, at --samples. Its cost is the CPU seconds of its Cycles renders (band
   groups and the one-sample object-id render), from the batch's own progress lines.
3. One plain RGB Cycles render of the same imported scene, same samples and resolution, the scene's bounce limit,
   in a Blender started the same way (bench_blender.py's PLAIN): what a user renders without chromatrace.
4. The planned render's error: `chromatrace compare` of it against a reference-tracer render with 5 nm bands, the
   scene's bounce limit and --reference-spp paths per pixel; its image-level mean ΔE00 (CIE 1931 observer) holds
   the plan's band and bounce error and both renders' noise.

Prints, per light, the CPU ratio planned spectral / plain RGB and the measured mean ΔE00. Not a test: the machine
is shared, so read the figures as ratios from one run.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_blender import PLAIN, ROOT, _children_cpu  # noqa: E402

BOX = os.path.join(ROOT, "scenes", "paper", "box.json")


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


def scene_for(light, work, masking):
    with open(BOX) as f:
        doc = absolute_paths(json.load(f), os.path.dirname(BOX))
    if light == "f11":
        doc["spectra"]["lamp"] = {"illuminant": "F11"}
        doc["name"] = "box-f11"
    for material in doc["materials"].values():
        if material.get("type") == "dichromatic" and material.get("lobe", "ggx") == "ggx":
            material["masking"] = masking
    path = os.path.join(work, f"box-{light}-{masking}.json")
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    return path


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode:
        sys.exit(f"{' '.join(cmd[:3])} ... failed ({r.returncode}): {r.stderr.strip()[-800:]}")
    return r


def bench(light, args, work, blender_exe, version):
    exe = os.environ["CHROMATRACE_EXE"]
    masking = "height-correlated" if int(version.split(".")[0]) >= 4 else "separable"
    work = os.path.join(work, version)
    os.makedirs(work, exist_ok=True)
    scene = scene_for(light, work, masking)
    res = f"{args.resolution}x{args.resolution}"
    plan_file, report_file = os.path.join(work, f"{light}-plan.json"), os.path.join(work, f"{light}-report.json")
    run([exe, "plan", scene, "--renderer", "cycles", "--edge-step", "5", "--target-de00", "1", "-o", plan_file,
         "--report", report_file, "-q"] + (["--no-reconstruction"] if args.no_reconstruction else []))
    with open(report_file) as f:
        report = json.load(f)
    bounces = report["settings"]["max_bounces"]
    bands = report["settings"]["band_count"]
    scene_bounces = report["scene_settings"]["max_bounces"]

    reference = os.path.join(work, f"{light}-reference.exr")
    start, start_cpu = time.monotonic(), _children_cpu()
    run([exe, "render", scene, "-o", reference, "--resolution", res, "--bands", "380:780:5", "--spp",
         str(args.reference_spp), "--max-bounces", str(scene_bounces), "--seed", "7", "-q"])
    reference_cpu = _children_cpu() - start_cpu

    blender = [blender_exe, "--background", "--factory-startup"]
    spectral_exr = os.path.join(work, f"{light}-cycles.exr")
    spectral = run(blender + ["--python", os.path.join(ROOT, "blender_addon", "batch.py"), "--", "--scene", scene,
                              "--out", spectral_exr, "--resolution", res, "--samples", str(args.samples),
                              "--bands-file", plan_file, "--max-bounces", str(bounces), "--components", "paths",
                              "--cache-dir", os.path.join(work, f"{light}-cache")],
                   env=dict(os.environ, CHROMATRACE_EXE=exe))
    timings = re.findall(r"chromatrace: render \d+/\d+ \(([^)]*)\): ([0-9.]+) s, ([0-9.]+) s CPU", spectral.stderr)
    if not timings:
        sys.exit("no render timings in the batch's output:\n" + spectral.stderr[-800:])
    spectral_cpu = sum(float(cpu) for _what, _wall, cpu in timings)
    groups = [(what, float(cpu)) for what, _wall, cpu in timings]

    plain = run(blender + ["--python-expr", PLAIN.format(root=ROOT, box=scene, samples=args.samples,
                                                          res=args.resolution, out=os.path.join(work, "rgb.exr"))])
    found = re.search(r"PLAIN_RENDER_SECONDS ([0-9.]+) ([0-9.]+)", plain.stdout)
    if not found:
        sys.exit("plain RGB render printed no timing:\n" + plain.stdout[-400:] + plain.stderr[-800:])
    plain_cpu = float(found.group(2))

    compare_dir = os.path.join(work, f"{light}-compare")
    run([exe, "compare", spectral_exr, reference, "-o", compare_dir, "--colour", "own", "-q"])
    with open(os.path.join(compare_dir, "compare.json")) as f:
        compared = json.load(f)
    mean_de = compared["image"]["delta_e00"]["mean"]

    print(f"\nBlender {version}, {light.upper()}: plan {bands} bands (edges {report['settings']['bands']['edges_nm']}), "
          f"{bounces} bounces (scene: {scene_bounces}); predicted mean dE00 {report['prediction']['mean_de00']:.2f}")
    for what, cpu in groups:
        print(f"  Cycles render ({what}): {cpu:.2f} s CPU")
    print(f"  planned spectral, all Cycles renders: {spectral_cpu:.2f} s CPU")
    print(f"  plain RGB Cycles render:              {plain_cpu:.2f} s CPU")
    print(f"  ratio planned spectral / plain RGB:   {spectral_cpu / plain_cpu:.2f}x CPU")
    print(f"  measured mean dE00 against the 5 nm reference ({args.reference_spp} spp, "
          f"{reference_cpu:.1f} s CPU): {mean_de:.2f}")
    return spectral_cpu / plain_cpu, mean_de


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--resolution", type=int, default=96)
    p.add_argument("--samples", type=int, default=256)
    p.add_argument("--reference-spp", type=int, default=2048)
    p.add_argument("--light", choices=("d65", "f11", "both"), default="both")
    p.add_argument("--blender", action="append", help="a Blender (repeatable; default: blender)")
    p.add_argument("--no-reconstruction", action="store_true",
                   help="plan's edges alone, its band values read as a step function (plan --no-reconstruction)")
    args = p.parse_args()
    if not os.environ.get("CHROMATRACE_EXE"):
        sys.exit("set CHROMATRACE_EXE to the chromatrace executable (e.g. build/cli/chromatrace)")
    print(f"paper box, {args.resolution}x{args.resolution}, {args.samples} samples, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory(prefix="chromatrace-bench-plan-") as work:
        results = []
        for blender_exe in args.blender or ["blender"]:
            version = blender_version(blender_exe)
            for light in (("d65", "f11") if args.light == "both" else (args.light,)):
                results.append((version, light, *bench(light, args, work, blender_exe, version)))
        print("\nBlender  light  CPU planned spectral / plain RGB  measured mean dE00")
        for version, light, ratio, mean_de in results:
            print(f"{version:8s} {light.upper():5s}  {ratio:5.2f}x{'':27s}{mean_de:.2f}")


if __name__ == "__main__":
    main()
