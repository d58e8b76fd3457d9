# SPDX-License-Identifier: GPL-3.0-or-later
"""A spectral render planned for a colour-error target (batch.py --plan; docs/plan.md, "Cycles' samples"):

1. `chromatrace plan` on the scene as a scene file (the batch's --scene, or the open scene written as the panel's
   Export writes it): the fewest bands and bounces, from the tracer's preview.
2. Two pilot renders by this Cycles with those bands, at the plan's preview size and PILOT_SAMPLES, seeds 1 and 2,
   no components: Cycles' Monte Carlo noise on this scene and this Blender.
3. `chromatrace plan --cycles-pilot` again: the same bands and bounces, and each band group's samples for the
   target with Cycles' noise as the pilots measured it. The render then takes that plan.
4. Where the scene uses Cycles' light tree (Blender 3.5 on), steps 2 and 3 again with it off; the plan that needs
   fewer samples in all is taken, and says which (its band file's cycles_light_tree, the output's header).

The pilots cost little (PILOT_SAMPLES at 32 pixels on the longer side: under a thousandth of a 256-sample render
at 1024 pixels) and are made in a folder of their own, removed after.
"""

import json
import os
import shutil
import tempfile

from .errors import BadInput

PILOT_SIZE = 32  # pixels on the longer side: plan's preview size
PILOT_SAMPLES = 64
PILOT_SEEDS = (1, 2)


def pilot_resolution(width, height):
    """The pilots' size: the render's aspect with PILOT_SIZE pixels on the longer side."""
    if width >= height:
        return [PILOT_SIZE, max(1, round(height * PILOT_SIZE / width))]
    return [max(1, round(width * PILOT_SIZE / height)), PILOT_SIZE]


class Planned:
    """The outcome: the band-plan file the render takes (bands, reconstruction, samples per band group), the plan's
    report (`chromatrace plan --report`), and one line saying what it predicts."""

    def __init__(self, bands_file, report, report_file=None, light_tree=None):
        self.bands_file = bands_file
        self.report = report
        self.report_file = report_file
        self.light_tree = light_tree  # Cycles' light tree set by the plan (False: off), or None: the scene's own
        self.alternatives = []  # the plans made on other pilots (the light tree as the scene has it), not taken
        self.approximations = []  # what the scene file planned on holds only approximately (scene_export)

    @property
    def max_bounces(self):
        return self.report["settings"]["max_bounces"]

    @property
    def samples(self):
        return self.report["settings"]["cycles_samples"]

    @property
    def met(self):
        """The plan reaches the target with this Cycles' noise (its pilots')."""
        return bool(self.report["target_met"]) and "cycles" in self.report["prediction"]

    @property
    def notes(self):
        """What the plan's model could not hold (an image texture seen as a few colours, a camera whose
        curves end early, ...), and what the open scene's file holds only approximately: said beside the prediction,
        which they make less certain."""
        return list(self.approximations) + list(self.report.get("notes", []))

    def summary(self):
        cycles = self.report["prediction"]["cycles"]
        low, high = cycles["mean_de00_range"]
        against = cycles.get("against_tracer_reference")
        if against and against.get("the_target"):  # planned for what compare measures against that reference
            alow, ahigh = against["mean_de00_range"]
            reference = (f" ({against['mean_de00']:.2f} ({alow:.2f}-{ahigh:.2f}) against a tracer reference of "
                         f"{against['samples']} paths, the target)")
        else:
            reference = ""
        return (f"plan for a mean ΔE00 of {self.report['target_de00']:g}: {self.report['settings']['band_count']} bands, "
                f"max {self.max_bounces} bounces, samples per band group {', '.join(map(str, self.samples))}; "
                f"predicted mean ΔE00 {cycles['mean_de00']:.2f} ({low:.2f}-{high:.2f}){reference}, Cycles' noise "
                f"{cycles['noise_ratio_to_tracer']:.2f} × the tracer's on the pilots{self._worst_object()}"
                f"{self._light_tree()}")

    def _light_tree(self):
        if self.light_tree is None:
            return ""
        others = "; ".join(f"{sum(a.samples)} with it as the scene has it" if a.met else
                           "as the scene has it, no plan reaches the target" for a in self.alternatives)
        return (f"; Cycles' light tree {'on' if self.light_tree else 'off'}: {sum(self.samples)} samples in all "
                f"({others})")

    def worst_object(self):
        """The object predicted worst (plan's prediction.cycles.objects), or None."""
        objects = self.report["prediction"]["cycles"].get("objects") or []
        return max(objects, key=lambda o: o["mean_de00"]) if objects else None

    def _worst_object(self):
        worst, cycles = self.worst_object(), self.report["prediction"]["cycles"]
        if worst is None:
            return ""
        raised = cycles.get("samples_raised_for_objects", 1)
        return (f"; worst object {worst['name']} {worst['mean_de00']:.2f} (objects held to "
                f"{cycles['object_limit_mean_de00']:g}" + (f", samples × {raised:.2f} for it)" if raised > 1 else ")"))

    def header(self):
        """What the output's header keeps of the plan (chromatrace.plan)."""
        cycles = self.report["prediction"]["cycles"]
        return json.dumps({"target_de00": self.report["target_de00"], "camera": self.report["camera"],
                           "max_bounces": self.max_bounces, "cycles_samples": self.samples,
                           "predicted_mean_de00": cycles["mean_de00"], "predicted_range": cycles["mean_de00_range"],
                           "predicted_noise_mean_de00": cycles["noise_only_mean_de00"],
                           "predicted_bands_mean_de00": self.report["prediction"]["mean_de00"],
                           "noise_ratio_to_tracer": cycles["noise_ratio_to_tracer"],
                           "tracer_noise_at_one_sample": cycles["tracer_noise_at_one_sample"],
                           "guide_band_group": cycles.get("guide_band_group"),
                           "cycles_light_tree": self.light_tree,
                           # What compare is predicted to measure against a tracer reference, where the plan was
                           # asked for it (batch --plan-reference-spp): {samples, the_target, mean_de00, range}.
                           "against_tracer_reference": cycles.get("against_tracer_reference"),
                           "worst_object": self.worst_object()})


def plan_render(scene_file, target, work_dir, render_pilot, tool, edge_step=None, light_tree=False, reference_spp=None):
    """Plans the render of `scene_file` for a mean ΔE00 of `target` into `work_dir`. `render_pilot(bands_file, seed,
    output)` renders a pilot with this Cycles (the caller's scene, at the pilots' size and samples, no components).
    `light_tree`: the scene's Cycles uses its light tree; the pilots are then rendered with it and without it, and the
    plan takes whichever needs the fewer samples in all for the target (docs/plan.md, "Cycles' light tree, planned").
    `reference_spp`: the target is as compare will measure it against a tracer reference of that many paths.
    Returns a Planned; BadInput when no plan reaches the target."""
    first, first_report = os.path.join(work_dir, "plan-bands.json"), os.path.join(work_dir, "plan-bands-report.json")
    tool.plan(scene_file, target, first, first_report, edge_step=edge_step)
    with open(first_report) as f:
        report = json.load(f)
    if not report["target_met"]:
        raise BadInput(f"--plan: no plan reaches a mean ΔE00 of {target:g} on {scene_file}: "
                       + "; ".join(report["notes"] or ["the bands and bounces alone miss it"]))
    # The pilots render every group alike: the plan's bands without its samples.
    with open(first) as f:
        bands = json.load(f)
    bands.pop("cycles_samples", None)
    tried = [_plan_with_pilots(scene_file, target, work_dir, render_pilot, tool, edge_step, bands, None, reference_spp)]
    if light_tree:
        tried.append(_plan_with_pilots(scene_file, target, work_dir, render_pilot, tool, edge_step, bands, False,
                                       reference_spp))
    met = [planned for planned in tried if planned.met]
    if not met:
        report = tried[0].report
        raise BadInput(f"--plan: no plan reaches a mean ΔE00 of {target:g} on {scene_file} with this Cycles' noise: "
                       + "; ".join(report["notes"] or ["the bands and bounces alone miss it"]))
    chosen = min(met, key=lambda planned: sum(planned.samples))  # the first (the scene's own) where they tie
    chosen.alternatives = [planned for planned in tried if planned is not chosen]
    if chosen.light_tree is not None:  # the render takes the pilots' setting with the samples planned on them
        with open(chosen.bands_file) as f:
            document = json.load(f)
        document["cycles_light_tree"] = chosen.light_tree
        with open(chosen.bands_file, "w") as f:
            json.dump(document, f)
    return chosen


def _plan_with_pilots(scene_file, target, work_dir, render_pilot, tool, edge_step, bands, light_tree, reference_spp):
    """`chromatrace plan --cycles-pilot` on two pilots rendered with `bands` (and Cycles' light tree off where
    `light_tree` is False; None: as the scene has it). A Planned, whether or not it meets the target."""
    tag = "" if light_tree is None else f"-light-tree-{'on' if light_tree else 'off'}"
    pilot_bands = os.path.join(work_dir, f"pilot-bands{tag}.json")
    with open(pilot_bands, "w") as f:
        json.dump(bands if light_tree is None else dict(bands, cycles_light_tree=light_tree), f)
    pilots = []
    for seed in PILOT_SEEDS:
        pilots.append(os.path.join(work_dir, f"pilot{tag}-{seed}.exr"))
        render_pilot(pilot_bands, seed, pilots[-1])
    final, final_report = os.path.join(work_dir, f"plan{tag}.json"), os.path.join(work_dir, f"plan{tag}-report.json")
    tool.plan(scene_file, target, final, final_report, pilots=pilots, edge_step=edge_step, reference_spp=reference_spp)
    with open(final_report) as f:
        return Planned(final, json.load(f), report_file=final_report, light_tree=light_tree)


def planning_folder():
    return tempfile.mkdtemp(prefix="chromatrace-plan-")


def remove_folder(path):
    shutil.rmtree(path, ignore_errors=True)
