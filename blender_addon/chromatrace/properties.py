# SPDX-License-Identifier: GPL-3.0-or-later
"""chromatrace's settings on Blender data: spectra of materials and lights, the scene's spectrum table and
render settings, what an import remembers for a lossless export, and the add-on preferences."""

import json
import os
import tempfile

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)

from . import cameras, defaults, spectra
from .floats import short_float

_KIND_ITEMS = [
    ("RGB", "From RGB", "Smooth spectrum upsampled from an RGB colour (Jakob and Hanika 2019)"),
    ("LIBRARY", "Library", "A spectrum from the project's library (scenes/spectra)"),
    ("CONSTANT", "Constant", "The same value at every wavelength"),
    ("CSV", "CSV file", "A column of a spectral CSV file (wavelength_nm first)"),
    ("ILLUMINANT", "CIE illuminant", "A CIE standard illuminant (relative, 100 at 560 nm)"),
    ("BLACKBODY", "Blackbody", "Planck's law at a temperature, normalised to 1 at its peak"),
    ("SAMPLES", "Samples", "Inline [wavelength_nm, value] pairs"),
    ("NAMED", "Scene spectrum", "A named spectrum of this scene's spectrum table"),
    ("TEXTURE", "Image texture", "An image whose every texel is upsampled from RGB (Jakob and Hanika 2019), "
                                 "mapped by the object's UV map"),
]
_TEXTURE_SPACE_ITEMS = [
    ("auto", "Auto", "Linear for float images (EXR, HDR), sRGB for integer ones (PNG, JPEG, TIFF)"),
    ("sRGB", "sRGB", "Texels are sRGB-encoded"),
    ("linear", "Linear", "Texels are linear sRGB"),
]
_ILLUMINANT_ITEMS = [(name, "D (any CCT)" if name == "D" else name, "") for name in spectra.ILLUMINANTS]


def _library_search(self, context, edit_text):
    return [entry for entry in spectra.library_entries() if edit_text.lower() in entry.lower()]


def _named_search(self, context, edit_text):
    return [s.name for s in context.scene.chromatrace.spectra if edit_text.lower() in s.name.lower()]


class CHROMATRACE_PG_spectrum(bpy.types.PropertyGroup):
    """Where a spectrum comes from: the scene format's spectrum sources (docs/scene-format.md)."""

    kind: EnumProperty(name="Spectrum", items=_KIND_ITEMS, default="RGB")
    spectrum_name: StringProperty(name="Name", description="Name in the scene's spectrum table", search=_named_search)
    library: StringProperty(name="Library", description="file.csv:column in scenes/spectra", search=_library_search)
    constant: FloatProperty(name="Value", min=0.0, default=0.5, soft_max=1.0)
    csv_path: StringProperty(name="CSV file", subtype="FILE_PATH")
    csv_column: StringProperty(name="Column", description="Value column (may be empty when the file has one)")
    extend: EnumProperty(name="Outside", items=[("zero", "Zero", "Zero outside the table"),
                                                ("clamp", "Clamp", "The end values outside the table")],
                         default="zero")
    rgb: FloatVectorProperty(name="Colour", subtype="COLOR", size=3, min=0.0, max=1.0, default=(0.8, 0.8, 0.8))
    use_current_colour: BoolProperty(
        name="Use current colour", default=True,
        description="Upsample the colour the node tree or light currently has, instead of the colour here")
    illuminant: EnumProperty(name="Illuminant", items=_ILLUMINANT_ITEMS, default="D65")
    cct_k: FloatProperty(name="CCT (K)", min=4000.0, max=25000.0, default=6504.0)
    blackbody_k: FloatProperty(name="Temperature (K)", min=100.0, max=100000.0, default=3200.0)
    samples_json: StringProperty(name="Samples", description="JSON list of [wavelength_nm, value] pairs",
                                 default="[[400, 0.5], [700, 0.5]]")
    texture_path: StringProperty(name="Image", subtype="FILE_PATH")
    texture_colour_space: EnumProperty(name="Colour space", items=_TEXTURE_SPACE_ITEMS, default="auto")
    texture_scale: FloatProperty(name="Scale", min=0.0, default=1.0, soft_max=10.0)
    # The colour Blender shows for a spectrum that is neither RGB nor a texture (in its viewport and a plain render):
    # chromatrace's linear sRGB of it (scene-bands: a reflectance's under D65, an emission's relative to D65), kept
    # with the source it was computed for; a source changed since shows the fallback, not a stale colour.
    preview: FloatVectorProperty(name="Preview colour", size=3, min=0.0, default=(0.8, 0.8, 0.8), options={"HIDDEN"})
    preview_of: StringProperty(options={"HIDDEN"})

    def preview_colour(self, fallback):
        """The preview colour, or `fallback` where none was computed for the source as it is now."""
        if not self.preview_of:
            return fallback
        try:
            current = json.dumps(self.to_json(), sort_keys=True)
        except (spectra.SourceError, ValueError):
            return fallback
        return tuple(self.preview) if current == self.preview_of else fallback

    def set_preview(self, colour):
        self.preview = [max(0.0, float(c)) for c in colour]
        self.preview_of = json.dumps(self.to_json(), sort_keys=True)

    def values(self):
        return {"name": self.spectrum_name, "library": self.library, "constant": self.constant,
                "csv_path": bpy.path.abspath(self.csv_path), "csv_column": self.csv_column, "extend": self.extend,
                "rgb": tuple(self.rgb), "use_current_colour": self.use_current_colour,
                "illuminant": self.illuminant, "cct_k": self.cct_k, "blackbody_k": self.blackbody_k,
                "samples": json.loads(self.samples_json) if self.kind == "SAMPLES" else [],
                "texture_path": bpy.path.abspath(self.texture_path), "texture_colour_space": self.texture_colour_space,
                "texture_scale": self.texture_scale}

    def to_json(self, current_rgb=None, base_dir=None):
        """The scene-format source object (or table name)."""
        return spectra.source_json(self.kind, self.values(), current_rgb, base_dir)

    def set_from_json(self, source, scene_dir):
        kind, values = spectra.source_values(source, scene_dir)
        self.kind = kind
        if kind == "NAMED":
            self.spectrum_name = values["name"]
        elif kind == "CONSTANT":
            self.constant = values["constant"]
        elif kind == "CSV":
            self.csv_path, self.csv_column, self.extend = values["csv_path"], values["csv_column"], values["extend"]
        elif kind == "RGB":
            self.rgb, self.use_current_colour = values["rgb"], False
        elif kind == "ILLUMINANT":
            self.illuminant, self.cct_k = values["illuminant"], values["cct_k"]
        elif kind == "BLACKBODY":
            self.blackbody_k = values["blackbody_k"]
        elif kind == "SAMPLES":
            self.samples_json, self.extend = json.dumps(values["samples"]), values["extend"]
        elif kind == "TEXTURE":
            self.texture_path = values["texture_path"]
            self.texture_colour_space = values["texture_colour_space"]
            self.texture_scale = values["texture_scale"]

    def draw(self, layout, allow_rgb_current=True):
        layout.prop(self, "kind")
        k = self.kind
        if k == "NAMED":
            layout.prop(self, "spectrum_name")
        elif k == "LIBRARY":
            layout.prop(self, "library")
        elif k == "CONSTANT":
            layout.prop(self, "constant")
        elif k == "CSV":
            layout.prop(self, "csv_path")
            layout.prop(self, "csv_column")
            layout.prop(self, "extend")
        elif k == "RGB":
            if allow_rgb_current:
                layout.prop(self, "use_current_colour")
            if not (allow_rgb_current and self.use_current_colour):
                layout.prop(self, "rgb")
        elif k == "ILLUMINANT":
            layout.prop(self, "illuminant")
            if self.illuminant == "D":
                layout.prop(self, "cct_k")
        elif k == "BLACKBODY":
            layout.prop(self, "blackbody_k")
        elif k == "SAMPLES":
            layout.prop(self, "samples_json")
            layout.prop(self, "extend")
        elif k == "TEXTURE":
            layout.prop(self, "texture_path")
            layout.prop(self, "texture_colour_space")
            layout.prop(self, "texture_scale")


class CHROMATRACE_PG_named_spectrum(bpy.types.PropertyGroup):
    # `name` (the table key) is PropertyGroup's own.
    source: PointerProperty(type=CHROMATRACE_PG_spectrum)


def _rebuild_nodes(self, context):
    from . import materials
    material = self.id_data
    if self.model != "NODES":
        materials.build_material_nodes(material)


MODEL_ITEMS = [
    ("NODES", "Node tree", "Keep the material's own nodes; its colour inputs get the spectra"),
    ("LAMBERT", "Lambert", "f = R(λ)/π: a Diffuse BSDF"),
    ("DICHROMATIC", "Dichromatic", "Lambertian body plus a spectrally flat GGX interface lobe (Shafer's model)"),
    ("MIRROR", "Mirror", "A perfect mirror scaled by R(λ)"),
    ("PRINCIPLED", "Principled", "Blender's Principled BSDF as an opaque dielectric: base colour R(λ) under a "
                                 "spectrally flat interface"),
    ("NONE", "No reflection", "Reflects nothing (an emitter only)"),
]


class CHROMATRACE_PG_material(bpy.types.PropertyGroup):
    model: EnumProperty(name="Model", items=MODEL_ITEMS, default="NODES", update=_rebuild_nodes,
                        description="Choosing a model other than Node tree rebuilds the material's nodes")
    reflectance: PointerProperty(type=CHROMATRACE_PG_spectrum, name="Reflectance")
    specular: FloatProperty(name="Specular", min=0.0, max=1.0, default=0.05, update=_rebuild_nodes,
                            description="Weight k_s of the interface lobe")
    lobe: EnumProperty(name="Lobe", items=[("ggx", "GGX", "GGX as Cycles' Glossy BSDF (alpha = roughness²)"),
                                           ("phong", "Phong", "Modified Phong (reference tracer only)")],
                       default="ggx", update=_rebuild_nodes)
    roughness: FloatProperty(name="Roughness", min=0.0, max=1.0, default=0.15, update=_rebuild_nodes)
    exponent: FloatProperty(name="Exponent", min=0.0, default=50.0)
    ior: FloatProperty(name="IOR", min=1.0, max=10.0, default=1.5, update=_rebuild_nodes,
                       description="The Principled BSDF's IOR (Blender 4.0 and later)")
    specular_ior_level: FloatProperty(name="Specular IOR Level", min=0.0, max=1.0, default=0.5,
                                      update=_rebuild_nodes,
                                      description="The Principled BSDF's Specular IOR Level (Blender 4.0 and later)")
    principled_specular: FloatProperty(name="Specular", min=0.0, max=1.0, default=0.5, update=_rebuild_nodes,
                                       description="The Principled BSDF's Specular (Blender 3.x): F0 = 0.08 × it")
    distribution: EnumProperty(name="Distribution", items=[
        ("MULTI_GGX", "Multiscatter GGX", "GGX with Cycles' energy compensation (Blender 4.0 and later)"),
        ("GGX", "GGX", "Single-scatter GGX")], default="MULTI_GGX", update=_rebuild_nodes)
    emissive: BoolProperty(name="Emits light", default=False, update=_rebuild_nodes)
    emission: PointerProperty(type=CHROMATRACE_PG_spectrum, name="Emission")
    emission_scale: FloatProperty(name="Scale", min=0.0, default=1.0, update=_rebuild_nodes,
                                  description="Radiance = spectrum × scale, in W·m⁻²·sr⁻¹·nm⁻¹")
    two_sided: BoolProperty(name="Two-sided", default=False, update=_rebuild_nodes,
                            description="Emit on both sides (one-sided emitters emit along the face normal)")
    scene_name: StringProperty(name="Scene name", description="The material's name in the scene file")


class CHROMATRACE_PG_object(bpy.types.PropertyGroup):
    role: EnumProperty(name="Role", items=[("OBJECT", "Object", ""), ("LIGHT", "Light", "An emitting quad or sphere")],
                       default="OBJECT")
    scene_name: StringProperty(name="Scene name")
    shape_json: StringProperty(name="Shape", description="The analytic shape this mesh was tessellated from")
    geometry_digest: StringProperty(description="Digest of mesh and transform when imported")
    light_group: StringProperty(name="Light group")
    light_material: StringProperty(name="Reflects as", description="Scene material the light also reflects with")


class CHROMATRACE_PG_light(bpy.types.PropertyGroup):
    emission: PointerProperty(type=CHROMATRACE_PG_spectrum, name="Emission")
    emission_scale: FloatProperty(name="Scale", min=0.0, default=1.0,
                                  description="The spectrum times this replaces the light's colour; its power stays")


class CHROMATRACE_PG_camera(bpy.types.PropertyGroup):
    scene_json: StringProperty(description="The camera as imported")
    digest: StringProperty(description="Digest of the camera when imported")


class CHROMATRACE_PG_scene(bpy.types.PropertyGroup):
    spectra: CollectionProperty(type=CHROMATRACE_PG_named_spectrum)
    active_spectrum: IntProperty()
    band_plan: EnumProperty(name="Band plan", items=[("RANGE", "Range", "Uniform bands lo:hi:width"),
                                                     ("FILE", "File", "A band plan file (chromatrace-bands/1)")],
                            default="RANGE")
    bands_lo: FloatProperty(name="From (nm)", default=defaults.band_range()[0], min=200.0, max=2000.0)
    bands_hi: FloatProperty(name="To (nm)", default=defaults.band_range()[1], min=200.0, max=2000.0)
    bands_width: FloatProperty(name="Width (nm)", default=defaults.band_range()[2], min=0.1, max=1000.0)
    bands_file: StringProperty(name="Plan file", subtype="FILE_PATH")
    samples: IntProperty(name="Samples", min=1, default=defaults.RENDER["samples"])
    max_bounces: IntProperty(name="Max bounces", min=0, default=defaults.RENDER["max_bounces"],
                             description="Scattering events per path: 0 emitters only, 1 direct light, >= 2 global")
    seed: IntProperty(name="Seed", min=0, default=defaults.RENDER["seed"])
    pixel_filter: EnumProperty(name="Pixel filter", items=[("box", "Box", "Integrate over the pixel"),
                                                           ("point", "Point", "The pixel centre (nearly: a Gaussian 0.01 pixel wide)")],
                               default=defaults.RENDER["pixel_filter"])
    spectral_mode: StringProperty(default=defaults.RENDER["spectral_mode"],
                                  description="Kept for export: Cycles always renders bands")
    tessellation_segments: IntProperty(name="Segments", min=0, default=0, description="0: the format's default")
    tessellation_rings: IntProperty(name="Rings", min=0, default=0, description="0: the format's default")
    use_paths: BoolProperty(name="Path types", default=True,
                            description="Emission, diffuse and glossy, direct and indirect")
    use_lights: BoolProperty(name="Light groups", default=True, description="One component per light group")
    use_bounces: BoolProperty(name="Bounce orders", default=False,
                              description="One component per number of bounces: max bounces renders per band group")
    use_object_ids: BoolProperty(name="Object ids", default=True)
    on_mixing_nodes: EnumProperty(
        name="Mixing nodes",  # whole at the panel's default width ("Channel-mixing nodes" was cut)
        items=[("REFUSE", "Refuse", "Do not render; list the nodes"),
               ("ONE_BAND", "One band per render", "Render each band alone (3× slower)")],
        default="REFUSE")
    on_world: EnumProperty(
        name="World light",
        items=[("REFUSE", "Refuse", "Do not render when the world's light cannot be a spectrum (a Sky Texture, or nodes that mix its channels); an HDRI can"),
               ("OMIT", "Omit", "Render without the world's light; a warning is printed and noted in the file")],
        default="REFUSE")
    output_path: StringProperty(name="Output", subtype="FILE_PATH", default="//spectral.exr")
    camera_preset: EnumProperty(name="Sensor", items=cameras.sensor_items(), default="canon_eos_5d_mkiii",
                                description="The sensor that sees the render when it is analysed: pixel, noise and ADC")
    camera_curves: EnumProperty(name="Camera", items=cameras.curve_items(), default="canon_eos_5d_mkiii",
                                description="The camera whose spectral response sees the render when it is analysed")
    cache_dir: StringProperty(name="Cache", subtype="DIR_PATH",
                              description="Band groups already rendered, for resuming (empty: the user cache)")
    plan_target: FloatProperty(name="Target ΔE00", min=0.05, soft_max=5.0, default=1.0, precision=2,
                               description="The mean colour error (CIEDE2000) Plan aims the bands, bounces and samples at")
    plan_summary: StringProperty(description="What the last Plan chose and predicts")
    scene_name: StringProperty(name="Name")
    description: StringProperty(name="Description")
    source_file: StringProperty(description="The scene file this scene was imported from")
    source_json: StringProperty(description="The imported scene document")

    def output_file(self):
        """The output's absolute path. A path relative to the .blend ("//name.exr", the default) has no folder to be
        relative to while the file was never saved: it then goes to Blender's temporary folder (Preferences > File
        Paths > Temporary Files, else the system's), never to the folder Blender happened to start in."""
        path = self.output_path or "//spectral.exr"
        if path.startswith("//") and not bpy.data.filepath:
            folder = getattr(getattr(bpy.context, "preferences", None), "filepaths", None)
            folder = bpy.path.abspath(folder.temporary_directory) if folder and folder.temporary_directory else ""
            return os.path.join(os.path.abspath(folder or tempfile.gettempdir()), path[2:])
        return os.path.abspath(bpy.path.abspath(path))

    def bands_argument(self):
        if self.band_plan == "FILE":
            return None
        return ":".join(f"{short_float(v)}" for v in (self.bands_lo, self.bands_hi, self.bands_width))

    def families(self):
        return {f for f, on in (("paths", self.use_paths), ("lights", self.use_lights),
                                ("bounces", self.use_bounces)) if on}


class CHROMATRACE_preferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    executable: StringProperty(name="chromatrace executable", subtype="FILE_PATH",
                               description="Empty: $CHROMATRACE_EXE, the installed one, or chromatrace on PATH")

    def draw(self, context):
        self.layout.prop(self, "executable")


def executable_preference(context):
    addon = context.preferences.addons.get(__package__)
    return bpy.path.abspath(addon.preferences.executable) if addon and addon.preferences else ""


class CHROMATRACE_PG_analysis(bpy.types.PropertyGroup):
    """The command lines of a scene's last Analyze Histogram, as text fields a person can select and copy (labels
    cannot be copied). Kept on the window manager: never saved into the .blend."""

    scene: StringProperty()
    sensor: StringProperty(name="Camera command", description="The chromatrace sensor command that was run")
    analyze: StringProperty(name="Analyzer command", description="The chromatrace analyze command that was run")


_classes = (CHROMATRACE_PG_spectrum, CHROMATRACE_PG_named_spectrum, CHROMATRACE_PG_material, CHROMATRACE_PG_object,
            CHROMATRACE_PG_light, CHROMATRACE_PG_camera, CHROMATRACE_PG_scene, CHROMATRACE_PG_analysis,
            CHROMATRACE_preferences)
_owners = ((bpy.types.Material, CHROMATRACE_PG_material), (bpy.types.Object, CHROMATRACE_PG_object),
           (bpy.types.Light, CHROMATRACE_PG_light), (bpy.types.Camera, CHROMATRACE_PG_camera),
           (bpy.types.Scene, CHROMATRACE_PG_scene))


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    for owner, group in _owners:
        owner.chromatrace = PointerProperty(type=group)
    bpy.types.WindowManager.chromatrace_analyses = CollectionProperty(type=CHROMATRACE_PG_analysis)


def analysis_of(window_manager, scene_name, create=False):
    """The window manager's record of a scene's last analysis (made when `create`), or None."""
    for entry in window_manager.chromatrace_analyses:
        if entry.scene == scene_name:
            return entry
    if not create:
        return None
    entry = window_manager.chromatrace_analyses.add()
    entry.scene = scene_name
    return entry


def unregister():
    del bpy.types.WindowManager.chromatrace_analyses
    for owner, _group in reversed(_owners):
        del owner.chromatrace
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
