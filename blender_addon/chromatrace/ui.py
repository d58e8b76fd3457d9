# SPDX-License-Identifier: GPL-3.0-or-later
"""Panels: spectral settings in the Render, Material, Light and Object properties."""

import os
import textwrap

import bpy

from . import bands, materials, operators
from .properties import MODEL_ITEMS, analysis_of


_PLANNED_SAMPLES = {}  # band-plan file: (its modification time, its cycles_samples or None)


def planned_samples(path):
    """bands.planned_samples of a band-plan file, read again only when the file changes: panels are drawn often."""
    try:
        mtime = os.path.getmtime(path)
    except OSError:
        return None
    cached = _PLANNED_SAMPLES.get(path)
    if cached is None or cached[0] != mtime:
        cached = _PLANNED_SAMPLES[path] = (mtime, bands.planned_samples(path))
    return cached[1]


class _Panel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"


class CHROMATRACE_PT_render(_Panel, bpy.types.Panel):
    bl_label = "chromatrace Spectral"
    bl_context = "render"

    def draw(self, context):
        s = context.scene.chromatrace
        layout = self.layout
        layout.use_property_split = True
        # One button per row, so that their labels are whole at the panel's default width.
        layout.operator("chromatrace.render_spectral", icon="RENDER_STILL")
        layout.operator_menu_enum("chromatrace.apply_preset", "preset", text="Presets", icon="PRESET")
        layout.prop(s, "output_path")
        layout.operator("chromatrace.analyze_render", icon="GRAPH")
        layout.prop(s, "camera_curves")
        layout.prop(s, "camera_preset")
        analysis = analysis_of(context.window_manager, context.scene.name)
        if analysis:  # the command lines, to repeat the analysis by hand: fields, so that they can be copied
            box = layout.box()
            box.prop(analysis, "sensor", text="")
            box.prop(analysis, "analyze", text="")
        col = layout.column(heading="Plan")
        col.prop(s, "plan_target")
        col.operator("chromatrace.plan", icon="SORTTIME")
        if s.plan_summary and s.band_plan == "FILE":
            col.label(text=s.plan_summary)
        col = layout.column(heading="Bands")
        col.prop(s, "band_plan")
        if s.band_plan == "RANGE":
            col.prop(s, "bands_lo")
            col.prop(s, "bands_hi")
            col.prop(s, "bands_width")
        else:
            col.prop(s, "bands_file")
        col = layout.column(heading="Sampling")
        planned = planned_samples(bpy.path.abspath(s.bands_file)) if s.band_plan == "FILE" and s.bands_file else None
        row = col.row()
        row.enabled = not planned  # the plan's samples are rendered, not these
        row.prop(s, "samples")
        if planned:
            col.label(text=f"Samples per band group, from the plan: {', '.join(map(str, planned))}")
        col.prop(s, "max_bounces")
        col.prop(s, "seed")
        col.prop(s, "pixel_filter")
        col = layout.column(heading="Components")
        col.prop(s, "use_paths")
        col.prop(s, "use_lights")
        col.prop(s, "use_bounces")
        col.prop(s, "use_object_ids")
        layout.prop(s, "on_mixing_nodes")
        layout.prop(s, "on_world")
        layout.prop(s, "cache_dir")


class CHROMATRACE_PT_preflight(_Panel, bpy.types.Panel):
    """The pre-flight summary: what becomes a spectrum (batch.py --explain shows the same as JSON)."""

    bl_label = "Spectra Check"
    bl_context = "render"
    bl_parent_id = "CHROMATRACE_PT_render"

    def draw(self, context):
        from .operators import PREFLIGHT, PREFLIGHT_SETTINGS, checked_settings
        layout = self.layout
        layout.operator("chromatrace.preflight", icon="CHECKMARK")
        summary = PREFLIGHT.get(context.scene.name)
        if summary is None:
            return
        if PREFLIGHT_SETTINGS.get(context.scene.name) != checked_settings(context.scene):
            layout.label(text="The bands or the refusals changed since: check again", icon="INFO")
            return
        col = layout.column(align=True)
        col.label(text=f"{summary['renders']} Cycles renders" if summary["ok"] else "Refused: nothing renders")
        icons = {"exact": "CHECKMARK", "upsampled": "COLOR", "refused": "ERROR", "omitted": "ERROR"}
        region = getattr(context, "region", None)
        width = max(30, int(region.width / (7 * context.preferences.system.ui_scale))) if region else 60
        for owner in summary["owners"]:
            col.label(text=f"{owner['kind']} {owner['name']}: {owner['status']}", icon=icons.get(owner["status"], "DOT"))
            for reason in owner["reasons"]:  # in full: wrapped to the panel's width, never cut off
                for line in textwrap.wrap(reason, width):
                    col.label(text=f"    {line}")


class CHROMATRACE_UL_spectra(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index=0, flt_flag=0):
        layout.prop(item, "name", text="", emboss=False)
        layout.label(text=item.source.kind.title())


class CHROMATRACE_PT_spectra(_Panel, bpy.types.Panel):
    bl_label = "Spectrum Table"
    bl_context = "render"
    bl_parent_id = "CHROMATRACE_PT_render"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        s = context.scene.chromatrace
        row = self.layout.row()
        row.template_list("CHROMATRACE_UL_spectra", "", s, "spectra", s, "active_spectrum", rows=3)
        col = row.column(align=True)
        col.operator("chromatrace.spectrum_add", icon="ADD", text="")
        col.operator("chromatrace.spectrum_remove", icon="REMOVE", text="")
        if 0 <= s.active_spectrum < len(s.spectra):
            s.spectra[s.active_spectrum].source.draw(self.layout.column(), allow_rgb_current=False)


class CHROMATRACE_PT_material(_Panel, bpy.types.Panel):
    bl_label = "chromatrace Spectra"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return getattr(context, "material", None) is not None

    def draw(self, context):
        s = context.material.chromatrace
        layout = self.layout
        layout.use_property_split = True
        row = layout.row(align=True)
        label = next(name for key, name, _ in MODEL_ITEMS if key == s.model)
        row.operator_menu_enum("chromatrace.set_model", "model", text=f"Model: {label}")
        row.operator("chromatrace.build_material", text="", icon="FILE_REFRESH")
        if s.model != "NONE":
            box = layout.box()
            box.label(text={"DICHROMATIC": "Diffuse reflectance", "PRINCIPLED": "Base colour"}.get(s.model, "Reflectance"))
            s.reflectance.draw(box.column())
        if s.model == "DICHROMATIC":
            layout.prop(s, "specular")
            layout.prop(s, "lobe")
            layout.prop(s, "roughness" if s.lobe == "ggx" else "exponent")
        if s.model == "PRINCIPLED":
            from .blender_compat import principled_version
            layout.prop(s, "roughness")
            if principled_version() == 2:
                layout.prop(s, "ior")
                layout.prop(s, "specular_ior_level")
                layout.prop(s, "distribution")
            else:
                layout.prop(s, "principled_specular")
        layout.prop(s, "emissive")
        if s.emissive:
            box = layout.box()
            box.label(text="Emission (W·m⁻²·sr⁻¹·nm⁻¹ = spectrum × scale)")
            s.emission.draw(box.column())
            box.prop(s, "emission_scale")
            box.prop(s, "two_sided")


class CHROMATRACE_PT_light(_Panel, bpy.types.Panel):
    bl_label = "chromatrace Spectrum"
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        return isinstance(getattr(context, "light", None), bpy.types.Light)

    def draw(self, context):
        s = context.light.chromatrace
        layout = self.layout
        layout.use_property_split = True
        # Colours the light's nodes give it (Cycles multiplies them by the light's Color, whose spectrum follows).
        leaves = list(materials.walk_light(context.light).leaves.values())
        if leaves:
            box = layout.box()
            for leaf in leaves:
                what = (f"Blackbody {leaf.blackbody_k:g} K: Planck's law" if leaf.blackbody_k is not None
                        else "an image: upsampled texel by texel" if leaf.texture is not None
                        else f"{leaf.label}: upsampled from RGB")
                box.label(text=f"Nodes: {what}", icon="NODETREE")
            box.label(text="× the light's Color, below")
        s.emission.draw(layout.column(heading="Color" if leaves else ""))
        layout.prop(s, "emission_scale")


class CHROMATRACE_PT_object(_Panel, bpy.types.Panel):
    bl_label = "chromatrace"
    bl_context = "object"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH"

    def draw(self, context):
        ob = context.object
        layout = self.layout
        layout.use_property_split = True
        layout.prop(ob.chromatrace, "role")
        layout.prop(ob.chromatrace, "scene_name")
        layout.prop(ob, "pass_index", text="Object id")
        if ob.chromatrace.role == "LIGHT" and hasattr(ob, "lightgroup"):
            layout.prop(ob, "lightgroup", text="Light group")


_classes = (CHROMATRACE_PT_render, CHROMATRACE_PT_preflight, CHROMATRACE_UL_spectra, CHROMATRACE_PT_spectra, CHROMATRACE_PT_material,
            CHROMATRACE_PT_light, CHROMATRACE_PT_object)


def draw_render_buttons(self, context):
    """The two actions at the top of the Render tab, under the engine (RENDER_PT_context, the first panel): found
    without scrolling past the engine's dozen panels, where the settings panel sits. One per row, so that their
    labels are whole at the editor's default width."""
    col = self.layout.column(align=True)
    col.operator("chromatrace.render_spectral", icon="RENDER_STILL")
    col.operator("chromatrace.analyze_render", icon="GRAPH")


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.RENDER_PT_context.append(draw_render_buttons)


def unregister():
    bpy.types.RENDER_PT_context.remove(draw_render_buttons)
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
