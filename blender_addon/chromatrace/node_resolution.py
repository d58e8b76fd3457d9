# SPDX-License-Identifier: GPL-3.0-or-later
"""Where each spectral colour of a render comes from: the colour walks of the materials, lights and world (what
their node trees do to colour, colour_walk.py), what the render refuses or renders one band at a time, and the
source of every spectral input — a spectrum of the add-on's, a Blackbody node's Planck's law, a grey, a colour
upsampled from RGB or an image texture — with its band averages (`chromatrace scene-bands`)."""

import json
import os

from . import materials, node_rules
from .errors import BadInput
from .spectra import SourceError, rgb_for_upsampling

WORLD_HINT = ("; to render without the world's light choose World light: Omit in the render settings "
              "(batch.py --on-world omit)")


# The role of a light's own colour where its nodes give the emitted colour: it multiplies that colour, as a
# reflectance would (a grey is flat), and it shows where emitters alone are rendered.
FILTER = "filter"


def is_texture(source):
    return isinstance(source, dict) and "texture" in source


def rgb_source(source, emitted=False):
    """A grey RGB reflectance as the constant it upsamples to (Jakob-Hanika's grey is flat): exact, not upsampled.
    An emitted RGB colour stays RGB: `chromatrace` makes it relative to D65, Blender's white (so an emitted grey
    is D65, not flat)."""
    if not emitted and isinstance(source, dict) and "rgb" in source and max(source["rgb"]) == min(source["rgb"]):
        return {"constant": source["rgb"][0]}
    return source


def upsampled(source):
    """Whether a source's spectrum is upsampled from RGB: a colour or a texture (a grey is exact: flat, or D65
    where emitted)."""
    return is_texture(source) or (isinstance(source, dict) and "rgb" in source
                                  and max(source["rgb"]) != min(source["rgb"]))


def source_text(source, role):
    """The JSON text that keys a source in a role: an emitted RGB colour is another spectrum than the same
    colour's reflectance (`chromatrace scene-bands` reads it from the spectra list's "radiance"), and a texture is
    prepared once per use."""
    if is_texture(source):
        return json.dumps({**source, "use": "radiance" if role == "emission" else "reflectance"}, sort_keys=True)
    if role == "emission" and isinstance(source, dict) and "rgb" in source:
        return json.dumps({"radiance": source}, sort_keys=True)
    return json.dumps(source, sort_keys=True)


# ---- the colour walks and what they refuse --------------------------------------------------------------

def walks(scene, used, lights):
    """The colour walk (colour_walk.Walk) of every material and light used, and of the world, by (kind, name)."""
    found = {}
    world = scene.world
    if world is not None:
        found[("world", world.name)] = materials.walk_world(world)
    for ob in lights:
        walk = materials.walk_light(ob.data)
        walk.name = ob.name
        for issue in walk.issues:
            issue["material"] = ob.name
        found[("light", ob.name)] = walk
    for material in used:
        found[("material", material.name)] = materials.walk_material(material)
    return found


def world_state(scene, all_walks, on_world):
    """What the render does with the world: {"status": "none" | "dark" | "lit" | "omitted" | "refused",
    "issues": [...]}. A world is lit when a background or emission it reaches has a colour and a strength;
    lit worlds are converted, or refused when a colour cannot be (an HDRI), unless `on_world` is "omit"."""
    world = scene.world
    if world is None:
        return {"status": "none", "issues": [], "walk": None}
    walk = all_walks[("world", world.name)]
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
        if on_world == "omit":
            return {"status": "omitted", "issues": walk.issues, "walk": walk}
        return {"status": "refused", "issues": walk.issues, "walk": walk}
    return {"status": "lit", "issues": walk.issues, "walk": walk}


def node_issues(used, all_walks, world):
    """(hard issues, channel-mixing issues): the world's first (its message says how to proceed), then the
    lights' and the materials'."""
    issues = []
    if world["status"] in ("lit", "refused"):
        issues += world["issues"]
    for (kind, _name), walk in all_walks.items():
        if kind != "world":
            issues += walk.issues
    for material in used:
        s = material.chromatrace
        if s.model == "DICHROMATIC" and s.lobe == "phong":
            issues.append({"kind": "material", "material": material.name, "node": "ct_glossy", "socket": None,
                           "reason": "the phong lobe has no Cycles counterpart (only the reference tracer "
                                     "renders it); use ggx", "fallback": False})
    return [i for i in issues if not i["fallback"]], [i for i in issues if i["fallback"]]


def world_warning(world):
    reasons = "; ".join(node_rules.describe_issue(i) for i in world["issues"] if not i["fallback"])
    return f"rendered without the world's light (strength 0), as asked: {reasons}"


def check_nodes(request, used, all_walks, world):
    """Refuses (BadInput) what cannot be rendered; returns the channel-mixing issues that need one band per
    render (empty: none)."""
    hard, mixing = node_issues(used, all_walks, world)
    if hard:
        raise BadInput(f"cannot render spectrally: {node_rules.summarise(hard)}")
    if mixing and request.on_mixing_nodes != "one-band":
        raise BadInput(f"nodes mix colour channels: {node_rules.summarise(mixing)} "
                       "(choose one band per render to render anyway)")
    if world["status"] == "omitted":
        request.log(f"warning: {world_warning(world)}")
    return mixing


# ---- the source of each spectral input ------------------------------------------------------------------

def resolve(scene, spectrum_settings, current_rgb, what, texture_allowed=False):
    """The source JSON of a spectrum setting, table names resolved; a texture only where texture_allowed."""
    try:
        source = spectrum_settings.to_json(current_rgb=current_rgb)
    except (SourceError, ValueError) as e:
        raise BadInput(f"{what}: {e}") from None
    if is_texture(source) and not texture_allowed:
        raise BadInput(f"{what}: an image texture can be a material's reflectance here; for a textured emitter "
                       "use an Image Texture node in the material's own nodes (Model: Node tree)")
    if isinstance(source, str):
        entry = scene.chromatrace.spectra.get(source)
        if entry is None:
            raise BadInput(f"{what}: unknown spectrum \"{source}\" (not in the scene's spectrum table)")
        source = entry.source.to_json()
        if isinstance(source, str):
            raise BadInput(f"{what}: spectrum table entry \"{entry.name}\" refers to another name")
        if is_texture(source):
            raise BadInput(f"{what}: spectrum table entry \"{entry.name}\" is an image texture (a texture is "
                           "given where it is used, not in the table)")
    return source


def _fixed_source(spectral_input):
    """(source, scale) of an input whose source the walk fixed (a Blackbody node) or that is an interface's
    grey; None for the others."""
    if spectral_input.source is not None:
        return spectral_input.source, 1.0
    if spectral_input.role == "interface":
        return {"constant": spectral_input.current_rgb[0]}, 1.0
    return None


def _reflectance_colour_check(spectral_input, rgb, what):
    if max(rgb) > 1.0 or min(rgb) < 0.0:
        raise BadInput(f"{what}: colour {tuple(round(c, 4) for c in rgb)} of {spectral_input.label} "
                       "is outside [0, 1], so it is not a reflectance")


def node_source(spectral_input, what):
    """(source, scale) of a colour a node tree fixes: a Blackbody node's Planck's law, a grey interface
    colour, or the colour upsampled (an emission colour above 1 from its normalised colour)."""
    rgb = spectral_input.current_rgb
    fixed = _fixed_source(spectral_input)
    if fixed is not None:
        return fixed
    if spectral_input.role == "reflectance":
        _reflectance_colour_check(spectral_input, rgb, what)
        return rgb_source({"rgb": [max(0.0, float(c)) for c in rgb]}), 1.0
    rgb, factor = rgb_for_upsampling(rgb)
    return rgb_source({"rgb": rgb}, emitted=spectral_input.role == "emission"), factor


def input_source(scene, material, spectral_input):
    """(source JSON, scale) of one spectral colour input of a material."""
    s = material.chromatrace
    what = f"material \"{material.name}\""
    rgb = spectral_input.current_rgb
    fixed = _fixed_source(spectral_input)
    if fixed is not None:
        return fixed
    if spectral_input.role == "reflectance":
        settings = s.reflectance
        if settings.kind == "RGB" and settings.use_current_colour:
            _reflectance_colour_check(spectral_input, rgb, what)
        source = rgb_source(resolve(scene, settings, rgb, what, texture_allowed=True))
        if is_texture(source) != (spectral_input.attribute == "image"):
            node_is = "is not an Image Texture node" if is_texture(source) else "is an Image Texture node"
            raise BadInput(f"{what}: its reflectance is {'an image texture' if is_texture(source) else 'a spectrum'}"
                           f" but its node {materials.REFLECTANCE_NODE} {node_is}; choose the model again to "
                           "rebuild the nodes")
        return source, 1.0
    if spectral_input.managed or s.emissive:
        settings = s.emission
        scale = 1.0 if spectral_input.managed else s.emission_scale
        if settings.kind == "RGB" and settings.use_current_colour:
            rgb, factor = rgb_for_upsampling(rgb)
            return rgb_source(resolve(scene, settings, rgb, what), emitted=True), scale * factor
        return resolve(scene, settings, None, what), scale
    rgb, factor = rgb_for_upsampling(rgb)
    return rgb_source({"rgb": rgb}, emitted=spectral_input.role == "emission"), factor


def _flat_if_grey(spectral_input):
    """A light's node colour that is an RGB grey as a flat factor (the FILTER role), else as it is."""
    rgb = spectral_input.current_rgb
    if spectral_input.role == "emission" and spectral_input.source is None and rgb is not None and max(rgb) == min(rgb):
        return spectral_input._replace(role=FILTER)
    return spectral_input


def light_temperature(light):
    """The Temperature (K) a light's colour is multiplied by (Blender 4.5 and later), or None when it is off."""
    return float(light.temperature) if getattr(light, "use_temperature", False) else None


def owner_inputs(scene, kind, thing, walk):
    """[(SpectralInput, source, scale)] of one material, light object or world; BadInput when one fails."""
    found = []
    if kind == "material":
        for spectral_input in materials.spectral_inputs(thing, walk):
            found.append((spectral_input, *input_source(scene, thing, spectral_input)))
        return found
    what = f"{kind} \"{thing.name}\""
    leaves = materials.leaf_inputs(walk)
    if kind == "light":
        light = thing.data
        settings = light.chromatrace
        # Where the light's nodes give its colour (a Blackbody node, a colour that is not a grey, a texture), its own
        # colour multiplies that: a filter, whose white is flat. Otherwise its colour is what it emits, relative to
        # D65, and a grey in its nodes (the white Emission node Blender 5 gives every new light) is a flat factor.
        leaves = [_flat_if_grey(leaf) for leaf in leaves]
        emitted = not any(leaf.role == "emission" for leaf in leaves)
        temperature = light_temperature(light)
        if settings.emission.kind == "RGB" and settings.emission.use_current_colour and temperature is not None:
            # Cycles multiplies the colour by the Blackbody colour of the light's Temperature: Planck's law at it,
            # as a Blackbody node is (render_setup switches the Temperature off for the spectral renders).
            rgb = tuple(light.color)
            if max(rgb) != min(rgb):
                raise BadInput(f"{what}: its colour {tuple(round(c, 4) for c in rgb)} tints its Temperature "
                               f"({temperature:g} K); a temperature is Planck's law, which only a grey colour "
                               "scales: make the colour grey, or switch the Temperature off and give the spectrum")
            source, scale = {"blackbody_k": temperature}, settings.emission_scale * max(0.0, rgb[0])
        elif settings.emission.kind == "RGB" and settings.emission.use_current_colour:
            rgb, factor = rgb_for_upsampling(tuple(light.color))
            source = rgb_source(resolve(scene, settings.emission, rgb, what), emitted=emitted)
            scale = settings.emission_scale * factor
        else:
            source, scale = resolve(scene, settings.emission, None, what), settings.emission_scale
        role = "emission" if emitted else FILTER
        found.append((materials.SpectralInput(light, "color", role, tuple(light.color), None, what, False),
                      source, scale))
    for spectral_input in leaves:
        found.append((spectral_input, *node_source(spectral_input, what)))
    return found


def spectral_inputs(scene, used, lights, all_walks, world):
    """Every spectral input of the materials, lights and world, with its source's key and its scale; identical
    sources share a key (they are evaluated once). Returns (keys: {source JSON: key}, inputs: [(SpectralInput,
    key, scale, owner name)], the names of the emitting materials, texture sources: {key: source})."""
    keys, inputs, emitters, texture_sources = {}, [], set(), {}

    def key_of(source, role):
        key = keys.setdefault(source_text(source, role), f"s{len(keys)}")
        if is_texture(source):
            texture_sources[key] = source
        return key

    owners = [("material", m, all_walks[("material", m.name)]) for m in used]
    owners += [("light", ob, all_walks[("light", ob.name)]) for ob in lights]
    if world["status"] == "lit":
        owners.append(("world", scene.world, world["walk"]))
    for kind, thing, walk in owners:
        for spectral_input, source, scale in owner_inputs(scene, kind, thing, walk):
            inputs.append((spectral_input, key_of(source, spectral_input.role), scale, thing.name))
            if kind == "material" and spectral_input.role == "emission":
                emitters.add(thing.name)
    return keys, inputs, emitters, texture_sources


# ---- band averages ---------------------------------------------------------------------------------------

def evaluate(tool, request, work_dir, keys):
    """`chromatrace scene-bands` of every source that is no texture: the band edges and each one's averages."""
    request_file = os.path.join(work_dir, "spectra.json")
    sources = {k: json.loads(t) for t, k in keys.items()}
    spectra = {k: s for k, s in sources.items() if not is_texture(s) and "radiance" not in s}
    radiance = {k: s["radiance"] for k, s in sources.items() if "radiance" in s}
    spectra = spectra or {"flat": {"constant": 1.0}}  # no spectra: the band edges all the same
    with open(request_file, "w") as f:
        json.dump({"format": "chromatrace-spectra/1", "spectra": spectra, "radiance": radiance}, f)
    return tool.band_averages(request_file, request.bands, request.bands_file)


def reflectance_above_one(entry, label):
    """What is wrong with a reflectance whose band evaluation `entry` goes above 1, or None."""
    if entry["max"] > 1.0:
        return (f"the reflectance of {label} reaches {entry['max']:g} at {entry['max_nm']:g} nm, "
                "but a reflectance must be in [0, 1]")
    return None


def band_averages(tool, request, work_dir, keys, inputs, texture_sources):
    """The band averages of every source (`chromatrace scene-bands`), a reflectance above 1 refused."""
    bands = evaluate(tool, request, work_dir, keys)
    for spectral_input, key, _scale, owner in inputs:
        if key in texture_sources:
            continue  # prepare-texture checks every texel
        problem = spectral_input.role == "reflectance" and reflectance_above_one(bands["spectra"][key],
                                                                                 spectral_input.label)
        if problem:
            raise BadInput(f"material \"{owner}\": {problem}")
    return bands
