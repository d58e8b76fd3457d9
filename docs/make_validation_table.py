# SPDX-License-Identifier: Apache-2.0
"""Writes the results table of docs/validation.md: each scene rendered by the reference tracer and by Cycles
(real Blender, through the add-on) at the cross-validation CTests' settings, held to each other with
`chromatrace compare`, and the figures of the verdict put between the table's markers. Each renderer also
renders a second seed and one sample per pixel, for its noise and its fixed cost: the table gives the time
each takes for the same noise.

    CHROMATRACE_EXE=build/cli/chromatrace python3 docs/make_validation_table.py

Environment as tests/blender/cross_validate.py: BLENDER, CROSS_SIZE (32x32), CROSS_BANDS (400:760:60),
CROSS_SPP (2048).
"""
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

EXE = os.environ["CHROMATRACE_EXE"]
BLENDER = os.environ.get("BLENDER", "blender")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIZE = os.environ.get("CROSS_SIZE", "32x32")
BANDS = os.environ.get("CROSS_BANDS", "400:760:60")
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


def render_tracer(scene, out, seed, spp=SPP):
    return timed([EXE, "render", scene, "-o", out, "--spp", str(spp), "--resolution", SIZE, "--bands", BANDS,
                  "--seed", str(seed), "--components", "paths,lights", "-q"])


def render_cycles(scene, out, seed, work, spp=SPP):
    return timed([BLENDER, "--background", "--factory-startup", "--python",
                  os.path.join(ROOT, "blender_addon", "batch.py"), "--", "--scene", scene, "--out", out,
                  "--samples", str(spp), "--resolution", SIZE, "--bands", BANDS, "--components", "paths,lights",
                  "--seed", str(seed), "--cache-dir", os.path.join(work, f"cache-{seed}-{spp}"), "-q"],
                 dict(os.environ, CHROMATRACE_EXE=EXE))


def compare(a, b, out, pixels="interior"):
    timed([EXE, "compare", a, b, "-o", out, "--pixels", pixels, "-q"])
    with open(os.path.join(out, "compare.json")) as f:
        return json.load(f)


def noise(first, second, out):
    """Per cell (object, component, band): the standard error of one render's object mean, from two renders
    of independent seeds. Their difference holds no image structure, only the noise of both: its standard
    error is √2 times one render's."""
    doc = compare(first, second, out)
    return {(c["object"], c["component"], c["band"]): c["se"] / math.sqrt(2) for c in doc["cells"] if c["se"] > 0}


def row(name, scene, work):
    path = lambda f: os.path.join(work, f)
    t = [render_tracer(scene, path(f"tracer{k}.exr"), seed) for k, seed in ((1, 1), (2, 2))]
    c = [render_cycles(scene, path(f"cycles{k}.exr"), seed, work) for k, seed in ((1, 7), (2, 8))]
    # What a render costs whatever its samples (start, scene import and set-up, Blender's above all): one
    # sample per pixel.
    t0 = render_tracer(scene, path("tracer-1spp.exr"), 3, 1)
    c0 = render_cycles(scene, path("cycles-1spp.exr"), 9, work, 1)
    doc = compare(path("cycles1.exr"), path("tracer1.exr"), path("compare"))
    cells = doc["cells"]
    worst = max(cells, key=lambda c: abs(c["z"]) if isinstance(c["z"], (int, float)) else 0.0)
    de = doc["image"]["delta_e00"]
    # The objects' totals: their ratios Cycles / tracer and the ratios' standard errors (median and largest).
    totals = [c for c in cells if c["component"] == "total" and c["object_id"] >= 0 and c["ratio"] and c["se_ratio"]]
    deviation = max(abs(c["ratio"] - 1) for c in totals)
    se_median, se_max = statistics.median(c["se_ratio"] for c in totals), max(c["se_ratio"] for c in totals)
    # Cycles' noise against the tracer's at equal samples: the median over the cells of the ratio of their
    # variances, and the time Cycles takes for the tracer's noise (its samples scaled by that ratio, variance
    # falling as 1 / samples; the fixed cost unscaled).
    se_t = noise(path("tracer1.exr"), path("tracer2.exr"), path("noise-tracer"))
    se_c = noise(path("cycles1.exr"), path("cycles2.exr"), path("noise-cycles"))
    ratios = sorted((se_c[k] / se_t[k]) ** 2 for k in se_t.keys() & se_c.keys())
    variance_ratio = statistics.median(ratios)
    tracer_time, cycles_time = statistics.mean(t), statistics.mean(c)
    cycles_equal = c0 + (cycles_time - c0) * variance_ratio
    return (f"| {name} | {len(cells)} | {sum(not c['pass'] for c in cells)} | {abs(worst['z']):.1f} "
            f"({worst['object']} {worst['component']}, {worst['band_nm'][0]:g}–{worst['band_nm'][1]:g} nm) "
            f"| {100 * deviation:.2f} % | {100 * se_median:.2f} % / {100 * se_max:.2f} % | {de['mean']:.2f} / {de['p95']:.2f} "
            f"| {tracer_time:.1f} s ({t0:.1f} s fixed) | {cycles_time:.1f} s ({c0:.1f} s fixed) "
            f"| {variance_ratio:.2f} ({len(ratios)} cells) | {tracer_time:.1f} s / {cycles_equal:.1f} s |")


def main():
    lines = ["| scene | cells | failed | largest \\|z\\| | objects' totals: largest \\|ratio − 1\\| | their standard error: "
             "median / largest | ΔE00 mean / 95th pct. | tracer | Cycles | variance Cycles / tracer (same samples) "
             "| time for the tracer's noise: tracer / Cycles |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
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
