"""Writes the results table of docs/validation.md: each scene rendered by the reference tracer and by Cycles
(real Blender, through the add-on) at the cross-validation CTests' settings, held to each other with
`chromatrace compare`, and the figures of the verdict put between the table's markers.

    CHROMATRACE_EXE=build/cli/chromatrace python3 docs/make_validation_table.py

Environment as tests/blender/cross_validate.py: BLENDER, CROSS_SIZE (32x32), CROSS_BANDS (380:780:40),
CROSS_SPP (2048).
"""
import json
import os
import subprocess
import sys
import tempfile
import time

EXE = os.environ["CHROMATRACE_EXE"]
BLENDER = os.environ.get("BLENDER", "blender")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIZE = os.environ.get("CROSS_SIZE", "32x32")
BANDS = os.environ.get("CROSS_BANDS", "380:780:40")
SPP = os.environ.get("CROSS_SPP", "2048")
SCENES = [("paper box", "scenes/paper/box.json"), ("Cornell box", "scenes/cornell_box/cornell_box.json"),
          ("glossy lights", "scenes/glossy_lights/glossy_lights.json")]
BEGIN, END = "<!-- validation table: begin -->", "<!-- validation table: end -->"


def timed(args, env=None):
    start = time.monotonic()
    result = subprocess.run(args, capture_output=True, text=True, env=env)
    if result.returncode != 0:
        sys.exit(f"failed ({result.returncode}): {' '.join(args)}\n{result.stderr}")
    return time.monotonic() - start


def row(name, scene, work):
    tracer, cycles = os.path.join(work, "tracer.exr"), os.path.join(work, "cycles.exr")
    t = timed([EXE, "render", scene, "-o", tracer, "--spp", SPP, "--resolution", SIZE, "--bands", BANDS, "--seed", "1",
               "--components", "paths,lights", "-q"])
    c = timed([BLENDER, "--background", "--factory-startup", "--python", os.path.join(ROOT, "blender_addon", "batch.py"),
               "--", "--scene", scene, "--out", cycles, "--samples", SPP, "--resolution", SIZE, "--bands", BANDS,
               "--components", "paths,lights", "--seed", "7", "--cache-dir", os.path.join(work, "cache"), "-q"],
              dict(os.environ, CHROMATRACE_EXE=EXE))
    out = os.path.join(work, "compare")
    timed([EXE, "compare", cycles, tracer, "-o", out, "--pixels", "interior", "-q"])
    with open(os.path.join(out, "compare.json")) as f:
        doc = json.load(f)
    cells = doc["cells"]
    worst = max(cells, key=lambda c: abs(c["z"]) if isinstance(c["z"], (int, float)) else 0.0)
    de = doc["image"]["delta_e00"]
    return (f"| {name} | {len(cells)} | {sum(not c['pass'] for c in cells)} | {abs(worst['z']):.1f} "
            f"({worst['object']} {worst['component']}, {worst['band_nm'][0]:g}–{worst['band_nm'][1]:g} nm) | {de['mean']:.2f} / {de['p95']:.2f} "
            f"| {t:.1f} s | {c:.1f} s |")


def main():
    lines = ["| scene | cells | failed | largest \\|z\\| | ΔE00 mean / 95th pct. | tracer | Cycles (same samples) |",
             "|---|---|---|---|---|---|---|"]
    for name, scene in SCENES:
        with tempfile.TemporaryDirectory(prefix="validation_") as work:
            lines.append(row(name, os.path.join(ROOT, scene), work))
            print(lines[-1], file=sys.stderr)
    path = os.path.join(ROOT, "docs", "validation.md")
    with open(path) as f:
        text = f.read()
    if BEGIN not in text or END not in text:
        sys.exit(f"{path}: the table's markers {BEGIN} … {END} are missing")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    settings = f"<!-- {SIZE}, bands {BANDS}, {SPP} samples per pixel -->"
    new = head + BEGIN + "\n" + settings + "\n\n" + "\n".join(lines) + "\n\n" + END + tail
    with open(path + ".tmp", "w") as f:
        f.write(new)
    os.replace(path + ".tmp", path)


main()
