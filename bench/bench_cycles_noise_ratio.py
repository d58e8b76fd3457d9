#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Measurement: Cycles' Monte Carlo noise against the reference tracer's at equal samples, on the test scenes.

    CHROMATRACE_EXE=build/cli/chromatrace python3 bench/bench_cycles_noise_ratio.py [--blender blender ...]
        [--resolution 64] [--samples 64] [--bands 400:700:50]

What plan's constants kCyclesNoiseRatio (the median) and kCyclesNoiseRatioLow/High (the range) in plan/plan.h are
measured with. For each scene (the paper box, the Cornell box, the textured scene under its HDRI, the glossy lights)
and each --blender: two Cycles renders by the add-on's batch at --resolution pixels on the longer side, --samples
samples and the --bands, seeds 1 and 2, no components; then `chromatrace plan --cycles-pilot A B`, which renders the
tracer the same way and gives the ratio of the two renderers' mean ΔE00 between their seeds (plan/measure.cpp,
measure_cycles_noise). Prints the ratio per scene and Blender, and the median and range.
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = {
    "paper box": "scenes/paper/box.json",
    "Cornell box": "scenes/cornell_box/cornell_box.json",
    "textured (HDRI)": "scenes/textured/textured.json",
    "glossy lights": "scenes/glossy_lights/glossy_lights.json",
}


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode:
        sys.exit(f"{' '.join(cmd[:4])} ... failed ({r.returncode}): {r.stderr.strip()[-800:]}")
    return r


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--blender", action="append", help="a Blender (repeatable; default: blender)")
    p.add_argument("--resolution", type=int, default=64)
    p.add_argument("--samples", type=int, default=64)
    p.add_argument("--bands", default="400:700:50")
    args = p.parse_args()
    exe = os.environ.get("CHROMATRACE_EXE")
    if not exe:
        sys.exit("set CHROMATRACE_EXE to the chromatrace executable (e.g. build/cli/chromatrace)")
    print(f"{args.resolution} pixels on the longer side, {args.samples} samples, bands {args.bands}, "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    ratios = []
    with tempfile.TemporaryDirectory(prefix="chromatrace-noise-ratio-") as work:
        for blender in args.blender or ["blender"]:
            for name, relative in SCENES.items():
                scene = os.path.join(ROOT, relative)
                with open(scene) as f:
                    width, height = json.load(f)["camera"]["resolution"]
                scale = args.resolution / max(width, height)
                size = f"{max(1, round(width * scale))}x{max(1, round(height * scale))}"
                pilots = []
                for seed in (1, 2):
                    out = os.path.join(work, f"{len(ratios)}-{seed}.exr")
                    run([blender, "--background", "--factory-startup", "--python",
                         os.path.join(ROOT, "blender_addon", "batch.py"), "--", "--scene", scene, "--out", out,
                         "--resolution", size, "--samples", str(args.samples), "--bands", args.bands, "--seed",
                         str(seed), "--components", "none", "--ggx-masking", "cycles", "--quiet",
                         "--cache-dir", os.path.join(work, "cache")], env=dict(os.environ, CHROMATRACE_EXE=exe))
                    pilots.append(out)
                report = os.path.join(work, "report.json")
                run([exe, "plan", scene, "-o", os.path.join(work, "plan.json"), "--report", report, "--cycles-pilot",
                     *pilots, "-q"])
                with open(report) as f:
                    cycles = json.load(f)["prediction"]["cycles"]
                ratio = cycles["noise_ratio_to_tracer"]
                ratios.append(ratio)
                between = re.search(r"mean ΔE00 (\S+) between them against the tracer's (\S+),", cycles["noise_ratio_from"])
                print(f"{os.path.basename(blender):10s} {name:16s} ratio {ratio:.3f} (mean ΔE00 between the seeds: Cycles "
                      f"{between.group(1)}, tracer {between.group(2)})", flush=True)
    print(f"median {statistics.median(ratios):.3f}, range {min(ratios):.3f}-{max(ratios):.3f} over {len(ratios)}")


if __name__ == "__main__":
    main()
