#!/usr/bin/env python3
"""Writes docs/stability.md: where each way of saving render time breaks, measured by `chromatrace study`.

    python3 docs/make_stability_table.py [--exe build/cli/chromatrace] [--resolution 32] [--out docs/stability.md]

Scenes: the paper box (smooth daylight, the baseline) and variants of it that provoke a failure — its lamp as CIE
F11 (three narrow peaks) or as a narrow-band blue LED (10 nm wide), its back wall with a narrow-band reflectance,
every surface a 90 % white (strong interreflection), the sphere a sharp mirror-like gloss (roughness 0.02).
Methods: uniform bands (9 over 380-780 nm), bands fitted by `chromatrace plan` (target 1), hero wavelengths (the
continuous mode), a truncated bounce limit (2), few samples (16). Each scene is studied once with all five
(`chromatrace study`, the scene's own settings as the base, a 5 nm tracer reference); each cell gives the method's
systematic rms ΔE00 (for few samples, the noise), how many objects' histogram classes differ from the reference,
and what chromatrace says about that setting before rendering (`render`'s warnings for it).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BOX = os.path.join(ROOT, "scenes", "paper", "box.json")

METHODS = [
    ("uniform bands (9 x 44 nm)", "tracer-bands-9"),
    ("bands fitted by plan (target 1)", "tracer-fitted-1"),
    ("hero wavelengths (continuous)", "tracer-mode-continuous"),
    ("truncated bounces (2)", "tracer-bounces-2"),
    ("few samples (16)", "tracer-samples-16"),
]


def absolute(node, base):
    if isinstance(node, dict):
        return {k: (os.path.join(base, v) if k in ("csv", "file") and isinstance(v, str) and not os.path.isabs(v)
                    else absolute(v, base)) for k, v in node.items()}
    if isinstance(node, list):
        return [absolute(v, base) for v in node]
    return node


def scenes(work):
    with open(BOX) as f:
        box = absolute(json.load(f), os.path.dirname(BOX))
    out = []

    def add(key, title, change):
        doc = json.loads(json.dumps(box))
        change(doc)
        doc["name"] = key
        path = os.path.join(work, key + ".json")
        with open(path, "w") as f:
            json.dump(doc, f, indent=1)
        out.append((key, title, path))

    add("smooth", "smooth daylight (the paper box, D65)", lambda d: None)
    add("f11", "spiky light (CIE F11)", lambda d: d["spectra"].__setitem__("lamp", {"illuminant": "F11"}))
    add("led", "narrow-band LED (450 nm, 10 nm wide)", lambda d: d["spectra"].__setitem__(
        "lamp", {"samples": [[430, 0], [440, 0], [450, 1], [460, 0], [470, 0]]}))
    add("narrow", "narrow-band reflectance (back wall: a 10 nm peak at 600 nm)", lambda d: d["materials"]["back_wall"]
        .__setitem__("reflectance", {"samples": [[380, 0.1], [590, 0.1], [600, 0.9], [610, 0.1], [780, 0.1]]}))

    def white(d):
        for m in d["materials"].values():
            for key in ("reflectance", "diffuse"):
                if key in m:
                    m[key] = {"constant": 0.9}
            if "specular" in m:
                m["specular"] = 0.05
    add("white", "strong interreflection (every surface 90 % white)", white)
    add("glossy", "sharp glossy highlight (sphere roughness 0.02)",
        lambda d: d["materials"]["sphere"].__setitem__("roughness", 0.02))
    return out


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True)


def says(exe, scene, setting, study_dir, resolution):
    """What chromatrace says about this setting before rendering."""
    name = setting["name"]
    if setting["knob"] in ("bands", "fitted"):
        r = run([exe, "render", scene, "-o", os.path.join(study_dir, "probe.exr"), "--plan",
                 os.path.join(study_dir, "plans", name + ".json"), "--resolution", "1x1", "--spp", "1", "-q"])
        # The band plan's warnings (those of the bounce limit and samples begin with the option's name).
        warnings = [line.split("warning: ", 1)[1] for line in r.stderr.splitlines()
                    if "warning: " in line and not line.split("warning: ", 1)[1].startswith("--")]
        if not warnings:
            return "nothing"
        first = warnings[0].split(";")[0]
        return f"render warns: {first}" + (f" (and {len(warnings) - 1} more)" if len(warnings) > 1 else "")
    if setting["knob"] in ("bounces", "samples"):
        # The render's own warning, for this setting alone (the other at a value that says nothing of it).
        if setting["knob"] == "bounces":
            flags, prefix = ["--max-bounces", str(setting["max_bounces"]), "--spp", "1"], "--max-bounces"
        else:
            flags, prefix = ["--spp", str(setting["samples"])], "--spp"
        r = run([exe, "render", scene, "-o", os.path.join(study_dir, "probe.exr"), "--resolution",
                 f"{resolution}x{resolution}", "-q"] + flags)
        warnings = [line.split("warning: ", 1)[1] for line in r.stderr.splitlines()
                    if "warning: " + prefix in line]
        return f"render warns: {warnings[0]}" if warnings else "nothing"
    return "nothing (no band error; more noise per sample)"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--exe", default=os.path.join(ROOT, "build", "cli", "chromatrace"))
    p.add_argument("--resolution", type=int, default=32)
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "stability.md"))
    args = p.parse_args()
    rows = {m: {} for m, _ in METHODS}
    titles = []
    with tempfile.TemporaryDirectory(prefix="chromatrace-stability-") as work:
        for key, title, scene in scenes(work):
            titles.append((key, title))
            study_dir = os.path.join(work, "study-" + key)
            print(f"studying {key} ...", file=sys.stderr, flush=True)
            r = run([args.exe, "study", scene, "-o", study_dir, "--resolution", f"{args.resolution}x{args.resolution}",
                     "--bands", "9", "--fitted", "1", "--samples", "16", "--bounces", "2", "--modes", "continuous",
                     "--no-plan", "--reference-spp", "1024", "-q"])
            if r.returncode not in (0, 1):
                sys.exit(f"study of {key} failed: {r.stderr.strip()[-500:]}")
            with open(os.path.join(study_dir, "study.json")) as f:
                study = json.load(f)
            by_name = {s["name"]: s for s in study["settings"]}
            base = by_name["tracer-base"]
            for method, name in METHODS:
                s = by_name.get(name)
                if s is None or not s.get("ok"):
                    rows[method][key] = "failed" if s else "not run"
                    continue
                e = s["error"]
                if s["knob"] == "samples":
                    size = f"noise {e['noise_rms_de00']:.1f}"
                elif e["systematic_rms_de00"] is None:
                    size = "not measurable"
                else:
                    size = f"{e['systematic_rms_de00']:.1f}"
                changed = sum(1 for o, b in zip(s["structure"]["objects"], base["structure"]["objects"])
                              if o["class"] != b["class"])
                cell = f"{size}; {changed} class{'es' if changed != 1 else ''} changed; {says(args.exe, scene, s, study_dir, args.resolution)}"
                rows[method][key] = cell
    lines = ["# Where methods break: the stability table", "",
             "Every way of saving render time breaks somewhere. This table is generated by",
             "[`docs/make_stability_table.py`](make_stability_table.py) from [`chromatrace study`](study.md) runs at "
             f"{args.resolution} × {args.resolution} pixels on the paper box and variants of it that provoke each "
             "failure. A cell gives the method's **systematic rms ΔE00** against a 5 nm tracer reference with the scene's "
             "bounce limit (for few samples: the Monte Carlo noise, rms ΔE00), how many objects' **histogram classes "
             "change** against the scene's own settings, and **what chromatrace says** about that setting before "
             "rendering: the warnings `render` (and `check-scene`) print for the setting, at the study's image size. A systematic error is the method's own; at this size noise of about 1.5 hides smaller ones "
             "(see [study.md](study.md#what-is-measured)).", ""]
    for (key, title) in titles:
        lines.append(f"- **{key}**: {title}")
    lines += ["", "| method | " + " | ".join(k for k, _ in titles) + " |",
              "|---|" + "---|" * len(titles)]
    for method, _ in METHODS:
        lines.append(f"| {method} | " + " | ".join(rows[method].get(k, "") for k, _ in titles) + " |")
    lines += ["", "Not in the table: Cycles' band multiplexing and its one-band fallback (each band group is a Cycles "
              "render of its own, so they share the bands' failures and cost more, see [plan.md](plan.md) and "
              "`bench/bench_plan_cycles.py`), and over-exposure, a camera setting (`chromatrace sensor` clips; the "
              "analyzer names clipped faces, [analyze.md](analyze.md)).", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print(args.out)


if __name__ == "__main__":
    main()
