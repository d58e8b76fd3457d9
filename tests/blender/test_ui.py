# SPDX-License-Identifier: Apache-2.0
"""Inside Blender: the add-on's panels, operators and property updates, as an artist uses them.

Panels are drawn into a stand-in layout that checks every property and operator they name exists (Blender
draws nothing in background mode); the operators run from Python as the UI calls them (the spectral render
synchronously, as it does in background mode); choosing a material model builds its nodes; the add-on
unregisters and registers again cleanly.
"""

import json
import os
import shutil
import sys
import tempfile

import bpy

sys.path.insert(0, os.path.join(os.environ["CHROMATRACE_SOURCE_DIR"], "tests", "blender"))
from harness import SOURCE, TOOL, chromatrace, expect, failures, finish, scene_file  # noqa: E402,F401
from chromatrace import ui  # noqa: E402


class Layout:
    """Records what a panel draws and checks that it exists."""

    use_property_split = False

    def __init__(self):
        self.drawn = []

    def prop(self, data, name, **kwargs):
        if name not in data.bl_rna.properties:
            failures.append(f"panel draws unknown property {type(data).__name__}.{name}")
        self.drawn.append(name)

    def operator(self, idname, **kwargs):
        module, name = idname.split(".")
        if not hasattr(getattr(bpy.ops, module), name):
            failures.append(f"panel draws unknown operator {idname}")
        self.drawn.append(idname)

    def operator_menu_enum(self, idname, prop, **kwargs):
        self.operator(idname)
        module, name = idname.split(".")
        op = getattr(getattr(bpy.ops, module), name, None)
        if op is None or prop not in op.get_rna_type().properties:
            failures.append(f"panel draws a menu of unknown property {idname}.{prop}")

    def template_list(self, *args, **kwargs):
        self.drawn.append("list")

    def label(self, **kwargs):
        self.drawn.append(("label", kwargs.get("text", "")))

    def row(self, **kwargs):
        return self

    column = box = row


class Context:
    def __init__(self, **values):
        self.__dict__.update(values)


def draw(panel, context):
    holder = Context(layout=Layout())
    if hasattr(panel, "poll") and not panel.poll(context):
        failures.append(f"{panel.__name__}.poll is false")
        return []
    panel.draw(holder, context)
    return holder.layout.drawn


scene = bpy.context.scene
cube = bpy.data.objects["Cube"]
material = cube.material_slots[0].material
light = bpy.data.objects["Light"].data
context = Context(scene=scene, material=material, light=light, object=cube, preferences=bpy.context.preferences,
                  window_manager=bpy.context.window_manager)

drawn = draw(ui.CHROMATRACE_PT_render, context)
if "chromatrace.render_spectral" not in drawn or "bands_width" not in drawn:
    failures.append(f"render panel lacks the render button or the band plan: {drawn}")
# The two actions sit at the top of the Render tab, in the engine's panel (RENDER_PT_context), one per row: they were
# only in the chromatrace panel, under a dozen Cycles panels (about 40 wheel notches down).
if ui.draw_render_buttons not in getattr(bpy.types.RENDER_PT_context, "_dyn_ui_initialize")():
    failures.append("the Render tab's first panel does not draw the chromatrace buttons")
holder = Context(layout=Layout())
ui.draw_render_buttons(holder, context)
if holder.layout.drawn != ["chromatrace.render_spectral", "chromatrace.analyze_render"]:
    failures.append(f"the Render tab's first panel draws {holder.layout.drawn}")
scene.chromatrace.band_plan = "FILE"
draw(ui.CHROMATRACE_PT_render, context)
# A plan that gives each band group its samples: the panel says they are the plan's.
with tempfile.TemporaryDirectory() as plan_dir:
    plan_file = os.path.join(plan_dir, "plan.json")
    with open(plan_file, "w") as f:
        json.dump({"format": "chromatrace-bands/1", "edges_nm": [400, 450, 500, 550, 600, 650, 700],
                   "cycles_samples": [256, 64]}, f)
    scene.chromatrace.bands_file = plan_file
    said = [d[1] for d in draw(ui.CHROMATRACE_PT_render, context) if isinstance(d, tuple)]
    if "Samples per band group, from the plan: 256, 64" not in said:
        failures.append(f"the panel does not say the plan gives the samples: {said}")
    scene.chromatrace.bands_file = ""
scene.chromatrace.band_plan = "RANGE"
for kind in ("RGB", "LIBRARY", "CONSTANT", "CSV", "ILLUMINANT", "BLACKBODY", "SAMPLES", "NAMED"):
    material.chromatrace.reflectance.kind = kind
    material.chromatrace.emission.kind = kind
    light.chromatrace.emission.kind = kind
    material.chromatrace.emissive = True
    draw(ui.CHROMATRACE_PT_material, context)
    draw(ui.CHROMATRACE_PT_light, context)
light.chromatrace.emission.kind = material.chromatrace.emission.kind = "RGB"
# A light whose colour a Blackbody node gives: the Light panel says so (it showed only "From RGB").
glow = bpy.data.lights.new("glow", "AREA")
glow.use_nodes = True
blackbody = glow.node_tree.nodes.new("ShaderNodeBlackbody")
blackbody.inputs["Temperature"].default_value = 5500
glow.node_tree.links.new(blackbody.outputs["Color"], glow.node_tree.nodes["Emission"].inputs["Color"])
said = [text for kind, text in [d for d in draw(ui.CHROMATRACE_PT_light, Context(light=glow)) if isinstance(d, tuple)]]
if not any("Blackbody 5500 K" in text for text in said):
    failures.append(f"the Light panel of a Blackbody-node light does not say so: {said}")
bpy.data.lights.remove(glow)
draw(ui.CHROMATRACE_PT_object, context)
bpy.ops.chromatrace.spectrum_add()
if len(scene.chromatrace.spectra) != 1:
    failures.append("spectrum_add added nothing")
draw(ui.CHROMATRACE_PT_spectra, context)
bpy.ops.chromatrace.spectrum_remove()

# The World light tooltip says what cannot be a spectrum, and not an HDRI, which the add-on upsamples.
refuse = scene.chromatrace.bl_rna.properties["on_world"].enum_items["REFUSE"].description
if "(an HDRI)" in refuse or "Sky Texture" not in refuse:
    failures.append(f"the World light tooltip says an HDRI cannot be a spectrum: {refuse}")

# Choosing a model builds its nodes; the spectral inputs are the ct_ nodes.
material.chromatrace.emissive = False
material.chromatrace.reflectance.kind = "LIBRARY"
material.chromatrace.reflectance.library = "synthetic_reflectances.csv:yellow"
material.chromatrace.model = "DICHROMATIC"
nodes = material.node_tree.nodes
if not all(n in nodes for n in ("ct_reflectance", "ct_diffuse", "ct_glossy", "ct_output")):
    failures.append(f"dichromatic model built {list(nodes.keys())}")
material.chromatrace.roughness = 0.4
if abs(nodes["ct_glossy"].inputs["Roughness"].default_value - 0.4) > 1e-6:
    failures.append("changing the roughness did not update the nodes")
with bpy.context.temp_override(material=material):
    if bpy.ops.chromatrace.build_material() != {"FINISHED"}:
        failures.append("build_material did not run")

# Set Model keeps the colour the material shows: a Principled BSDF's red base colour becomes the Lambert
# model's reflectance colour (not grey).
red = bpy.data.materials.new("red plastic")
red.use_nodes = True
red.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.05, 0.02, 1.0)
with bpy.context.temp_override(material=red):
    if bpy.ops.chromatrace.set_model(model="LAMBERT") != {"FINISHED"}:
        failures.append("set_model did not run")
kept = tuple(red.node_tree.nodes["ct_reflectance"].outputs[0].default_value[:3])
if max(abs(a - b) for a, b in zip(kept, (0.8, 0.05, 0.02))) > 1e-6 or red.chromatrace.model != "LAMBERT":
    failures.append(f"Set Model did not keep the red: {kept}, model {red.chromatrace.model}")

# Presets set the band plan and the quality.
if bpy.ops.chromatrace.apply_preset(preset="PAPER") != {"FINISHED"}:
    failures.append("apply_preset did not run")
sc = scene.chromatrace
if (sc.bands_argument(), sc.samples, sc.max_bounces) != ("380:780:10", 256, 8):
    failures.append(f"the paper preset set {sc.bands_argument()}, {sc.samples} samples, {sc.max_bounces} bounces")

# File > Import of a scene whose GGX masking this Cycles lacks (the paper box as written for the tracer, on Blender
# 4.0 and later; a height-correlated one on 3.x): refused before anything is added, the file named and the
# import's own option offered (not a batch flag); with that option it imports, each material named in a warning.
from chromatrace import scene_import  # noqa: E402
from chromatrace.errors import BadInput  # noqa: E402
other = (os.path.join(SOURCE, "scenes", "paper", "box.json") if bpy.app.version >= (4, 0, 0)
         else os.path.join(SOURCE, "tests", "data", "scenes", "ggx_height_correlated.json"))
held = (len(bpy.data.objects), len(bpy.data.materials), len(bpy.data.collections))
try:  # an operator that reports an error raises it when called from Python
    failures.append(f"Import of {other} (the other GGX masking) was not refused: {bpy.ops.chromatrace.import_scene(filepath=other)}")
except RuntimeError as e:
    if f"{other}: materials." not in str(e):
        failures.append(f"Import's refusal does not name the file: {e}")
try:
    scene_import.import_scene(other, bpy.context.scene, TOOL, masking_option="Import's \"GGX masking: Cycles'\" option")
    failures.append(f"import_scene of {other} did not refuse the other GGX masking")
except BadInput as e:
    if not str(e).startswith(other + ": materials.") or "GGX masking: Cycles'" not in str(e) or "--ggx-masking" in str(e):
        failures.append(f"the masking refusal does not name the file and the import's option: {e}")
if (len(bpy.data.objects), len(bpy.data.materials), len(bpy.data.collections)) != held:
    failures.append("a refused import left objects, materials or collections behind")
if bpy.ops.chromatrace.import_scene(filepath=other, ggx_masking="CYCLES") != {"FINISHED"}:
    failures.append(f"Import of {other} with GGX masking: Cycles' did not finish")
for ob in [o for o in bpy.data.objects if o.users_collection and o.users_collection[0].name != "Collection"]:
    bpy.data.objects.remove(ob)

# Import, render (synchronously in background mode) and export through the operators.
work = tempfile.mkdtemp(prefix="chromatrace-ui-")
bpy.ops.chromatrace.import_scene(filepath=scene_file("paper", "box.json"))
s = scene.chromatrace
s.samples, s.max_bounces, s.bands_lo, s.bands_hi, s.bands_width = 2, 2, 400, 700, 100
scene.render.resolution_x = scene.render.resolution_y = 16
s.output_path = os.path.join(work, "ui.exr")
s.cache_dir = os.path.join(work, "cache")
if bpy.ops.chromatrace.render_spectral() != {"FINISHED"} or not os.path.isfile(s.output_path):
    failures.append("Render Spectral did not write its file")
if not os.path.isfile(os.path.join(work, "ui.preview.png")):
    failures.append("Render Spectral wrote no preview (ui.preview.png) beside its file")
# Before it renders, Render Spectral says what these settings leave out (2 bounces, 2 samples, 100 nm bands), as
# the batch does, with fixes Cycles has (no continuous mode).
from chromatrace.operators import RENDER_WARNINGS  # noqa: E402
said = RENDER_WARNINGS.get(scene.name, [])
if (not any(w.startswith("render.max_bounces 2 leaves") for w in said)
        or not any(w.startswith("render.samples 2 gives Cycles Monte Carlo noise") for w in said)
        or not any("bands of 100 nm give its" in w and "chromatrace plan" in w for w in said)
        or any("--spectral-mode" in w for w in said)):
    failures.append(f"Render Spectral did not say what its settings leave out: {said}")
# From the render to the histogram: Analyze Histogram runs the camera and the analyzer on the render and keeps the
# two command lines it ran (shown in the panel, so the analysis can be repeated by hand); the report is written.
from chromatrace.operators import ANALYSES  # noqa: E402
# The camera is chosen by name from every camera chromatrace ships (a list, not free text to mistype).
curves = [item.identifier for item in s.bl_rna.properties["camera_curves"].enum_items]
if len(curves) != 18 or "nikon_d850" not in curves or "cie1931" not in curves:
    failures.append(f"the camera list is not the 17 shipped cameras and the CIE observer: {curves}")
s.camera_curves = "nikon_d850"
if bpy.ops.chromatrace.analyze_render() != {"FINISHED"}:
    failures.append("Analyze Histogram failed")
analysis = ANALYSES.get(scene.name, {})
commands = analysis.get("commands", [])
if len(commands) != 2 or " sensor " not in commands[0] or " analyze " not in commands[1] \
        or s.output_path not in commands[0] or "--preset canon_eos_5d_mkiii --camera nikon_d850" not in commands[0]:
    failures.append(f"Analyze Histogram kept the wrong command lines: {commands}")
# The panel shows them as fields, which can be selected and copied (labels could not), kept out of the .blend.
from chromatrace.properties import analysis_of  # noqa: E402
kept = analysis_of(bpy.context.window_manager, scene.name)
if kept is None or [kept.sensor, kept.analyze] != commands:
    failures.append(f"the window manager does not hold the analysis's command lines: {kept and [kept.sensor, kept.analyze]}")
drawn = draw(ui.CHROMATRACE_PT_render, Context(scene=scene, window_manager=bpy.context.window_manager))
if drawn.count("sensor") != 1 or drawn.count("analyze") != 1:
    failures.append(f"the render panel does not show the command lines as fields: {drawn}")
report = analysis.get("report", "")
if not report.startswith(os.path.join(work, "ui_analysis")) or not os.path.isfile(report):
    failures.append(f"Analyze Histogram wrote no report beside the render: {report}")
if os.path.isfile(os.path.join(os.path.dirname(report), "analysis.json")):
    import json  # noqa: E402
    with open(os.path.join(os.path.dirname(report), "analysis.json")) as f:
        if not json.load(f).get("regions"):
            failures.append("the analysis of the render found no regions")
else:
    failures.append("Analyze Histogram wrote no analysis.json")
# Plan: the bands, bounces and each band group's samples for the target, from the scene as Export writes it and two
# small pilots of this Cycles; the plan is kept in the render cache (plans/<scene name>.json and its report) and
# becomes the scene's band plan, its bounce limit the scene's, and the panel says what it predicts (Samples greyed
# out under the plan's). The Final preset plans for a mean ΔE00 of 1.
from chromatrace import bands as band_plans  # noqa: E402
s.plan_target = 2.0
# The default file's point light is a Blender light: written as the sphere of its radius (scene_export), it is
# planned with the rest.
if bpy.ops.chromatrace.plan() != {"FINISHED"}:
    failures.append("Plan did not finish")
kept = os.path.join(work, "cache", "plans", f"{s.scene_name}.json")
report_file = os.path.join(work, "cache", "plans", f"{s.scene_name}.report.json")
if (s.band_plan, bpy.path.abspath(s.bands_file)) != ("FILE", kept) or not os.path.isfile(report_file):
    failures.append(f"Plan did not keep its plan in the cache and set it: {s.band_plan} {s.bands_file}")
else:
    with open(report_file) as f:
        planned_report = json.load(f)
    planned = band_plans.planned_samples(kept)
    if (planned_report["target_de00"] != 2.0 or not planned
            or planned != planned_report["prediction"]["cycles"]["samples_per_band_group"]
            or s.max_bounces != planned_report["settings"]["max_bounces"]
            or not s.plan_summary.startswith(f"{planned_report['settings']['band_count']} bands in {len(planned)} Cycles renders")):
        failures.append(f"Plan set other settings than its report: {s.plan_summary}, {planned}, {s.max_bounces}")
    drawn = draw(ui.CHROMATRACE_PT_render, Context(scene=scene, window_manager=bpy.context.window_manager))
    if ("label", s.plan_summary) not in drawn or not any(isinstance(d, tuple) and d[1].startswith("Samples per band group, from the plan") for d in drawn):
        failures.append(f"the render panel does not show the plan: {drawn}")
    if bpy.ops.chromatrace.apply_preset(preset="FINAL") != {"FINISHED"}:
        failures.append("the Final preset did not plan")
    with open(report_file) as f:
        if json.load(f)["target_de00"] != 1.0 or s.plan_target != 1.0:
            failures.append("the Final preset did not plan for a mean ΔE00 of 1")
s.band_plan, s.samples, s.max_bounces = "RANGE", 2, 2
# A sky texture cannot be a spectrum: with World light: Omit the render goes on without it and says so.
sky_world = bpy.data.worlds.new("Sky")
sky_world.use_nodes = True
sky = sky_world.node_tree.nodes.new("ShaderNodeTexSky")
sky_world.node_tree.links.new(sky.outputs["Color"], sky_world.node_tree.nodes["Background"].inputs["Color"])
dark_world = scene.world
scene.world, s.on_world = sky_world, "OMIT"
s.output_path = os.path.join(work, "sky.exr")
if bpy.ops.chromatrace.render_spectral() != {"FINISHED"}:
    failures.append("Render Spectral with the world omitted did not finish")
if not any(w.startswith("rendered without the world's light") for w in RENDER_WARNINGS.get(scene.name, [])):
    failures.append(f"Render Spectral did not say it left the world out: {RENDER_WARNINGS.get(scene.name)}")
scene.world, s.on_world = dark_world, "REFUSE"
# An error names the panel's fields, not the batch's options (it said "--bands: … not a whole number of 70 nm
# bands" where the panel's field is Width (nm)).
s.bands_width = 70
try:
    bpy.ops.chromatrace.render_spectral()
    failures.append("Render Spectral with 70 nm bands over 400-700 nm did not refuse")
except RuntimeError as e:
    if "--bands" in str(e) or "Bands (From, To, Width)" not in str(e):
        failures.append(f"the refusal of the band width names the batch's option, not the panel's fields: {e}")
s.bands_width = 100
# A file never saved has no folder for "//": the default output goes to Blender's temporary folder, named in full,
# not to the folder Blender was started in.
if bpy.data.filepath:
    failures.append(f"the test's file was saved ({bpy.data.filepath}): the unsaved case is not tested")
temporary = os.path.join(work, "blender temporary")
os.makedirs(temporary)
bpy.context.preferences.filepaths.temporary_directory = temporary
s.output_path = "//unsaved.exr"
started_in = os.getcwd()
if s.output_file() != os.path.join(temporary, "unsaved.exr"):
    failures.append(f"the unsaved file's output is {s.output_file()}, not in the temporary folder {temporary}")
if bpy.ops.chromatrace.render_spectral() != {"FINISHED"} or not os.path.isfile(os.path.join(temporary, "unsaved.exr")):
    failures.append(f"Render Spectral of an unsaved file wrote nothing to {temporary}")
if os.path.exists(os.path.join(started_in, "unsaved.exr")):
    os.remove(os.path.join(started_in, "unsaved.exr"))
    failures.append(f"Render Spectral of an unsaved file wrote into the folder Blender started in ({started_in})")
if bpy.ops.chromatrace.preflight() != {"FINISHED"}:
    failures.append("Check Spectra did not finish")
drawn = draw(ui.CHROMATRACE_PT_preflight, context)
if "chromatrace.preflight" not in drawn:
    failures.append(f"the spectra check panel lacks its button: {drawn}")
# After a band change the summary's count of Cycles renders is no longer true: the panel says to check again.
from chromatrace.operators import PREFLIGHT  # noqa: E402
renders = f"{PREFLIGHT[scene.name]['renders']} Cycles renders"
if ("label", renders) not in drawn:
    failures.append(f"the spectra check panel does not show its summary ({renders}): {drawn}")
s.bands_width /= 2
drawn = draw(ui.CHROMATRACE_PT_preflight, context)
if ("label", renders) in drawn or not any(isinstance(d, tuple) and "check again" in d[1] for d in drawn):
    failures.append(f"after a band change the spectra check panel still shows {renders}: {drawn}")
s.bands_width *= 2
if [o["status"] for o in PREFLIGHT[scene.name]["owners"] if o["kind"] == "world"] != ["dark"]:
    failures.append(f"the imported scene has no environment, so its world must be dark: {PREFLIGHT[scene.name]['owners']}")
scene.world = bpy.data.worlds["World"]  # the factory world again, a grey background: exact
bpy.ops.chromatrace.preflight()
if [o["status"] for o in PREFLIGHT[scene.name]["owners"] if o["kind"] == "world"] != ["exact"]:
    failures.append(f"the factory world (a grey background) is not exact: {PREFLIGHT[scene.name]['owners']}")
if bpy.ops.chromatrace.export_scene(filepath=os.path.join(work, "exported.json")) != {"FINISHED"}:
    failures.append("export did not finish")

chromatrace.unregister()
chromatrace.register()
if not hasattr(bpy.types.Scene, "chromatrace") or not hasattr(bpy.ops.chromatrace, "render_spectral"):
    failures.append("register after unregister did not restore the add-on")

shutil.rmtree(work, ignore_errors=True)
finish("ui")
