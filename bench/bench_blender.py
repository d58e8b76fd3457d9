#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Benchmark of the Blender add-on: a spectral Cycles render of a scene beside one plain RGB Cycles render.

    CHROMATRACE_EXE=build/cli/chromatrace python3 bench/bench_blender.py [--scene scenes/paper/box.json]
        [--resolution 256] [--samples 128] [--bands 395:705:10] [--blender blender]

The scene is the paper box unless --scene names another (scenes/textured/textured.json: image textures and an
HDRI world, whose per-band-group images the spectral run prepares first, with a cache of its own, so cold).

Spectral: blender_addon/batch.py on scenes/paper/box.json (31 bands centred at 400, 410, ... 700 nm by
default, so 11 renders of 3 bands, the last of 1; path and light-group components; the scene's 8 bounces).
It reports the seconds of each Cycles render (from the add-on's progress lines) and the wall time of the
whole run: Blender's start, the import, every render and `chromatrace assemble`.
Plain RGB: the same imported scene rendered once by Cycles with the same samples, bounces and passes, in a
Blender started the same way: what one band group costs without the add-on around it.
Not a test: the machine is shared, so read the figures as orders of magnitude and ratios.
"""

import argparse
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BOX = os.path.join(ROOT, "scenes", "paper", "box.json")

# Run inside Blender by the plain RGB case: import the scene, the add-on's Cycles settings, one render.
PLAIN = """
import os, sys, time, bpy
sys.path.insert(0, os.path.join({root!r}, "blender_addon"))
import chromatrace
from chromatrace import cycles_setup, scene_import, tool
from chromatrace.journal import Journal
chromatrace.register()
for c in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras):
    for item in list(c):
        c.remove(item)
scene = bpy.context.scene
scene_import.import_scene({box!r}, scene, tool.Tool(tool.find_executable()), lambda m: None)
journal = Journal()
passes = {{"Emit", "DiffDir", "DiffInd", "DiffCol", "GlossDir", "GlossInd", "GlossCol", "IndexOB"}}
cycles_setup.apply(journal, scene, scene.view_layers[0], {samples}, {seed}, False, ({res}, {res}), passes)
cycles_setup.set_bounces(journal, scene, 7)
scene.render.filepath = {out!r}
start, start_cpu = time.monotonic(), time.process_time()
bpy.ops.render.render(write_still=True)
print(f"PLAIN_RENDER_SECONDS {{time.monotonic() - start:.3f}} {{time.process_time() - start_cpu:.3f}}", flush=True)
"""


def _children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=BOX)
    p.add_argument("--resolution", type=int, default=256)
    p.add_argument("--samples", type=int, default=128)
    p.add_argument("--bands", default="395:705:10")
    p.add_argument("--blender", default="blender")
    args = p.parse_args()
    if not os.environ.get("CHROMATRACE_EXE"):
        sys.exit("set CHROMATRACE_EXE to the chromatrace executable (e.g. build/cli/chromatrace)")
    work = tempfile.mkdtemp(prefix="chromatrace-bench-")
    scene = os.path.abspath(args.scene)
    blender = [args.blender, "--background", "--factory-startup"]

    start, start_cpu = time.monotonic(), _children_cpu()
    spectral = subprocess.run(
        blender + ["--python", os.path.join(ROOT, "blender_addon", "batch.py"), "--", "--scene", scene,
                   "--out", os.path.join(work, "spectral.exr"), "--resolution", f"{args.resolution}x{args.resolution}",
                   "--samples", str(args.samples), "--bands", args.bands, "--cache-dir", os.path.join(work, "cache")],
        capture_output=True, text=True)
    spectral_wall, spectral_cpu = time.monotonic() - start, _children_cpu() - start_cpu
    if spectral.returncode:
        sys.exit(f"spectral render failed: {spectral.stderr.strip().splitlines()[-1]}")
    timings = re.findall(r"chromatrace: render \d+/\d+ \([^)]*\): ([0-9.]+) s, ([0-9.]+) s CPU", spectral.stderr)
    groups = [float(wall) for wall, _cpu in timings]
    groups_cpu = [float(cpu) for _wall, cpu in timings]
    bands = re.search(r"(\d+) bands in (\d+) renders", spectral.stderr)
    textures = [float(t) for t in re.findall(r"chromatrace: texture .*: ([0-9.]+) s$", spectral.stderr, re.M)]

    start, start_cpu = time.monotonic(), _children_cpu()
    plain = subprocess.run(blender + ["--python-expr", PLAIN.format(
        root=ROOT, box=scene, samples=args.samples, seed=1, res=args.resolution, out=os.path.join(work, "rgb.exr"))],
        capture_output=True, text=True)
    plain_wall, plain_cpu = time.monotonic() - start, _children_cpu() - start_cpu
    found = re.search(r"PLAIN_RENDER_SECONDS ([0-9.]+) ([0-9.]+)", plain.stdout)
    if plain.returncode or not found:
        sys.exit(f"plain RGB render failed: {plain.stderr.strip()[-500:]}")
    plain_render, plain_render_cpu = float(found.group(1)), float(found.group(2))

    print(f"{os.path.basename(scene)}, {args.resolution}x{args.resolution}, {args.samples} samples, "
          f"{bands.group(1)} bands in {bands.group(2)} Cycles renders, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f}")
    print(f"{'':34}{'wall s':>10}{'CPU s':>10}")
    rows = [("spectral: texture preparation", sum(textures), float("nan"))] if textures else []
    rows += [("spectral: per band group (mean)", sum(groups) / len(groups), sum(groups_cpu) / len(groups_cpu)),
            ("spectral: all band groups", sum(groups), sum(groups_cpu)),
            ("spectral: whole run", spectral_wall, spectral_cpu),
            ("plain RGB: one Cycles render", plain_render, plain_render_cpu),
            ("plain RGB: whole run", plain_wall, plain_cpu)]
    for label, wall, cpu in rows:
        print(f"{label:34}{wall:10.2f}{cpu:10.2f}")
    print(f"spectral / plain RGB render: {sum(groups) / plain_render:.1f}x wall, "
          f"{sum(groups_cpu) / plain_render_cpu:.1f}x CPU "
          f"(one band group / plain RGB: {sum(groups_cpu) / len(groups_cpu) / plain_render_cpu:.2f}x CPU)")
    print("whole run: Blender start, import, renders (and for the spectral run, the texture preparation, "
          "chromatrace assemble and the preview)")
    shutil.rmtree(work, ignore_errors=True)

if __name__ == "__main__":
    main()
