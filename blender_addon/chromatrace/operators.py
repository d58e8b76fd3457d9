# SPDX-License-Identifier: GPL-3.0-or-later
"""Operators: the spectral render (modal, with progress and Esc to cancel), scene import and export, and
small helpers for materials and the spectrum table."""

import os
import re
import shlex
import shutil
import tempfile
import webbrowser

import bpy
from bpy.props import EnumProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import blender_compat, materials, scene_export, scene_import, spectral_render, tool
from .errors import BadInput
from .properties import MODEL_ITEMS, analysis_of, executable_preference


def _tool(context):
    return tool.Tool(tool.find_executable(executable_preference(context)))


# The batch's and the command's option names, as the panel names the fields that set them.
_PANEL_WORDS = ((r"--bands-file\b", "Bands: Plan file"), (r"--bands\b", "Bands (From, To, Width)"),
                (r"--samples\b", "Sampling: Samples"), (r"--max-bounces\b", "Sampling: Max bounces"),
                (r"--seed\b", "Sampling: Seed"))


def panel_words(message):
    """An error message with the options it names said as the panel's fields (an artist sees no --bands)."""
    for option, field in _PANEL_WORDS:
        message = re.sub(option, field, message)
    return message


# Per scene name: what the last Render Spectral said: its settings' warnings (settings_warnings), then the
# render's own (the world left out, one band per render); one line each.
RENDER_WARNINGS = {}


def settings_warnings(scene, chromatrace_tool, request):
    """What the scene's render settings leave out, said before rendering as the batch says it for a scene file
    (`chromatrace check-scene --renderer cycles`): the scene written as a scene file (scene_export) and judged
    with its band plan, samples, bounce limit and resolution. Only for a scene imported from a scene file, whose
    lights and materials the check reads; [] for others. One line each."""
    if not scene.chromatrace.source_file:
        return []
    work = tempfile.mkdtemp(prefix="chromatrace-check-")
    try:
        path = os.path.join(work, "scene.json")
        scene_export.export_scene(scene, path, chromatrace_tool, log=lambda message: None)
        return chromatrace_tool.render_warnings(path, bands_file=request.bands_file)
    except (BadInput, RuntimeError) as e:
        return [f"the render settings were not checked: {e}"]
    finally:
        shutil.rmtree(work, ignore_errors=True)


# Scene names with a spectral render running modally, and those whose render Esc has cancelled in a window other
# than the one it runs in (a modal operator hears only its own window's events).
RENDERING = set()
ESCAPED = set()


class CHROMATRACE_OT_render_escape(bpy.types.Operator):
    """Esc in this window cancels the spectral render running in another (the preview's window has the focus)"""

    bl_idname = "chromatrace.render_escape"
    bl_label = "Cancel Spectral Render"
    bl_options = {"INTERNAL"}

    scene: StringProperty()

    def invoke(self, context, event):
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if self.scene not in RENDERING:
            return {"FINISHED", "PASS_THROUGH"}
        if event.type == "ESC" and event.value == "PRESS":
            ESCAPED.add(self.scene)
            return {"FINISHED"}
        return {"PASS_THROUGH"}


class CHROMATRACE_OT_render_spectral(bpy.types.Operator):
    """Render the scene spectrally with Cycles (bands multiplexed three per render) into a spectral EXR"""

    bl_idname = "chromatrace.render_spectral"
    bl_label = "Render Spectral"

    _steps = None
    _timer = None

    def _start(self, context):
        self._messages = []
        request = spectral_render.Request.from_scene(context.scene, log=self._messages.append)
        chromatrace_tool = _tool(context)
        warnings = settings_warnings(context.scene, chromatrace_tool, request)
        RENDER_WARNINGS[context.scene.name] = warnings
        for warning in warnings:
            self.report({"WARNING"}, warning)
        self._render = spectral_render.SpectralRender(context.scene, request, chromatrace_tool)
        return self._render

    def _done(self, context):
        """Reports the output (and its preview) and shows the preview in an Image Editor."""
        output = context.scene.chromatrace.output_file()
        preview = self._render.preview
        # What the render itself warned of (the world left out, one band per render), as the batch prints it.
        for message in self._messages:
            if message.startswith("warning: "):
                RENDER_WARNINGS.setdefault(context.scene.name, []).append(message[len("warning: "):])
                self.report({"WARNING"}, message[len("warning: "):])
        self.report({"INFO"}, f"wrote {output}" + (f"; preview {preview}" if preview else ""))
        if preview and not bpy.app.background:
            show_image(context, preview)

    def execute(self, context):  # synchronous: background mode and scripts
        try:
            self._start(context).run()
        except BadInput as e:
            self.report({"ERROR"}, panel_words(str(e)))
            return {"CANCELLED"}
        self._done(context)
        return {"FINISHED"}

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        try:
            self._steps = self._start(context).steps()
        except BadInput as e:
            self.report({"ERROR"}, panel_words(str(e)))
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.05, window=context.window)
        wm.modal_handler_add(self)
        RENDERING.add(context.scene.name)
        ESCAPED.discard(context.scene.name)
        for window in wm.windows:  # Esc in any other window (a preview's) cancels too
            if window != context.window:
                with context.temp_override(window=window):
                    bpy.ops.chromatrace.render_escape("INVOKE_DEFAULT", scene=context.scene.name)
        wm.progress_begin(0, 1)
        context.workspace.status_text_set("chromatrace: preparing the spectral render (Esc cancels)")
        return {"RUNNING_MODAL"}

    def _finish(self, context):
        RENDERING.discard(context.scene.name)
        ESCAPED.discard(context.scene.name)
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def modal(self, context, event):
        if event.type == "ESC" or context.scene.name in ESCAPED:
            self._steps.close()  # the render's finally restores every setting
            self._finish(context)
            self.report({"WARNING"}, "spectral render cancelled; finished band groups stay in the cache")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            done, total, message = next(self._steps)
        except StopIteration:
            self._finish(context)
            self._done(context)
            return {"FINISHED"}
        except BadInput as e:
            self._finish(context)
            self.report({"ERROR"}, panel_words(str(e)))
            return {"CANCELLED"}
        except Exception as e:
            self._finish(context)
            self.report({"ERROR"}, f"spectral render failed: {e}")
            return {"CANCELLED"}
        context.window_manager.progress_update(done / total)
        context.workspace.status_text_set(f"chromatrace: {message} (Esc cancels)")
        return {"RUNNING_MODAL"}


# The last analysis per scene: the command lines run (shown in the panel, to repeat by hand) and the report.
ANALYSES = {}


class CHROMATRACE_OT_analyze_render(bpy.types.Operator):
    """See the spectral render through a camera and analyse its colour histograms; open the report in the browser"""

    bl_idname = "chromatrace.analyze_render"
    bl_label = "Analyze Histogram"

    def execute(self, context):
        s = context.scene.chromatrace
        render = s.output_file()
        if not os.path.isfile(render):
            self.report({"ERROR"}, f"no spectral render at {render}: Render Spectral first")
            return {"CANCELLED"}
        folder = os.path.splitext(render)[0] + "_analysis"
        chromatrace_tool = _tool(context)
        commands, report = chromatrace_tool.analysis_commands(render, folder, s.camera_preset, s.camera_curves)
        os.makedirs(folder, exist_ok=True)
        try:
            chromatrace_tool.run_commands(commands)
        except (BadInput, RuntimeError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        ANALYSES[context.scene.name] = {"commands": [" ".join(map(shlex.quote, argv)) for argv in commands],
                                        "report": report}
        entry = analysis_of(context.window_manager, context.scene.name, create=True)
        entry.sensor, entry.analyze = ANALYSES[context.scene.name]["commands"]
        for line in ANALYSES[context.scene.name]["commands"]:
            self.report({"INFO"}, line)
        self.report({"INFO"}, f"report {report}")
        if not bpy.app.background:
            webbrowser.open("file://" + report)
        return {"FINISHED"}


def show_image(context, path):
    """Loads an image file (again, if it is loaded already) and shows it in an Image Editor: one of the window's,
    or the render view Blender opens (Preferences > Interface > Render In)."""
    image = bpy.data.images.load(path, check_existing=True)
    image.reload()
    editors = [a for a in context.window.screen.areas if a.type == "IMAGE_EDITOR"]
    if not editors:
        bpy.ops.render.view_show("INVOKE_DEFAULT")
        for window in context.window_manager.windows:
            editors += [a for a in window.screen.areas if a.type == "IMAGE_EDITOR"]
    for area in editors[:1]:
        area.spaces.active.image = image
        area.tag_redraw()
    return image


# The last pre-flight summary per scene (kept here, not in the scene, so that checking changes nothing).
PREFLIGHT = {}


# Per scene name: the settings the last Check Spectra ran with (checked_settings), so that the panel does not show
# a summary those settings no longer give.
PREFLIGHT_SETTINGS = {}


def checked_settings(scene):
    """The settings a Check Spectra summary depends on besides the scene's colours: the band plan (how many Cycles
    renders) and what is refused or left out."""
    s = scene.chromatrace
    return (s.band_plan, s.bands_argument(), s.bands_file if s.band_plan == "FILE" else "", s.on_mixing_nodes,
            s.on_world)


class CHROMATRACE_OT_preflight(bpy.types.Operator):
    """Check which colours become spectra: every material, light and the world exact, upsampled or refused"""

    bl_idname = "chromatrace.preflight"
    bl_label = "Check Spectra"

    def execute(self, context):
        request = spectral_render.Request.from_scene(context.scene, log=lambda m: None)
        try:
            summary = spectral_render.SpectralRender(context.scene, request, _tool(context)).preflight()
        except BadInput as e:
            self.report({"ERROR"}, panel_words(str(e)))
            return {"CANCELLED"}
        PREFLIGHT[context.scene.name] = summary
        PREFLIGHT_SETTINGS[context.scene.name] = checked_settings(context.scene)
        refused = [o for o in summary["owners"] if o["status"] == "refused"]
        if refused:
            self.report({"WARNING"}, "; ".join(o["reasons"][0] if o["reasons"] else o["name"] for o in refused[:3]))
        else:
            self.report({"INFO"}, f"{summary['renders']} Cycles renders; nothing refused")
        return {"FINISHED"}


class CHROMATRACE_OT_import_scene(bpy.types.Operator, ImportHelper):
    """Import a chromatrace scene (chromatrace-scene/1) into the current scene"""

    bl_idname = "chromatrace.import_scene"
    bl_label = "Import chromatrace Scene"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})
    ggx_masking: EnumProperty(
        name="GGX masking",
        items=[("SCENE", "Scene's", "Refuse a GGX material whose masking this Cycles does not have"),
               ("CYCLES", "Cycles'", "Give GGX materials this Cycles' masking, with a warning naming each one")],
        default="SCENE")

    def execute(self, context):
        try:
            scene_import.import_scene(self.filepath, context.scene, _tool(context),
                                      lambda m: self.report({"INFO"}, m), ggx_masking=self.ggx_masking.lower(),
                                      warn=lambda m: self.report({"WARNING"}, m.removeprefix("warning: ")),
                                      masking_option="Import's \"GGX masking: Cycles'\" option")
        except BadInput as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return {"FINISHED"}


class CHROMATRACE_OT_export_scene(bpy.types.Operator, ExportHelper):
    """Export the scene as a chromatrace scene (chromatrace-scene/1), meshes as PLY files beside it"""

    bl_idname = "chromatrace.export_scene"
    bl_label = "Export chromatrace Scene"
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    def execute(self, context):
        try:
            scene_export.export_scene(context.scene, self.filepath, _tool(context),
                                      lambda m: self.report({"INFO"}, m))
        except BadInput as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return {"FINISHED"}


class CHROMATRACE_OT_build_material(bpy.types.Operator):
    """Rebuild the material's nodes from its chromatrace model"""

    bl_idname = "chromatrace.build_material"
    bl_label = "Rebuild Nodes"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        m = getattr(context, "material", None)
        return m is not None and m.chromatrace.model != "NODES"

    def execute(self, context):
        materials.build_material_nodes(context.material)
        return {"FINISHED"}


def current_colour(material):
    """The colour the material shows now: its first upsampled reflectance colour (a Principled or Diffuse BSDF's
    base colour, through groups and Mix nodes), else its viewport colour."""
    walk = materials.walk_material(material) if material.chromatrace.model == "NODES" else None
    if walk is not None:
        for leaf in walk.leaves.values():
            if leaf.texture is None and leaf.blackbody_k is None and leaf.role == "reflectance":
                return tuple(min(1.0, max(0.0, c)) for c in leaf.rgb)
    node = material.node_tree.nodes.get(materials.REFLECTANCE_NODE) if material.node_tree else None
    if node is not None and node.bl_idname == "ShaderNodeRGB":
        return tuple(node.outputs[0].default_value[:3])
    return tuple(material.diffuse_color[:3])


class CHROMATRACE_OT_set_model(bpy.types.Operator):
    """Choose the material's model: its nodes are rebuilt for that BRDF, keeping the colour it shows now"""

    bl_idname = "chromatrace.set_model"
    bl_label = "Set Model"
    bl_options = {"REGISTER", "UNDO"}
    model: bpy.props.EnumProperty(name="Model", items=MODEL_ITEMS)

    @classmethod
    def poll(cls, context):
        return getattr(context, "material", None) is not None

    def invoke(self, context, event):
        material = context.material
        own = material.chromatrace.model == "NODES" and blender_compat.uses_nodes(material) \
            and len(material.node_tree.nodes) > 0
        if own and self.model != "NODES":
            return context.window_manager.invoke_props_dialog(self, width=420)
        return self.execute(context)

    def draw(self, context):
        material = context.material
        colour = ", ".join(f"{c:.3f}" for c in current_colour(material))
        column = self.layout.column()
        column.label(text=f"Replace the {len(material.node_tree.nodes)} nodes of \"{material.name}\"")
        column.label(text=f"by the {self.model.lower()} model's? Its colour ({colour}) is kept.")
        column.label(text="Undo (Ctrl Z) brings the nodes back.")

    def execute(self, context):
        material = context.material
        s = material.chromatrace
        if self.model != "NODES" and s.model == "NODES" and s.reflectance.kind == "RGB":
            s.reflectance.rgb = current_colour(material)
        s.model = self.model  # rebuilds the nodes (properties._rebuild_nodes)
        return {"FINISHED"}


# Band plans and quality: (label, description, settings of the scene's chromatrace properties).
PRESETS = {
    "PREVIEW": ("Quick preview", "6 bands of 50 nm over 400-700 nm (2 Cycles renders), 16 samples, 4 bounces",
                {"band_plan": "RANGE", "bands_lo": 400.0, "bands_hi": 700.0, "bands_width": 50.0, "samples": 16,
                 "max_bounces": 4}),
    "PAPER": ("The paper's settings", "40 bands of 10 nm over 380-780 nm (14 Cycles renders), 256 samples, "
              "8 bounces, as scenes/paper/box.json", {"band_plan": "RANGE", "bands_lo": 380.0, "bands_hi": 780.0,
                                                      "bands_width": 10.0, "samples": 256, "max_bounces": 8}),
    "FINAL": ("Final", "Planned for a mean ΔE00 of 1: the fewest bands, bounces and samples per band group that the "
              "plan predicts there (Plan, with the target set to 1)", {"plan_target": 1.0}),
}


class CHROMATRACE_OT_plan(bpy.types.Operator):
    """Plan the bands, bounces and each band group's samples for the target mean ΔE00: chromatrace plan on the scene
    as Export writes it, with two small pilot renders that measure this Cycles' noise; the plan is kept in the
    render cache and becomes the scene's band plan"""

    bl_idname = "chromatrace.plan"
    bl_label = "Plan"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        from . import plan_scene, planning
        scene = context.scene
        s = scene.chromatrace
        work = planning.planning_folder()
        try:
            planned = plan_scene.plan_open_scene(scene, _tool(context), s.plan_target, work)
            kept = plan_scene.keep(planned, bpy.path.abspath(s.cache_dir) if s.cache_dir else None,
                                   s.scene_name or scene.name)
        except (BadInput, RuntimeError) as e:
            self.report({"ERROR"}, f"Plan: {panel_words(str(e))}")
            return {"CANCELLED"}
        finally:
            planning.remove_folder(work)
        s.band_plan = "FILE"
        s.bands_file = kept
        s.max_bounces = planned.max_bounces
        s.plan_summary = (f"{planned.report['settings']['band_count']} bands in {len(planned.samples)} Cycles renders, "
                          f"max {planned.max_bounces} bounces; predicted mean ΔE00 "
                          f"{planned.report['prediction']['cycles']['mean_de00']:.2f} "
                          f"({'-'.join(f'{x:.2f}' for x in planned.report['prediction']['cycles']['mean_de00_range'])})"
                          + (f", worst object {worst['name']} {worst['mean_de00']:.2f}"
                             if (worst := planned.worst_object()) else ""))
        self.report({"INFO"}, planned.summary())
        for note in planned.notes:
            self.report({"WARNING"}, f"Plan: {note}")
        return {"FINISHED"}


class CHROMATRACE_OT_apply_preset(bpy.types.Operator):
    """Set the band plan and the quality from a preset"""

    bl_idname = "chromatrace.apply_preset"
    bl_label = "Spectral Render Preset"
    bl_options = {"REGISTER", "UNDO"}
    preset: bpy.props.EnumProperty(name="Preset", items=[(k, v[0], v[1]) for k, v in PRESETS.items()])

    def execute(self, context):
        s = context.scene.chromatrace
        for key, value in PRESETS[self.preset][2].items():
            setattr(s, key, value)
        if self.preset == "FINAL":
            return bpy.ops.chromatrace.plan()
        return {"FINISHED"}


class CHROMATRACE_OT_spectrum_add(bpy.types.Operator):
    """Add a named spectrum to the scene's spectrum table"""

    bl_idname = "chromatrace.spectrum_add"
    bl_label = "Add Spectrum"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        s = context.scene.chromatrace
        entry = s.spectra.add()
        entry.name = f"spectrum{len(s.spectra)}"
        s.active_spectrum = len(s.spectra) - 1
        return {"FINISHED"}


class CHROMATRACE_OT_spectrum_remove(bpy.types.Operator):
    """Remove the selected spectrum from the scene's spectrum table"""

    bl_idname = "chromatrace.spectrum_remove"
    bl_label = "Remove Spectrum"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return len(context.scene.chromatrace.spectra) > 0

    def execute(self, context):
        s = context.scene.chromatrace
        s.spectra.remove(s.active_spectrum)
        s.active_spectrum = max(0, min(s.active_spectrum, len(s.spectra) - 1))
        return {"FINISHED"}


def _menu_import(self, context):
    self.layout.operator(CHROMATRACE_OT_import_scene.bl_idname, text="chromatrace scene (.json)")


def _menu_export(self, context):
    self.layout.operator(CHROMATRACE_OT_export_scene.bl_idname, text="chromatrace scene (.json)")


_classes = (CHROMATRACE_OT_render_escape, CHROMATRACE_OT_render_spectral, CHROMATRACE_OT_analyze_render, CHROMATRACE_OT_preflight, CHROMATRACE_OT_import_scene, CHROMATRACE_OT_export_scene,
            CHROMATRACE_OT_build_material, CHROMATRACE_OT_set_model, CHROMATRACE_OT_plan, CHROMATRACE_OT_apply_preset, CHROMATRACE_OT_spectrum_add, CHROMATRACE_OT_spectrum_remove)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
