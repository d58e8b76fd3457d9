#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes docs/stability.md: where each way of saving render time breaks, measured by `chromatrace study`.

    python3 docs/make_stability_table.py [--exe build/cli/chromatrace] [--resolution 32] [--cycles-resolution 16]
                                         [--no-cycles] [--out docs/stability.md]

Scenes: the paper box (smooth daylight, the baseline) and variants of it that provoke a failure — its lamp as CIE
F11 (three narrow peaks) or as a narrow-band blue LED (10 nm wide), its back wall with a narrow-band reflectance,
every surface a 90 % white (strong interreflection), the sphere a sharp mirror-like gloss (roughness 0.02).
Methods: uniform bands (9 over 380-780 nm), bands fitted by `chromatrace plan` (target 1), hero wavelengths (the
continuous mode), a truncated bounce limit (2), few samples (16) — each scene studied once with all five by the
tracer (`chromatrace study`, the scene's own settings as the base, a 5 nm tracer reference) — and Cycles through
the Blender add-on: its band multiplexing (three bands per Cycles render) with the same 9 uniform bands and with
the bands `plan` fits for Cycles, studied at a smaller size (`--cycles-resolution`; Blender on PATH or
CHROMATRACE_BLENDER), and the one-band fallback. Each cell gives the method's systematic rms ΔE00 (for few
samples, the noise), how many objects' histogram classes differ from the reference, and what chromatrace says
about that setting before rendering (`render`'s warnings for it; for Cycles, the Blender batch's, which are
`check-scene --renderer cycles`'s). About 7 minutes on two loaded cores, half of it the Cycles studies.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BOX = os.path.join(ROOT, "scenes", "paper", "box.json")

# (row, the study setting it reads): the tracer's study, then the Cycles study.
METHODS = [
    ("uniform bands (9 x 44 nm)", "tracer-bands-9"),
    ("bands fitted by plan (target 1)", "tracer-fitted-1"),
    ("hero wavelengths (continuous)", "tracer-mode-continuous"),
    ("Cycles multiplexing (9 x 44 nm, 3 bands per render)", "cycles-bands-9"),
    ("Cycles multiplexing, bands fitted by plan (target 1)", "cycles-fitted-1"),
    ("Cycles one-band fallback (9 x 44 nm)", "one-band"),
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


def first_of(warnings, who):
    if not warnings:
        return "nothing"
    first = warnings[0].split(";")[0]
    return f"{who} warns: {first}" + (f" (and {len(warnings) - 1} more)" if len(warnings) > 1 else "")


def says(exe, scene, setting, study_dir, resolution):
    """What chromatrace says about this setting before rendering."""
    name = setting["name"]
    plan_file = os.path.join(study_dir, "plans", name + ".json")
    if setting["renderer"] == "cycles":
        # What the Blender batch prints before it renders: check-scene for Cycles with the batch's options
        # (Blender.WarnsBeforeRenderingWhatItsSettingsLeaveOut shows the two the same), its band plan's lines.
        r = run([exe, "check-scene", scene, "--json", "--renderer", "cycles", "--bands-file", plan_file,
                 "--resolution", f"{resolution}x{resolution}"])
        warnings = [w for w in json.loads(r.stdout)["scene"]["warnings"] if not w.startswith("render.")]
        return first_of(warnings, "batch.py")
    if setting["knob"] in ("bands", "fitted"):
        r = run([exe, "render", scene, "-o", os.path.join(study_dir, "probe.exr"), "--plan", plan_file,
                 "--resolution", "1x1", "--spp", "1", "-q"])
        # The band plan's warnings (those of the bounce limit and samples begin with the option's name).
        warnings = [line.split("warning: ", 1)[1] for line in r.stderr.splitlines()
                    if "warning: " in line and not line.split("warning: ", 1)[1].startswith("--")]
        return first_of(warnings, "render")
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
    # The continuous mode: no band error; what render says of its samples (a prediction for the bands mode).
    r = run([exe, "render", scene, "-o", os.path.join(study_dir, "probe.exr"), "--spectral-mode", "continuous",
             "--resolution", f"{resolution}x{resolution}", "-q"])
    warnings = [line.split("warning: ", 1)[1] for line in r.stderr.splitlines() if "warning: " in line]
    return first_of(warnings, "render") + " (no band error)"


def cell(exe, scene, s, base, study_dir, resolution, tracer_twin=None):
    """One cell: the size of the error, the class changes, what is said."""
    e = s["error"]
    if s["knob"] == "samples":
        size = f"noise {e['noise_rms_de00']:.1f}"
    elif e["systematic_rms_de00"] is None:
        size = "not measurable"
    else:
        size = f"{e['systematic_rms_de00']:.1f}"
    if tracer_twin is not None and tracer_twin.get("ok") and tracer_twin["error"]["systematic_rms_de00"] is not None:
        size += f" (tracer, same bands: {tracer_twin['error']['systematic_rms_de00']:.1f})"
    if s["renderer"] == "cycles":
        size += f", {s['cost']['renders']} renders"
    changed = sum(1 for o, b in zip(s["structure"]["objects"], base["structure"]["objects"]) if o["class"] != b["class"])
    return f"{size}; {changed} class{'es' if changed != 1 else ''} changed; {says(exe, scene, s, study_dir, resolution)}"


def one_band_cell(multiplexed):
    """The one-band fallback: the multiplexed render's image in expectation, one band per Cycles render."""
    bands = multiplexed["band_count"]
    groups = multiplexed["cost"]["renders"] - 1  # less the object-id render
    return (f"as multiplexing, {bands + 1} renders instead of {groups + 1}; batch.py warns where nodes mix colour "
            "channels (none here)")


def study(exe, scene, out, resolution, extra):
    r = run([exe, "study", scene, "-o", out, "--resolution", f"{resolution}x{resolution}", "--no-plan",
             "--reference-spp", "1024", "-q"] + extra)
    if r.returncode not in (0, 1):
        sys.exit(f"study of {scene} failed: {r.stderr.strip()[-500:]}")
    with open(os.path.join(out, "study.json")) as f:
        return {s["name"]: s for s in json.load(f)["settings"]}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--exe", default=os.path.join(ROOT, "build", "cli", "chromatrace"))
    p.add_argument("--resolution", type=int, default=32)
    p.add_argument("--cycles-resolution", type=int, default=16)
    p.add_argument("--no-cycles", action="store_true", help="leave out the Cycles rows (no Blender)")
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "stability.md"))
    args = p.parse_args()
    cycles = not args.no_cycles
    if cycles and not (os.environ.get("CHROMATRACE_BLENDER") or shutil.which("blender")):
        sys.exit("no Blender (PATH or CHROMATRACE_BLENDER) for the Cycles rows; give --no-cycles to leave them out")
    methods = [(m, n) for m, n in METHODS if cycles or not (n.startswith("cycles") or n == "one-band")]
    rows = {m: {} for m, _ in methods}
    titles = []
    with tempfile.TemporaryDirectory(prefix="chromatrace-stability-") as work:
        for key, title, scene in scenes(work):
            titles.append((key, title))
            print(f"studying {key} ...", file=sys.stderr, flush=True)
            tracer_dir = os.path.join(work, "study-" + key)
            settings = study(args.exe, scene, tracer_dir, args.resolution,
                             ["--bands", "9", "--fitted", "1", "--samples", "16", "--bounces", "2",
                              "--modes", "continuous"])
            if cycles:
                # Cycles with the tracer beside it (the reference's noise, and the same bands in the tracer).
                with open(scene) as f:
                    render = json.load(f)["render"]
                cycles_dir = os.path.join(work, "cycles-" + key)
                print(f"studying {key} with Cycles ...", file=sys.stderr, flush=True)
                c = study(args.exe, scene, cycles_dir, args.cycles_resolution,
                          ["--renderers", "tracer,cycles", "--bands", "9", "--fitted", "1", "--bounces",
                           str(render["max_bounces"]), "--samples", str(render["samples"]), "--modes", "bands"])
            for method, name in methods:
                if name.startswith("tracer"):
                    s, base, where, res, twin = settings.get(name), settings["tracer-base"], tracer_dir, args.resolution, None
                    scene_file = scene
                else:
                    s = c.get("cycles-bands-9" if name == "one-band" else name)
                    base, where, res, scene_file = c["tracer-base"], cycles_dir, args.cycles_resolution, scene
                    twin = c.get("tracer-bands-9") if name == "cycles-bands-9" else None
                if s is None or not s.get("ok"):
                    rows[method][key] = "failed" if s else "not run"
                elif name == "one-band":
                    rows[method][key] = one_band_cell(s)
                else:
                    rows[method][key] = cell(args.exe, scene_file, s, base, where, res, twin)
    lines = ["# Where methods break: the stability table", "",
             "Every way of saving render time breaks somewhere. This table is generated by",
             "[`docs/make_stability_table.py`](make_stability_table.py) from [`chromatrace study`](study.md) runs at "
             f"{args.resolution} × {args.resolution} pixels on the paper box and variants of it that provoke each "
             "failure. A cell gives the method's **systematic rms ΔE00** against a 5 nm tracer reference with the scene's "
             "bounce limit (for few samples: the Monte Carlo noise, rms ΔE00), how many objects' **histogram classes "
             "change** against the tracer with the scene's own settings (for Cycles, the tracer's at Cycles' image size), and **what chromatrace says** about that setting "
             "before rendering: the warnings `render` (and `check-scene`) print for the setting, at the study's image "
             "size; the first is quoted up to its fix, which every warning names (bands fitted by `chromatrace plan`, "
             "narrower bands, the continuous mode where the renderer has it, the bounces or samples `plan` chooses). "
             "A systematic error is the method's own; at this size noise of about 1.5 hides smaller ones "
             "(see [study.md](study.md#what-is-measured)).", ""]
    for (key, title) in titles:
        lines.append(f"- **{key}**: {title}")
    lines += ["", "| method | " + " | ".join(k for k, _ in titles) + " |",
              "|---|" + "---|" * len(titles)]
    for method, _ in methods:
        lines.append(f"| {method} | " + " | ".join(rows[method].get(k, "") for k, _ in titles) + " |")
    lines += ["", "**Bands** (the first two rows): a band render multiplies band averages, exact only where the light or "
              "the reflectance is flat within a band, so spiky light and narrow-band reflectances break uniform bands; "
              "`plan` fits edges and a reconstruction to the scene's own spectra ([plan.md](plan.md)). "
              "`render` and `check-scene` judge a band plan through its reconstruction, one colour at a time, and "
              "name each light or material whose colour is off by a ΔE00 above 2 with the cause (the light's peaks or "
              "the reflectance) ([render.md](render.md#spectral-modes)). `tests/plan/test_spectral_check.cpp` provokes "
              "each: `SpectralCheck.NarrowBandLightIsNamedAtWideBandsOnly` (the LED at 40 nm bands, not at 1 nm), "
              "`NarrowBandReflectanceIsNamedAsTheCause` (the narrow back wall at 9 bands), "
              "`AReconstructionIsPartOfTheBands` (F11: `plan`'s bands silent, the same edges read as steps named), "
              "`SmoothSpectraAtTenNanometresGiveNoWarning`, and `CheckSceneAndRenderSayIt` (the lines printed by "
              "`check-scene` and `render`, and for Cycles without the continuous mode).", ""]
    if cycles:
        lines += ["**Cycles** (the next three rows) was studied at "
                  f"{args.cycles_resolution} × {args.cycles_resolution} pixels (to keep the script's run time "
                  "reasonable; its noise is larger there, so its intervals are wider), through the Blender add-on's batch "
                  "with three bands per Cycles render, against the same kind of tracer reference; the renders include the "
                  "object-id render. Multiplexing adds no error of its own: each band group is a Cycles render whose R, "
                  "G and B carry three bands, so it shares the band plan's failures (compare the tracer with the same "
                  "bands) and what differs is Cycles itself (its sampling and glossy model). Before it renders, the "
                  "batch prints the same warnings as `check-scene --renderer cycles` with its options (the fixes name "
                  "no continuous mode, which Cycles lacks): `Blender.WarnsBeforeRenderingWhatItsSettingsLeaveOut` "
                  "renders the paper box under F11 with 100 nm bands, 2 bounces and 4 samples and checks each line, "
                  "cause and fix; the Render Spectral button says the same for a scene imported from a scene file "
                  "(`blender.test_ui`). **The one-band fallback** (`--on-mixing-nodes one-band`, or `--bands-per-render 1`) "
                  "renders each band alone, copied into R, G and B: the same image in expectation "
                  "(`Blender.MultiplexingIsExactInExpectation`), so it was not studied again; it costs three times the "
                  "band renders and breaks nowhere else, except that channel-mixing nodes, the reason for it, act on "
                  "each band as on a grey (a hue or saturation change does nothing there). The batch says so, with the "
                  "renders it costs and the nodes by name (`blender.test_restore`, a hue/saturation node); a scene file, "
                  "as here, has no such nodes.", ""]
    lines += ["**Bounces and samples** (the last two rows): their warnings come from `plan`'s model, run by `check-scene` "
              "and `render` (and the Blender batch) before rendering ([render.md](render.md#warnings-before-a-render)); "
              f"their cells were filled from `render` at {args.resolution} × {args.resolution} pixels. "
              "`tests/plan/test_render_check.cpp` provokes each: `RenderCheck.BounceShareIsTheTracersWithinItsNoise` "
              "(the paper box at 2 bounces: the predicted share of the light against the tracer's), "
              "`WhiteBoxNeedsMoreBouncesThanThePaperBox`, `FewSamplesGiveThePredictedNoise` (4 paths per pixel: the "
              "predicted noise against two renders) and `CheckSceneAndRenderSayItAndPlansSettingsAreSilent` (the "
              "settings `plan` chooses are silent). The noise prediction is the tracer's in the bands mode: the "
              "continuous mode (hero wavelengths) has about 1.7 times its noise per sample "
              "([study.md](study.md#reading-a-study-of-the-paper-box)), which the warning does not count — the classes "
              "that change there change with the noise.", "",
              "Not in the table: over-exposure, a camera setting (`chromatrace sensor` clips; the analyzer names clipped "
              "faces, [analyze.md](analyze.md)).", ""]
    with open(args.out, "w") as f:
        f.write("\n".join(lines))
    print(args.out)


if __name__ == "__main__":
    main()
