#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Benchmark of the Blender add-on on an artist's scene, on every Blender: spectral Cycles against plain Cycles.

    CHROMATRACE_EXE=build/cli/chromatrace python3 bench/bench_artist_scene.py [--blender NAME=EXE ...]
        [--resolution 80x60] [--samples 64] [--bands 400:700:20]

The scene is an artist's .blend (tests/blender/make_artist_scene.py grey_floor hdri): a floor whose colour is an
Image Texture node of a packed float image, under Blender's own studio HDRI courtyard.exr as the world, seen by a
perspective camera with the sky above the horizon. For each Blender (default: Debian's blender and the bpy
modules setup.sh installs under build/, as CTest runs them):

- spectral, first run: blender_addon/batch.py with an empty cache, so the HDRI's and the texture's per-band-group
  images are prepared (`chromatrace prepare-texture`) before the Cycles renders;
- spectral, textures cached: the same with another seed, so every Cycles render is made again but the prepared
  images come from the cache, as when an artist renders again after changing the samples or the camera;
- plain: Cycles' own render of the same .blend at the same size and samples (tests/blender/render_plain.py).

Each run is its own Blender process, started the same way; the table gives the wall and CPU seconds of the
whole process and of the Cycles renders alone (from the add-on's progress lines and the plain render's own
timing), and their ratios to the plain render. Not a test: the machine is shared; read ratios.
"""

import argparse
import glob
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAKE = os.path.join(ROOT, "tests", "blender", "make_artist_scene.py")
PLAIN = os.path.join(ROOT, "tests", "blender", "render_plain.py")
BATCH = os.path.join(ROOT, "blender_addon", "batch.py")


def default_blenders():
    found = [("3.4", "blender")]
    for shim in sorted(glob.glob(os.path.join(ROOT, "build", "tests", "blender", "blender-[0-9]*"))):
        name = os.path.basename(shim)[len("blender-"):]
        if os.access(shim, os.X_OK) and re.fullmatch(r"[0-9]+\.[0-9]+", name):
            found.append((name, shim))
    return found


def children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(command):
    """(completed process, wall s, CPU s of the process and its children)."""
    start, start_cpu = time.monotonic(), children_cpu()
    done = subprocess.run(command, capture_output=True, text=True)
    wall, cpu = time.monotonic() - start, children_cpu() - start_cpu
    if done.returncode:
        sys.exit(f"{' '.join(command[:4])} ...: {(done.stderr or done.stdout).strip()[-800:]}")
    return done, wall, cpu


def spectral(blender, blend, out, cache, args, seed):
    done, wall, cpu = run([blender, "--background", "--factory-startup", "--python", BATCH, "--", "--blend", blend,
                           "--out", out, "--resolution", args.resolution, "--samples", str(args.samples),
                           "--bands", args.bands, "--seed", str(seed), "--cache-dir", cache])
    renders = re.findall(r"chromatrace: render \d+/\d+ \([^)]*\): ([0-9.]+) s, ([0-9.]+) s CPU", done.stderr)
    textures = re.findall(r"chromatrace: texture (.*): (cached|[0-9.]+ s)$", done.stderr, re.M)
    return {"wall": wall, "cpu": cpu, "renders": len(renders),
            "render_wall": sum(float(w) for w, _ in renders), "render_cpu": sum(float(c) for _, c in renders),
            "textures": [t[1] for t in textures]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--blender", action="append", help="NAME=EXECUTABLE (repeat); default: every Blender CTest runs")
    p.add_argument("--resolution", default="80x60")
    p.add_argument("--samples", type=int, default=64)
    p.add_argument("--bands", default="400:700:20")
    args = p.parse_args()
    if not os.environ.get("CHROMATRACE_EXE"):
        sys.exit("set CHROMATRACE_EXE to the chromatrace executable (e.g. build/cli/chromatrace)")
    blenders = [tuple(b.split("=", 1)) for b in args.blender] if args.blender else default_blenders()
    print(f"artist's scene (textured floor, HDRI world), {args.resolution}, {args.samples} samples, bands "
          f"{args.bands}; {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    print(f"{'Blender':8}{'run':28}{'whole s':>9}{'CPU s':>8}{'renders':>8}{'render s':>10}{'CPU s':>8}"
          f"{'/ plain':>9}")
    for name, blender in blenders:
        work = tempfile.mkdtemp(prefix="chromatrace-bench-")
        try:
            blend = os.path.join(work, "artist.blend")
            run([blender, "--background", "--factory-startup", "--python", MAKE, "--", "grey_floor", blend, "hdri"])
            cache = os.path.join(work, "cache")
            first = spectral(blender, blend, os.path.join(work, "first.exr"), cache, args, 1)
            again = spectral(blender, blend, os.path.join(work, "again.exr"), cache, args, 2)
            plain, wall, cpu = run([blender, "--background", "--factory-startup", blend, "--python", PLAIN, "--",
                                    os.path.join(work, "plain.exr"), args.resolution, str(args.samples)])
            found = re.search(r"PLAIN_RENDER_SECONDS ([0-9.]+) ([0-9.]+)", plain.stdout)
            plain_render_wall, plain_render_cpu = float(found.group(1)), float(found.group(2))
            for label, r in (("spectral, first run", first), ("spectral, textures cached", again)):
                print(f"{name:8}{label:28}{r['wall']:9.2f}{r['cpu']:8.2f}{r['renders']:8d}{r['render_wall']:10.2f}"
                      f"{r['render_cpu']:8.2f}{r['render_cpu'] / plain_render_cpu:8.1f}x")
            print(f"{name:8}{'plain Cycles':28}{wall:9.2f}{cpu:8.2f}{1:8d}{plain_render_wall:10.2f}"
                  f"{plain_render_cpu:8.2f}{1.0:8.1f}x")
            print(f"{name:8}{'':28}whole run, spectral / plain: first {first['cpu'] / cpu:.1f}x CPU, "
                  f"cached {again['cpu'] / cpu:.1f}x CPU; textures: first {', '.join(first['textures'])}; "
                  f"again {', '.join(again['textures'])}")
        finally:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
