"""The spectral render: Cycles renders three bands at a time, chromatrace assembles the spectral EXR.

    render = SpectralRender(scene, Request.from_scene(scene, output="out.exr"), Tool(executable))
    for done, total, message in render.steps():   # one step per Cycles render; render.run() does them all
        ...

What it guarantees:
- Everything it changes (colours, Cycles and colour-management settings, passes, light groups, object
  indices, the world's strength) goes through a Journal and is put back in a `finally`, whether the render
  succeeds, fails or is cancelled (closing the generator). It never saves the .blend.
- Each finished Cycles render is read back (`chromatrace info`: to the end of its pixel data, at the render's
  size, with the channels assemble takes from it) and only then moved into a cache directory keyed by a hash of
  everything that decides its pixels (cache.py); one that does not read (a full disk) fails the run and is
  removed. A run that was killed resumes with the renders still missing; a cached render that does not read
  back is rendered again, with a warning. The final EXR is written atomically by `chromatrace assemble`.
"""

import hashlib
import json
import os
import re
import shutil
import sys
import tempfile
import time

import bpy

from . import VERSION, blender_compat, cache, components, cycles_setup, defaults, manifest, materials, node_rules
from .bands import band_groups, describe_band_range, group_colour
from .errors import BadInput
from .geometry_digest import update_with_mesh
from .journal import Journal
from .spectra import SourceError, rgb_for_upsampling

WORLD_HINT = ("; to render without the world's light choose World light: Omit in the render settings "
              "(batch.py --on-world omit)")

# Tests set this to a callable f(event, **info); an exception it raises aborts the render at that point.
TEST_HOOK = None

_GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES", "POINTCLOUD", "VOLUME"}


class RenderPlan:
    """What _prepare decided: the objects and materials rendered, their spectral inputs and band averages, the
    band groups, light groups, components, render variants, passes and object ids, and the cache key."""

    def __init__(self, **fields):
        self.key = None
        self.__dict__.update(fields)


def _used_materials(objects):
    """The materials of the objects' slots, each once, in slot order."""
    used = []
    for ob in objects:
        for slot in getattr(ob, "material_slots", []):
            if slot.material is not None and slot.material not in used:
                used.append(slot.material)
    return used


class Request:
    """What to render: the scene's chromatrace settings, optionally overridden (batch.py's options)."""

    def __init__(self, **values):
        self.samples = defaults.RENDER["samples"]
        self.max_bounces = defaults.RENDER["max_bounces"]
        self.seed = defaults.RENDER["seed"]
        self.bands = defaults.RENDER["bands"]
        self.bands_file = None
        self.families = {"paths", "lights"}
        self.object_ids = True
        self.resolution = None
        self.point_filter = False
        self.on_mixing_nodes = "refuse"  # or "one-band"
        self.on_world = "refuse"  # a lit world whose colours cannot be spectra (an HDRI): or "omit"
        self.bands_per_render = 3
        self.device = "CPU"  # Cycles' device: CPU, or a GPU backend (cycles_setup.select_device)
        self.output = None
        self.cache_root = None
        self.keep_cache = False
        self.only_group = None  # render only this band group into the cache, no ids, no assembly (batch --band-group)
        self.only_variant = None  # with only_group: only this render variant (bounce limit) of it (--bounce-limit)
        self.log = _stderr_log
        for key, value in values.items():
            if not hasattr(self, key):
                raise TypeError(f"unknown request setting {key}")
            setattr(self, key, value)

    @classmethod
    def from_scene(cls, scene, **overrides):
        s = scene.chromatrace
        values = dict(samples=s.samples, max_bounces=s.max_bounces, seed=s.seed, bands=s.bands_argument(),
                      bands_file=bpy.path.abspath(s.bands_file) if s.band_plan == "FILE" else None,
                      families=s.families(), object_ids=s.use_object_ids, point_filter=s.pixel_filter == "point",
                      on_mixing_nodes="one-band" if s.on_mixing_nodes == "ONE_BAND" else "refuse",
                      on_world="omit" if s.on_world == "OMIT" else "refuse",
                      output=bpy.path.abspath(s.output_path),
                      cache_root=bpy.path.abspath(s.cache_dir) if s.cache_dir else None)
        values.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**values)


def _cycles_preferences():
    return bpy.context.preferences.addons["cycles"].preferences


def _stderr_log(message):
    print(f"chromatrace: {message}", file=sys.stderr, flush=True)


def _group_name(name):
    return re.sub(r"[^A-Za-z0-9_-]", "_", name) or "group"


def _rna_plain(struct):
    values = {}
    if struct is None:
        return values
    for prop in struct.bl_rna.properties:
        if prop.type in ("BOOLEAN", "INT", "FLOAT", "ENUM", "STRING") and prop.identifier != "rna_type":
            value = getattr(struct, prop.identifier)
            values[prop.identifier] = materials._plain(value)
    return values


# Settings that cannot change a final render's pixels (the viewport's, baking, stamps and output naming, which
# Cycles writes as metadata, debugging), by name prefix: left out of the cache key, so that changing one does not
# render again.
_NOT_PIXELS = ("name", "preview_", "debug_", "bake", "use_bake", "use_stamp", "stamp_", "metadata_", "threads",
               "use_lock_interface", "use_auto_tile", "tile_size", "use_placeholder", "use_overwrite", "frame_map",
               "fps", "file_extension", "is_movie_format", "views_format", "sequencer_gl_preview", "use_render_cache",
               "has_multiple_engines", "simplify_gpencil", "line_thickness")
# An object's (and a light object's) visibility to each kind of ray.
_RAY_VISIBILITY = ("visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission",
                   "visible_volume_scatter", "visible_shadow", "is_holdout", "is_shadow_catcher",
                   "show_instancer_for_render")
# The view layer's filter: which kinds of things it renders.
_VIEW_LAYER_FILTER = ("use_solid", "use_sky", "use_ao", "use_strand", "use_volumes", "use_motion_blur")


def _pixel_settings(struct, fixed=()):
    """The plain settings of an RNA struct that may change a render's pixels: all but those that cannot
    (_NOT_PIXELS) and those the render sets itself (`fixed`)."""
    return {k: v for k, v in _rna_plain(struct).items() if k not in fixed and not k.startswith(_NOT_PIXELS)}


class SpectralRender:
    def __init__(self, scene, request, tool):
        self.scene = scene
        self.request = request
        self.tool = tool
        self.rendered = 0  # Cycles renders made by this run (not found in the cache)
        self.cached = 0
        self.cache_dir = None
        self.preview = None  # the picture a person would see, written beside the output when the render ends

    def run(self):
        for _ in self.steps():
            pass

    # ---- preparation ---------------------------------------------------------------------------------

    def _view_layer(self):
        for layer in self.scene.view_layers:
            if layer.use:
                return layer
        raise BadInput(f"scene \"{self.scene.name}\": no view layer is enabled for rendering")

    def _objects(self, view_layer):
        return [ob for ob in view_layer.objects if not ob.hide_render and (ob.type in _GEOMETRY_TYPES or ob.type == "LIGHT")]

    def _scene_parts(self):
        """(view layer, objects, used materials, light objects (one per light datablock))."""
        scene = self.scene
        view_layer = self._view_layer()
        if scene.camera is None:
            raise BadInput(f"scene \"{scene.name}\": no camera")
        objects = self._objects(view_layer)
        lights, seen = [], set()
        for ob in objects:
            if ob.type == "LIGHT" and ob.data.as_pointer() not in seen:
                seen.add(ob.data.as_pointer())
                lights.append(ob)
        return view_layer, objects, _used_materials(objects), lights

    def _walks(self, used, lights):
        """The colour walk (colour_walk.Walk) of every material and light used, and of the world, by (kind, name)."""
        walks = {}
        world = self.scene.world
        if world is not None:
            walks[("world", world.name)] = materials.walk_world(world)
        for ob in lights:
            walk = materials.walk_light(ob.data)
            walk.name = ob.name
            for issue in walk.issues:
                issue["material"] = ob.name
            walks[("light", ob.name)] = walk
        for material in used:
            walks[("material", material.name)] = materials.walk_material(material)
        return walks

    def _world_state(self, walks):
        """What the render does with the world: {"status": "none" | "dark" | "lit" | "omitted" | "refused",
        "issues": [...]}. A world is lit when a background or emission it reaches has a colour and a strength;
        lit worlds are converted, or refused when a colour cannot be (an HDRI), unless the request omits them."""
        world = self.scene.world
        if world is None:
            return {"status": "none", "issues": [], "walk": None}
        walk = walks[("world", world.name)]
        lit = bool(walk.leaves) or bool(walk.issues) or any(
            node.bl_idname in ("ShaderNodeBackground", "ShaderNodeEmission") and node.inputs["Color"].is_linked and
            walk.constant_scalar((), node.inputs["Strength"]) != 0.0 for _path, node in walk.shaders)
        if not lit:
            return {"status": "dark", "issues": [], "walk": walk}
        hard = [i for i in walk.issues if not i["fallback"]]
        if hard:
            for issue in hard:
                if not issue["reason"].endswith(WORLD_HINT):
                    issue["reason"] += WORLD_HINT
            if self.request.on_world == "omit":
                return {"status": "omitted", "issues": walk.issues, "walk": walk}
            return {"status": "refused", "issues": walk.issues, "walk": walk}
        return {"status": "lit", "issues": walk.issues, "walk": walk}

    def _node_issues(self, used, walks, world):
        """(hard issues, channel-mixing issues): the world's first (its message says how to proceed), then the
        lights' and the materials'."""
        issues = []
        if world["status"] in ("lit", "refused"):
            issues += world["issues"]
        for (kind, _name), walk in walks.items():
            if kind != "world":
                issues += walk.issues
        for material in used:
            s = material.chromatrace
            if s.model == "DICHROMATIC" and s.lobe == "phong":
                issues.append({"kind": "material", "material": material.name, "node": "ct_glossy", "socket": None,
                               "reason": "the phong lobe has no Cycles counterpart (only the reference tracer "
                                         "renders it); use ggx", "fallback": False})
        return [i for i in issues if not i["fallback"]], [i for i in issues if i["fallback"]]

    def _check_nodes(self, used, walks, world):
        """Refuses (BadInput) what cannot be rendered; returns the channel-mixing issues that need one band per
        render (empty: none)."""
        hard, mixing = self._node_issues(used, walks, world)
        if hard:
            raise BadInput(f"cannot render spectrally: {node_rules.summarise(hard)}")
        if mixing and self.request.on_mixing_nodes != "one-band":
            raise BadInput(f"nodes mix colour channels: {node_rules.summarise(mixing)} "
                           "(choose one band per render to render anyway)")
        if world["status"] == "omitted":
            self.request.log(f"warning: {self._world_warning(world)}")
        return mixing

    def _world_warning(self, world):
        reasons = "; ".join(node_rules.describe_issue(i) for i in world["issues"] if not i["fallback"])
        return f"rendered without the world's light (strength 0), as asked: {reasons}"

    def _resolve(self, spectrum_settings, current_rgb, what, texture_allowed=False):
        """The source JSON of a spectrum setting, table names resolved; a texture only where texture_allowed."""
        try:
            source = spectrum_settings.to_json(current_rgb=current_rgb)
        except (SourceError, ValueError) as e:
            raise BadInput(f"{what}: {e}") from None
        if _is_texture(source) and not texture_allowed:
            raise BadInput(f"{what}: an image texture can be a material's reflectance here; for a textured emitter "
                           "use an Image Texture node in the material's own nodes (Model: Node tree)")
        if isinstance(source, str):
            entry = self.scene.chromatrace.spectra.get(source)
            if entry is None:
                raise BadInput(f"{what}: unknown spectrum \"{source}\" (not in the scene's spectrum table)")
            source = entry.source.to_json()
            if isinstance(source, str):
                raise BadInput(f"{what}: spectrum table entry \"{entry.name}\" refers to another name")
            if _is_texture(source):
                raise BadInput(f"{what}: spectrum table entry \"{entry.name}\" is an image texture (a texture is "
                               "given where it is used, not in the table)")
        return source

    @staticmethod
    def _node_source(spectral_input, what):
        """(source, scale) of a colour a node tree fixes: a Blackbody node's Planck's law, a grey interface
        colour, or the colour upsampled (an emission colour above 1 from its normalised colour)."""
        rgb = spectral_input.current_rgb
        if spectral_input.source is not None:
            return spectral_input.source, 1.0
        if spectral_input.role == "interface":
            return {"constant": rgb[0]}, 1.0
        if spectral_input.role == "reflectance":
            if max(rgb) > 1.0 or min(rgb) < 0.0:
                raise BadInput(f"{what}: colour {tuple(round(c, 4) for c in rgb)} of {spectral_input.label} "
                               "is outside [0, 1], so it is not a reflectance")
            return _rgb_source({"rgb": [max(0.0, float(c)) for c in rgb]}), 1.0
        rgb, factor = rgb_for_upsampling(rgb)
        return _rgb_source({"rgb": rgb}), factor

    def _input_source(self, material, spectral_input):
        """(source JSON, scale) of one spectral colour input of a material."""
        s = material.chromatrace
        what = f"material \"{material.name}\""
        rgb = spectral_input.current_rgb
        if spectral_input.source is not None:
            return spectral_input.source, 1.0
        if spectral_input.role == "interface":
            return {"constant": rgb[0]}, 1.0
        if spectral_input.role == "reflectance":
            settings = s.reflectance
            if settings.kind == "RGB" and settings.use_current_colour and (max(rgb) > 1.0 or min(rgb) < 0.0):
                raise BadInput(f"{what}: colour {tuple(round(c, 4) for c in rgb)} of {spectral_input.label} "
                               "is outside [0, 1], so it is not a reflectance")
            source = _rgb_source(self._resolve(settings, rgb, what, texture_allowed=True))
            if _is_texture(source) != (spectral_input.attribute == "image"):
                node_is = "is not an Image Texture node" if _is_texture(source) else "is an Image Texture node"
                raise BadInput(f"{what}: its reflectance is {'an image texture' if _is_texture(source) else 'a spectrum'}"
                               f" but its node {materials.REFLECTANCE_NODE} {node_is}; choose the model again to "
                               "rebuild the nodes")
            return source, 1.0
        if spectral_input.managed or s.emissive:
            settings = s.emission
            scale = 1.0 if spectral_input.managed else s.emission_scale
            if settings.kind == "RGB" and settings.use_current_colour:
                rgb, factor = rgb_for_upsampling(rgb)
                return _rgb_source(self._resolve(settings, rgb, what)), scale * factor
            return self._resolve(settings, None, what), scale
        rgb, factor = rgb_for_upsampling(rgb)
        return _rgb_source({"rgb": rgb}), factor

    def _owner_inputs(self, kind, thing, walk):
        """[(SpectralInput, source, scale)] of one material, light object or world; BadInput when one fails."""
        found = []
        if kind == "material":
            for spectral_input in materials.spectral_inputs(thing, walk):
                found.append((spectral_input, *self._input_source(thing, spectral_input)))
            return found
        what = f"{kind} \"{thing.name}\""
        if kind == "light":
            light = thing.data
            settings = light.chromatrace
            if settings.emission.kind == "RGB" and settings.emission.use_current_colour:
                rgb, factor = rgb_for_upsampling(tuple(light.color))
                source, scale = _rgb_source(self._resolve(settings.emission, rgb, what)), settings.emission_scale * factor
            else:
                source, scale = self._resolve(settings.emission, None, what), settings.emission_scale
            found.append((materials.SpectralInput(light, "color", "emission", tuple(light.color), None, what, False),
                          source, scale))
        for spectral_input in materials.leaf_inputs(walk):
            found.append((spectral_input, *self._node_source(spectral_input, what)))
        return found

    def _prepare(self, work_dir):
        """The plan of the renders: what is rendered, with which band values, into which components."""
        request = self.request
        view_layer, objects, used, lights = self._scene_parts()
        walks = self._walks(used, lights)
        world = self._world_state(walks)
        mixing = self._check_nodes(used, walks, world)
        replicate = bool(mixing)
        keys, inputs, emitters = self._spectral_inputs(used, lights, walks, world)
        bands = self._band_averages(work_dir, keys, inputs)
        edges = bands["bands"]["edges_nm"]
        per_render = 1 if replicate else request.bands_per_render
        if replicate:
            count = len(edges) - 1
            request.log(f"warning: one band per render, {count} Cycles renders of the bands instead of "
                        f"{len(band_groups(count, request.bands_per_render))}, because nodes mix colour channels: "
                        f"{node_rules.summarise(mixing)}; each band is rendered alone as a grey (in R, G and B), so "
                        "these nodes act on its value only (a change of hue or saturation does nothing to a grey); "
                        "nodes that act on each channel alike (Mix, Gamma, Invert, Bright/Contrast) keep three bands "
                        "per render")
        textures = self._prepare_textures(work_dir, inputs, edges, per_render, replicate)
        transmission = any(materials.has_transmission(walks[("material", m.name)]) for m in used)
        light_groups, assignments, world_group = self._light_groups(view_layer, objects, emitters, world)
        total, planned = components.component_plan(request.families, light_groups, request.max_bounces, transmission,
                                                    environment=world["status"] == "lit")
        plan = RenderPlan(view_layer=view_layer, objects=objects, materials=used, inputs=inputs, bands=bands, edges=edges,
                          groups=band_groups(len(edges) - 1, per_render), replicate=replicate, per_render=per_render,
                          light_groups=light_groups, assignments=assignments, total=total, components=planned,
                          variants=components.render_variants(request.max_bounces, "bounces" in request.families),
                          passes=components.passes_needed(planned), ids=self._object_ids(objects),
                          world=world, world_group=world_group, lights=lights, replaced={}, textures=textures,
                          texture_images={})
        plan.key = cache.cache_key(self._cache_description(plan))
        return plan

    def _spectral_inputs(self, used, lights, walks, world):
        """Every spectral input of the materials, lights and world, with its source's key and its scale; identical
        sources share a key (they are evaluated once). Also the names of the emitting materials."""
        keys, inputs, emitters = {}, [], set()
        self._texture_sources = {}

        def key_of(source, role):
            if _is_texture(source):  # one image is prepared once per use: a reflectance or a radiance
                text = json.dumps({**source, "use": "radiance" if role == "emission" else "reflectance"}, sort_keys=True)
                key = keys.setdefault(text, f"s{len(keys)}")
                self._texture_sources[key] = source
                return key
            return keys.setdefault(json.dumps(source, sort_keys=True), f"s{len(keys)}")

        for material in used:
            for spectral_input, source, scale in self._owner_inputs("material", material,
                                                                    walks[("material", material.name)]):
                inputs.append((spectral_input, key_of(source, spectral_input.role), scale, material.name))
                if spectral_input.role == "emission":
                    emitters.add(material.name)
        for ob in lights:
            for spectral_input, source, scale in self._owner_inputs("light", ob, walks[("light", ob.name)]):
                inputs.append((spectral_input, key_of(source, spectral_input.role), scale, ob.name))
        if world["status"] == "lit":
            for spectral_input, source, scale in self._owner_inputs("world", self.scene.world, world["walk"]):
                inputs.append((spectral_input, key_of(source, spectral_input.role), scale, self.scene.world.name))
        return keys, inputs, emitters

    def _band_averages(self, work_dir, keys, inputs):
        """The band averages of every source (`chromatrace scene-bands`), a reflectance above 1 refused."""
        bands = self._evaluate(work_dir, keys)
        for spectral_input, key, _scale, owner in inputs:
            if key in self._texture_sources:
                continue  # prepare-texture checks every texel
            problem = self._above_one(bands, spectral_input, key)
            if problem:
                raise BadInput(f"material \"{owner}\": {problem}")
        return bands

    def _evaluate(self, work_dir, keys):
        request = self.request
        request_file = os.path.join(work_dir, "spectra.json")
        spectra = {k: json.loads(t) for t, k in keys.items() if not _is_texture(json.loads(t))}
        spectra = spectra or {"flat": {"constant": 1.0}}  # no spectra: the band edges all the same
        with open(request_file, "w") as f:
            json.dump({"format": "chromatrace-spectra/1", "spectra": spectra}, f)
        return self.tool.band_averages(request_file, request.bands, request.bands_file)

    @staticmethod
    def _above_one(bands, spectral_input, key):
        entry = bands["spectra"][key]
        if spectral_input.role == "reflectance" and entry["max"] > 1.0:
            return (f"the reflectance of {spectral_input.label} reaches {entry['max']:g} at {entry['max_nm']:g} nm, "
                    "but a reflectance must be in [0, 1]")
        return None

    def _prepare_textures(self, work_dir, inputs, edges, per_render, replicate):
        """Every image texture's per-band-group images (`chromatrace prepare-texture`, cached by content in
        <cache root>/textures): {key: prepare-texture's --json summary}."""
        textures = {}
        wanted = {key: (spectral_input, owner) for spectral_input, key, _scale, owner in inputs
                  if key in self._texture_sources}
        if not wanted:
            return textures
        bands_file = os.path.join(work_dir, "bands.json")
        with open(bands_file, "w") as f:
            json.dump({"format": "chromatrace-bands/1", "edges_nm": edges}, f)
        directory = os.path.join(self.request.cache_root or cache.default_root(), "textures")
        os.makedirs(directory, exist_ok=True)
        for key, (spectral_input, owner) in wanted.items():
            source = self._texture_sources[key]
            kind = "radiance" if spectral_input.role == "emission" else "reflectance"
            scale = source.get("scale", 1.0)
            if kind == "reflectance" and scale > 1.0:
                raise BadInput(f"{owner}: the texture of {spectral_input.label} has scale {scale:g}, but a "
                               "reflectance's scale must be in [0, 1]")
            image = self._texture_file(source["texture"], work_dir)
            start = time.monotonic()
            textures[key] = self.tool.prepare_texture(image, kind, source.get("colour_space", "auto"), bands_file,
                                                      per_render, replicate, scale, directory)
            summary = textures[key]
            self.request.log(f"texture {source['texture']} ({summary['width']}x{summary['height']}, "
                             f"{summary['distinct_colours']} colours, {kind}): "
                             f"{'cached' if summary['cached'] else f'{time.monotonic() - start:.1f} s'}")
        return textures

    @staticmethod
    def _texture_file(texture, work_dir):
        """The file of a texture source; an image packed into the .blend is written out into work_dir first."""
        if not texture.startswith("packed:"):
            return texture
        image = bpy.data.images[texture[len("packed:"):]]
        name = os.path.basename(image.filepath) or f"{image.name}.png"
        path = os.path.join(work_dir, f"packed-{len(os.listdir(work_dir))}-{name}")
        with open(path, "wb") as f:
            f.write(image.packed_file.data)
        return path

    def _light_groups(self, view_layer, objects, emitters, world):
        """Light groups: every emitter in one (its own, or one named after it), a lit world too; none without the
        lights family. Returns (groups, {object name: group}, the world's group or None)."""
        light_groups, assignments = [], {}
        if "lights" not in self.request.families:
            return light_groups, assignments, None
        if not hasattr(view_layer, "lightgroups"):
            raise BadInput("light-group components need Blender 3.2 or later (or leave out the lights family)")
        for ob in objects:
            emits = ob.type == "LIGHT" or any(
                slot.material is not None and slot.material.name in emitters for slot in ob.material_slots)
            if not emits:
                continue
            group = ob.lightgroup or _group_name(ob.name)
            assignments[ob.name] = group
            if group not in light_groups:
                light_groups.append(group)
        world_group = None
        if world["status"] == "lit":
            world_group = self.scene.world.lightgroup or "world"
            if world_group not in light_groups:
                light_groups.append(world_group)
        return light_groups, assignments, world_group

    def _object_ids(self, objects):
        """Object ids, written by their own render (manifest.IDS_FILE), not by the band renders: the objects'
        pass indices when they are distinct and positive, else 1, 2, … by name."""
        if not self.request.object_ids:
            return {}
        geometry = [ob for ob in objects if ob.type in _GEOMETRY_TYPES]
        indices = [ob.pass_index for ob in geometry]
        if all(i > 0 for i in indices) and len(set(indices)) == len(indices):
            return {ob.name: ob.pass_index for ob in geometry}
        return {ob.name: i + 1 for i, ob in enumerate(sorted(geometry, key=lambda o: o.name))}

    def _cache_description(self, plan):
        scene, request = self.scene, self.request
        depsgraph = bpy.context.evaluated_depsgraph_get()
        geometry = {}
        for ob in plan.objects:
            digest = hashlib.sha256()
            digest.update(repr([list(row) for row in ob.matrix_world]).encode())
            digest.update(json.dumps([[getattr(ob, a, None) for a in _RAY_VISIBILITY],
                                      _rna_plain(getattr(ob, "cycles", None))], sort_keys=True).encode())
            if ob.type == "LIGHT":
                digest.update(json.dumps([_rna_plain(ob.data), _rna_plain(getattr(ob.data, "cycles", None))],
                                         sort_keys=True).encode())
                if blender_compat.uses_nodes(ob.data):
                    digest.update(json.dumps(materials.node_tree_digest(ob.data.node_tree)).encode())
            else:
                evaluated = ob.evaluated_get(depsgraph)
                mesh = evaluated.to_mesh()
                if mesh is not None:
                    update_with_mesh(digest, mesh)
                    digest.update(repr([p.use_smooth for p in mesh.polygons]).encode())
                    evaluated.to_mesh_clear()
                digest.update(repr([s.material.name if s.material else None for s in ob.material_slots]).encode())
            geometry[ob.name] = digest.hexdigest()
        camera = scene.camera
        world = scene.world
        focus = camera.data.dof.focus_object
        view_layer = plan.view_layer
        return {
            "addon": list(VERSION), "blender": bpy.app.version_string,
            "edges": plan.edges, "per_render": plan.per_render, "replicate": plan.replicate,
            "inputs": [[i.label, i.role, key, scale] for i, key, scale, _owner in plan.inputs],
            "averages": {k: v["bands"] for k, v in plan.bands["spectra"].items()},
            "textures": {k: v["hash"] for k, v in plan.textures.items()},
            "samples": request.samples, "seed": request.seed, "max_bounces": request.max_bounces,
            "device": request.device, "variants": plan.variants, "point_filter": request.point_filter,
            "resolution": self._resolution(),
            "passes": sorted(plan.passes), "light_groups": plan.assignments, "ids": plan.ids,
            "geometry": geometry,
            "nodes": {m.name: materials.node_tree_digest(m.node_tree) for m in plan.materials},
            "material_settings": {m.name: _rna_plain(getattr(m, "cycles", None)) for m in plan.materials},
            "camera": [repr([list(r) for r in camera.matrix_world]), _rna_plain(camera.data),
                       _rna_plain(getattr(camera.data, "cycles", None))],
            # Depth of field: f-stop, focus distance or object, the aperture's blades, rotation and ratio.
            "depth_of_field": [_rna_plain(camera.data.dof),
                               repr([list(r) for r in focus.matrix_world]) if focus is not None else None],
            "world": materials.node_tree_digest(world.node_tree) if blender_compat.uses_nodes(world) else None,
            "world_state": [plan.world["status"], plan.world_group,
                            list(world.color) if world is not None else None],
            "world_settings": [_rna_plain(getattr(world, "cycles", None)),
                               _rna_plain(getattr(world, "cycles_visibility", None))] if world is not None else None,
            # Cycles and render settings the render does not set itself: light paths (transparent bounces,
            # minimum bounces, volume steps), sampling pattern, dicing, culling, film transparency of glass, …
            "cycles": _pixel_settings(scene.cycles, cycles_setup.FIXED["cycles"]),
            "render": _pixel_settings(scene.render, cycles_setup.FIXED["render"]),
            "view_layer": [[getattr(view_layer, a, None) for a in _VIEW_LAYER_FILTER],
                           view_layer.material_override.name if view_layer.material_override else None],
        }

    def _resolution(self):
        if self.request.resolution:
            return list(self.request.resolution)
        r = self.scene.render
        return [r.resolution_x * r.resolution_percentage // 100, r.resolution_y * r.resolution_percentage // 100]

    # ---- pre-flight ----------------------------------------------------------------------------------

    def preflight(self):
        """What a render would do, without rendering or changing anything (batch.py --explain): every material,
        light and the world with its status — "exact" (every colour a spectrum: the add-on's spectra, Blackbody
        nodes, grey), "upsampled" (some colour upsampled from RGB), "refused" (with every reason in full), or
        for the world also "none", "dark" (no light) and "omitted" (refused, rendered without it as asked) —
        and the number of Cycles renders the plan needs (null when something is refused)."""
        request = self.request
        view_layer, objects, used, lights = self._scene_parts()
        walks = self._walks(used, lights)
        world = self._world_state(walks)
        hard, mixing = self._node_issues(used, walks, world)
        owners = []
        keys = {}

        def key_of(source):
            text = json.dumps(source, sort_keys=True)
            return keys.setdefault(text, f"s{len(keys)}")

        def report(kind, thing, walk, status_override=None):
            name = thing.name
            issues = [i for i in hard + mixing if i["kind"] == kind and i["material"] == name]
            entry = {"kind": kind, "name": name, "status": None, "reasons": [node_rules.describe_issue(i) for i in issues],
                     "colours": []}
            inputs = []
            if status_override is None:
                try:
                    inputs = self._owner_inputs(kind, thing, walk)
                except BadInput as e:
                    entry["reasons"].append(str(e))
                    entry["status"] = "refused"
            for spectral_input, source, scale in inputs:
                colour = {"input": spectral_input.label, "role": spectral_input.role, "source": source,
                          "scale": scale, "key": key_of(source), "upsampled": "rgb" in source or _is_texture(source)}
                if _is_texture(source):
                    try:
                        colour["negative_texels"] = self._texture_noise(source, spectral_input.role)
                    except BadInput as e:
                        entry["reasons"].append(f"{kind} \"{name}\", {spectral_input.label}: {e}")
                        entry["status"] = "refused"
                entry["colours"].append(colour)
            refused = any(not i["fallback"] for i in issues) or (
                any(i["fallback"] for i in issues) and request.on_mixing_nodes != "one-band")
            if status_override is not None:
                entry["status"] = status_override
            elif refused or entry["status"] == "refused":
                entry["status"] = "refused"
            else:
                entry["status"] = "upsampled" if any(c["upsampled"] for c in entry["colours"]) else "exact"
            if any(i["fallback"] for i in issues) and entry["status"] != "refused":
                entry["one_band_per_render"] = True
            owners.append(entry)
            return entry

        for material in used:
            report("material", material, walks[("material", material.name)])
        for ob in lights:
            report("light", ob, walks[("light", ob.name)])
        if self.scene.world is not None:
            status = world["status"]
            report("world", self.scene.world, world["walk"], None if status in ("lit", "refused") else status)
            if status == "omitted":
                owners[-1]["reasons"] = [self._world_warning(world)]
        else:
            owners.append({"kind": "world", "name": None, "status": "none", "reasons": [], "colours": []})

        work_dir = tempfile.mkdtemp(prefix="chromatrace-")
        try:
            bands = self._evaluate(work_dir, keys)
        finally:
            shutil.rmtree(work_dir, ignore_errors=True)
        for entry in owners:
            for colour in entry["colours"]:
                if _is_texture(colour["source"]):  # every texel upsampled when the render prepares it
                    colour["bands"] = None
                    del colour["key"]
                    continue
                values = bands["spectra"][colour["key"]]
                colour["bands"] = [v * colour["scale"] for v in values["bands"]]
                if colour["role"] == "reflectance" and values["max"] > 1.0:
                    entry["status"] = "refused"
                    entry["reasons"].append(
                        f"{entry['kind']} \"{entry['name']}\": the reflectance of {colour['input']} reaches "
                        f"{values['max']:g} at {values['max_nm']:g} nm, but a reflectance must be in [0, 1]")
                del colour["key"]
        edges = bands["bands"]["edges_nm"]
        refused = [e for e in owners if e["status"] == "refused"]
        replicate = bool(mixing) and request.on_mixing_nodes == "one-band"
        per_render = 1 if replicate else request.bands_per_render
        groups = band_groups(len(edges) - 1, per_render)
        variants = components.render_variants(request.max_bounces, "bounces" in request.families)
        renders = None if refused else len(groups) * len(variants) + (1 if request.object_ids else 0)
        return {"format": "chromatrace-preflight/1", "scene": self.scene.name,
                "ok": not refused, "renders": renders, "bands": len(edges) - 1, "edges_nm": edges,
                "bands_per_render": per_render, "band_groups": len(groups), "bounce_limits": len(variants),
                "render_variants": list(variants),
                "object_id_render": bool(request.object_ids), "owners": owners}

    def _texture_noise(self, source, role):
        """The capture noise an image texture's file has, as the render will zero it ({"zeroed", "largest",
        "threshold"}); None for an image packed into the .blend (judged when the render writes it out)."""
        path = source["texture"]
        if path.startswith("packed:"):
            return None
        kind = "reflectance" if role == "reflectance" else "radiance"
        space = {"sRGB": "sRGB", "linear": "linear"}.get(source.get("colour_space"), "auto")
        return self.tool.check_texture(path, kind, space)["negative_texels"]

    # ---- rendering -----------------------------------------------------------------------------------

    def _apply_settings(self, journal, plan):
        scene, request = self.scene, self.request
        view_layer = plan.view_layer
        cycles_setup.apply(journal, scene, view_layer, request.samples, request.seed, request.point_filter,
                           self._resolution(), plan.passes)
        plan.device = cycles_setup.select_device(journal, scene, _cycles_preferences(), request.device)
        world = scene.world
        if world is not None and plan.world["status"] != "lit":  # dark, or omitted as asked: strength 0
            journal.set(world, "color", (0.0, 0.0, 0.0))
            if blender_compat.uses_nodes(world):
                for node in world.node_tree.nodes:
                    if node.bl_idname == "ShaderNodeBackground":
                        journal.set(node.inputs["Strength"], "default_value", 0.0)
        if world is not None and plan.world_group and world.lightgroup != plan.world_group:
            journal.set(world, "lightgroup", plan.world_group)
        for spectral_input, _key, _scale, _owner in plan.inputs:
            node = spectral_input.replace
            if node is not None and node.as_pointer() not in plan.replaced:
                plan.replaced[node.as_pointer()] = _replace_with_rgb(journal, node)
        self._load_textures(journal, plan)
        existing = set(view_layer.lightgroups.keys()) if hasattr(view_layer, "lightgroups") else set()
        for group in plan.light_groups:
            if group not in existing:
                view_layer.lightgroups.add(name=group)
                existing.add(group)
                journal.call_on_restore(lambda name=group: _remove_lightgroup(scene, view_layer, name))
        for ob in plan.objects:
            if ob.name in plan.assignments and ob.lightgroup != plan.assignments[ob.name]:
                journal.set(ob, "lightgroup", plan.assignments[ob.name])
            if ob.name in plan.ids and ob.pass_index != plan.ids[ob.name]:
                journal.set(ob, "pass_index", plan.ids[ob.name])

    def _load_textures(self, journal, plan):
        """The prepared images as Blender images (raw data: no colour transform), removed again on restore; a
        black image stands in for reflectance textures when only emitters are shown."""
        for key, summary in plan.textures.items():
            images = []
            for group in summary["groups"]:
                image = bpy.data.images.load(group["file"], check_existing=False)
                image.colorspace_settings.name = "Non-Color"
                journal.call_on_restore(lambda image=image: bpy.data.images.remove(image))
                images.append(image)
            plan.texture_images[key] = images
        if plan.textures and self.request.max_bounces == 0:
            black = bpy.data.images.new("chromatrace black", 1, 1, alpha=False, float_buffer=True)
            black.pixels[:] = (0.0, 0.0, 0.0, 1.0)
            journal.call_on_restore(lambda: bpy.data.images.remove(black))
            plan.texture_images[None] = [black]

    def _set_colours(self, journal, plan, group):
        no_reflection = self.request.max_bounces == 0  # emitters only
        index = plan.groups.index(group)
        for spectral_input, key, scale, _owner in plan.inputs:
            if key in plan.textures:
                image = plan.texture_images[key][index]
                if no_reflection and spectral_input.role != "emission":
                    image = plan.texture_images[None][0]
                journal.set(spectral_input.target, "image", image)
                continue
            values = plan.bands["spectra"][key]["bands"]
            r, g, b = group_colour(values, group, plan.replicate)
            factor = 0.0 if no_reflection and spectral_input.role != "emission" else scale
            colour = (r * factor, g * factor, b * factor)
            if spectral_input.alpha is not None:
                colour = (*colour, spectral_input.alpha)
            target = spectral_input.target
            if spectral_input.replace is not None:
                target = plan.replaced[spectral_input.replace.as_pointer()]
            journal.set(target, spectral_input.attribute, colour)

    def steps(self):
        """Generator: yields (renders done, renders in all, message) after each Cycles render."""
        request = self.request
        if not request.output:
            raise BadInput("output: no file name")
        out_dir = os.path.dirname(os.path.abspath(request.output))
        if not os.path.isdir(out_dir):
            raise BadInput(f"output: {request.output}: directory {out_dir} does not exist")
        journal = Journal()
        work_dir = tempfile.mkdtemp(prefix="chromatrace-")
        try:
            plan = self._prepare(work_dir)
            self.cache_dir = cache.cache_directory(request.cache_root, plan.key)
            groups, variants = plan.groups, plan.variants
            total = len(groups) * len(variants) + (1 if request.object_ids else 0)
            request.log(f"{len(plan.edges) - 1} bands in {len(groups)} renders of {plan.per_render} band(s)"
                        f"{' x ' + str(len(variants)) + ' bounce limits' if len(variants) > 1 else ''}; "
                        f"cache {self.cache_dir}")
            wanted = manifest.channels_by_file(self._manifest(plan))
            todo = set(manifest.missing_renders(self.cache_dir, groups, list(variants)))
            only = request.only_group
            if only is not None:
                if only >= len(groups):
                    raise BadInput(f"--band-group: must be in [0, {len(groups) - 1}] for {len(groups)} band groups, "
                                   f"got {only}")
                total = len(variants)
                if request.only_variant is not None:
                    if request.only_variant not in variants:
                        raise BadInput(f"--bounce-limit: must be one of {', '.join(variants)}, got "
                                       f"\"{request.only_variant}\"")
                    total = 1
            self._drop_unreadable(plan, wanted, todo)
            applied = False
            done = 0
            for g, group in enumerate(groups):
                if only is not None and g != only:
                    continue
                colours_set = False
                for variant, cycles_bounces in variants.items():
                    if request.only_variant is not None and variant != request.only_variant:
                        continue
                    final = os.path.join(self.cache_dir, manifest.render_file_name(g, variant))
                    if (g, variant) not in todo:
                        self.cached += 1
                        done += 1
                        request.log(f"render {done}/{total} ({describe_band_range(plan.edges, group)}, {variant}): "
                                    "already in the cache")
                        yield done, total, "cached"
                        continue
                    if not applied:
                        self._apply_settings(journal, plan)
                        applied = True
                    if not colours_set:
                        self._set_colours(journal, plan, group)
                        colours_set = True
                    cycles_setup.set_bounces(journal, self.scene, cycles_bounces)
                    if TEST_HOOK is not None:
                        TEST_HOOK("before_render", group=g, variant=variant, rendered=self.rendered)
                    temporary = final + ".partial"
                    journal.set(self.scene.render, "filepath", temporary)
                    start, start_cpu = time.monotonic(), time.process_time()
                    bpy.ops.render.render(write_still=True, scene=self.scene.name)
                    if not os.path.isfile(temporary):
                        raise RuntimeError(f"Cycles wrote no file for render {done + 1} ({temporary})")
                    channels = wanted.get(os.path.basename(final), set())
                    cache.commit(temporary, final, lambda path: self._unreadable(path, channels))
                    self.rendered += 1
                    done += 1
                    message = (f"render {done}/{total} ({describe_band_range(plan.edges, group)}, {variant}): "
                               f"{time.monotonic() - start:.2f} s, {time.process_time() - start_cpu:.2f} s CPU")
                    request.log(message)
                    yield done, total, message
            if only is not None:
                request.log(f"band group {only} of {len(groups)}"
                            f"{'' if request.only_variant is None else ' (' + request.only_variant + ')'} is in the cache "
                            f"{self.cache_dir}")
                return
            if request.object_ids:
                ids_file = os.path.join(self.cache_dir, manifest.IDS_FILE)
                if os.path.isfile(ids_file):
                    self.cached += 1
                    done += 1
                    request.log(f"render {done}/{total} (object ids): already in the cache")
                    yield done, total, "cached"
                else:
                    if not applied:
                        self._apply_settings(journal, plan)
                        applied = True
                    message = self._render_ids(journal, plan, ids_file, wanted.get(manifest.IDS_FILE, set()))
                    done += 1
                    request.log(f"render {done}/{total} (object ids): {message}")
                    yield done, total, message
            journal.restore()
            self._assemble(plan)
            self._write_preview()
            if not request.keep_cache:
                cache.remove(self.cache_dir)
        finally:
            journal.restore()
            shutil.rmtree(work_dir, ignore_errors=True)

    def _render_ids(self, journal, plan, final, channels):
        """The object-id render: one sample per pixel, at the pixel's centre."""
        cycles_setup.set_id_render(journal, self.scene, plan.view_layer)
        temporary = final + ".partial"
        journal.set(self.scene.render, "filepath", temporary)
        start, start_cpu = time.monotonic(), time.process_time()
        bpy.ops.render.render(write_still=True, scene=self.scene.name)
        if not os.path.isfile(temporary):
            raise RuntimeError(f"Cycles wrote no file for the object-id render ({temporary})")
        cache.commit(temporary, final, lambda path: self._unreadable(path, channels))
        self.rendered += 1
        return f"{time.monotonic() - start:.2f} s, {time.process_time() - start_cpu:.2f} s CPU"

    def _unreadable(self, path, channels):
        """Why a Cycles render file cannot be assembled, or None: it must read to the end of its pixel data, be of
        the render's size and hold `channels`."""
        try:
            info = self.tool.image_info(path)
        except (BadInput, RuntimeError) as e:
            return str(e)
        size = [info["width"], info["height"]]
        if size != self._resolution():
            return f"{path}: {size[0]}x{size[1]} pixels, not the render's {'x'.join(map(str, self._resolution()))}"
        missing = sorted(set(channels) - {c["name"] for c in info["channels"]})
        if missing:
            return f"{path}: no channel {', '.join(missing)}"
        return None

    def _drop_unreadable(self, plan, wanted, todo):
        """Adds to `todo` (and removes from the cache) every cached render that does not read back."""
        cached = [(g, v) for g in range(len(plan.groups)) for v in plan.variants if (g, v) not in todo]
        files = [(manifest.render_file_name(g, v), (g, v)) for g, v in cached]
        if self.request.object_ids:
            files.append((manifest.IDS_FILE, None))
        for name, entry in files:
            path = os.path.join(self.cache_dir, name)
            if not os.path.isfile(path):
                continue
            problem = self._unreadable(path, wanted.get(name, set()))
            if problem is None:
                continue
            self.request.log(f"warning: {name} in the cache does not read back, so it is rendered again: {problem}")
            cache.discard(path)
            if entry is not None:
                todo.add(entry)

    def _manifest(self, plan, attributes=None):
        """The `chromatrace-assemble/1` document of the plan's renders."""
        names = None
        if self.request.object_ids:
            names = {}
            for ob in plan.objects:
                if ob.name in plan.ids:
                    names[plan.ids[ob.name]] = ob.chromatrace.scene_name or ob.name
        return manifest.build_manifest(
            plan.edges, plan.groups, list(plan.variants), plan.view_layer.name, plan.total,
            plan.components, object_names=names, attributes=attributes, replicate=plan.replicate,
            reconstruction=plan.bands["bands"].get("reconstruction"), pass_names=blender_compat.pass_names())

    def _assemble(self, plan):
        request = self.request
        manifest_file = os.path.join(self.cache_dir, "manifest.json")
        cache.write_json(manifest_file, self._manifest(plan, self._attributes(plan)))
        self.tool.assemble(manifest_file, os.path.abspath(request.output))
        request.log(f"wrote {request.output} ({self.rendered} renders made, {self.cached} from the cache)")

    def _write_preview(self):
        """OUT.preview.png beside OUT.exr: the display rendering of a camera (tool.preview), so that a person sees
        the scene as photographed, not the raw integral of radiance with the CIE observer. A failure is said, and
        leaves the spectral file as it is."""
        output = os.path.abspath(self.request.output)
        preview = os.path.splitext(output)[0] + ".preview.png"
        try:
            self.tool.preview(output, preview)
        except (BadInput, RuntimeError) as e:
            self.request.log(f"warning: no preview: {e}")
            return
        self.preview = preview
        self.request.log(f"preview {preview}")

    def _attributes(self, plan):
        scene, request = self.scene, self.request
        s = scene.chromatrace
        source = s.source_json or json.dumps({"blend": bpy.data.filepath, "scene": scene.name})
        attributes = {}
        if plan.world["status"] == "omitted":
            attributes["chromatrace.warning"] = self._world_warning(plan.world)
        return attributes | {
            "chromatrace.renderer": (f"Cycles (Blender {bpy.app.version_string}) via the chromatrace add-on: "
                                     f"{plan.per_render} band(s) per render, max {request.max_bounces} bounces, "
                                     f"on {request.device}"),
            "chromatrace.device": getattr(plan, "device", request.device),
            "chromatrace.samples": str(request.samples),
            "chromatrace.seed": str(request.seed),
            "chromatrace.scene": source,
            "chromatrace.camera": json.dumps(camera_description(scene, self._resolution())),
        }


def camera_description(scene, resolution):
    """The camera as `chromatrace render` describes it in the header."""
    import math
    camera = scene.camera
    width, height = resolution
    data = camera.data
    m = camera.matrix_world
    position = [m[i][3] for i in range(3)]
    forward = [-m[i][2] for i in range(3)]
    up = [m[i][1] for i in range(3)]
    fit = data.sensor_fit
    if fit == "VERTICAL" or (fit == "AUTO" and height > width):
        sensor = (data.sensor_height if fit == "VERTICAL" else data.sensor_width) * width / height
    else:
        sensor = data.sensor_width
    tan_w = 0.5 * sensor / data.lens
    tan_h = tan_w * height / width
    return {"position": position, "look_at": [position[i] + forward[i] for i in range(3)], "up": up,
            "horizontal_fov_deg": math.degrees(2 * math.atan(tan_w)), "vertical_fov_deg": math.degrees(2 * math.atan(tan_h)),
            "sensor_width_mm": sensor, "focal_length_mm": data.lens, "resolution": [width, height]}


def _is_texture(source):
    return isinstance(source, dict) and "texture" in source


def _rgb_source(source):
    """A grey RGB source as the constant it upsamples to (Jakob-Hanika's grey is flat): exact, not upsampled."""
    if isinstance(source, dict) and "rgb" in source and max(source["rgb"]) == min(source["rgb"]):
        return {"constant": source["rgb"][0]}
    return source


def _replace_with_rgb(journal, node):
    """Replaces a Blackbody node's links by an RGB node's for the render (the node stays, unlinked); undone
    through the journal. Returns the RGB node's output socket, whose colour the render sets per band group."""
    tree = node.id_data
    targets = [link.to_socket for link in node.outputs[0].links if link.is_valid and not link.is_muted]
    rgb = tree.nodes.new("ShaderNodeRGB")
    rgb.label = f"chromatrace: {node.name}"
    rgb.location = node.location

    def undo():
        tree.nodes.remove(rgb)
        for socket in targets:
            tree.links.new(node.outputs[0], socket)

    journal.call_on_restore(undo)
    for socket in targets:
        tree.links.new(rgb.outputs[0], socket)
    return rgb.outputs[0]


def _remove_lightgroup(scene, view_layer, name):
    groups = view_layer.lightgroups
    if name not in groups.keys():
        return
    if hasattr(groups, "remove"):
        groups.remove(groups[name])
        return
    previous = view_layer.active_lightgroup_index
    view_layer.active_lightgroup_index = groups.keys().index(name)
    with bpy.context.temp_override(scene=scene, view_layer=view_layer):
        bpy.ops.scene.view_layer_remove_lightgroup()
    view_layer.active_lightgroup_index = min(previous, max(len(groups) - 1, 0))
