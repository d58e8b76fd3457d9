# SPDX-License-Identifier: GPL-3.0-or-later
"""Which shader nodes break band multiplexing (pure Python, no bpy).

Multiplexing puts three different bands in R, G and B and reads each channel back as its own band. That is
exact when every node treats the three channels alike and separately (any per-channel function, even a
non-linear one, gives each band what a render of that band alone would). It fails where a node mixes
channels or treats them differently — Principled specular or sheen tint (Blender 3: the highlight takes the
hue of the base colour; 4.0+: a coloured tint, by whose strongest channel Cycles weighs the layers below),
Multiscatter GGX up to Blender 3 (a random walk the channels share; from 4.0 a per-channel albedo scaling,
which multiplexes exactly), subsurface radii per channel, colour ramps, hue/saturation, RGB curves,
colour-to-BW, separating or combining channels, hue/saturation/colour/value blend modes. Rendering one band
per render, copied to all three channels, makes those nodes see grey and act on each band alone: the
"one-band" fallback. Some inputs are not spectra at all (procedural textures, vertex colours, the Wavelength
node, volumes): no fallback helps, so those always refuse.

A node is described as a dict (materials.describe_node_tree makes them from Blender nodes):
  {"name": "Principled BSDF", "type": "ShaderNodeBsdfPrincipled", "props": {"distribution": "GGX"},
   "inputs": {"Specular Tint": 0.0, ...}  (values of unlinked inputs),
   "colour_output_linked": True}         (whether a colour output feeds anything)

Colour paths (colour_node) say what happens to a colour on its way to a shader's colour input: every node a
colour passes through before it reaches a shader is either a constant the add-on turns into a spectrum (an
RGB node), an image whose every texel it upsamples (Image and Environment Texture nodes), an exact spectrum (a Blackbody node: Planck's law), a node that acts on each channel alike and
separately and passes its colour inputs on (Mix, Gamma, Invert, Bright/Contrast), a channel-mixing node that
only the one-band fallback renders (hue/saturation, RGB curves, hue/saturation/colour/value blends), or a
node whose colours cannot be spectra, which refuses the render. There is no fourth case: a colour node the
add-on does not know refuses.
"""

_MIXING_BLENDS = {"HUE", "SATURATION", "COLOR", "VALUE"}
# Image nodes whose every texel the render upsamples (chromatrace prepare-texture): one texture per band group.
IMAGE_NODES = ("ShaderNodeTexImage", "ShaderNodeTexEnvironment")
# Blender colour spaces (OpenColorIO names) and how prepare-texture decodes them; others are refused.
IMAGE_COLOUR_SPACES = {"sRGB": "sRGB", "Linear": "linear", "Linear Rec.709": "linear", "Non-Color": "linear",
                       "Raw": "linear"}
_CHANNEL_NODES = {
    "ShaderNodeValToRGB": "a colour ramp makes colours from a scalar",
    "ShaderNodeHueSaturation": "hue/saturation mixes colour channels",
    "ShaderNodeRGBToBW": "RGB to BW mixes colour channels",
    "ShaderNodeRGBCurve": "RGB curves may bend each channel differently",
    "ShaderNodeSeparateRGB": "separating channels treats them differently",
    "ShaderNodeSeparateColor": "separating channels treats them differently",
    "ShaderNodeCombineRGB": "combining channels treats them differently",
    "ShaderNodeCombineColor": "combining channels treats them differently",
    "ShaderNodeSubsurfaceScattering": "subsurface scattering has a radius per channel",
    "ShaderNodeBsdfHairPrincipled": "principled hair derives colour from melanin",
    "ShaderNodeBsdfHair": "hair colour is not a reflectance spectrum",
}
_NOT_SPECTRAL = {
    "ShaderNodeWavelength": "the Wavelength node makes an RGB colour, not a spectrum",
    "ShaderNodeAttribute": "attribute colours are RGB, not spectra",
    "ShaderNodeVertexColor": "vertex colours are RGB, not spectra",
}
_SHADER_CHANNEL_NODES = {"ShaderNodeSubsurfaceScattering", "ShaderNodeBsdfHairPrincipled", "ShaderNodeBsdfHair"}
_MULTISCATTER_NODES = {"ShaderNodeBsdfPrincipled", "ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic",
                       "ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction"}


def _positive(value):
    if value is None:  # linked: a texture or other node decides, so it may be non-zero
        return True
    if isinstance(value, (tuple, list)):  # a colour (Blender 4 tints): only white is neutral
        return any(abs(c - 1.0) > 1e-6 for c in value[:3])
    return value > 0.0


def node_issues(node):
    """[(reason, fallback_helps)] for one shader node the output reaches (a BSDF, emission, ...); what the
    nodes on the way to its colour inputs do is colour_node's."""
    t, props, inputs = node["type"], node.get("props", {}), node.get("inputs", {})
    issues = []
    if t in _SHADER_CHANNEL_NODES:
        issues.append((_CHANNEL_NODES[t], True))
    if t in _MULTISCATTER_NODES and props.get("distribution") == "MULTI_GGX" and \
            props.get("multiscatter", "random-walk") == "random-walk":
        issues.append(("Multiscatter GGX couples the colour channels", True))
    if t == "ShaderNodeBsdfPrincipled":
        # A tint matters only where its lobe has weight (Blender 3: Specular, Sheen; 4: ... IOR Level, Weight).
        for tint, weights in (("Specular Tint", ("Specular", "Specular IOR Level")),
                              ("Sheen Tint", ("Sheen", "Sheen Weight"))):
            lobe_on = any(w in inputs and _positive(inputs[w]) for w in weights) or not any(w in inputs for w in weights)
            if tint in inputs and _positive(inputs[tint]) and lobe_on:
                if isinstance(inputs[tint], (tuple, list)):  # Principled v2 (Blender 4.0+): a colour
                    issues.append((f"a coloured {tint.lower()} makes Cycles weigh the layers below by its strongest "
                                   "channel", True))
                else:
                    issues.append((f"{tint.lower()} takes the hue of the base colour", True))
        for name in ("Subsurface", "Subsurface Weight"):
            if name in inputs and _positive(inputs[name]):
                issues.append(("subsurface scattering has a radius per channel", True))
    return issues


def tree_issues(material_name, nodes, volume_linked=False, kind="material"):
    """Every issue of one material's (light's, world's) reached shader nodes as dicts
    {kind, material (the owner's name), node, reason, fallback}."""
    found = []
    if volume_linked:
        found.append({"kind": kind, "material": material_name, "node": "Material Output",
                      "reason": "volume shaders are not supported", "fallback": False})
    for node in nodes:
        for reason, fallback in node_issues(node):
            found.append({"kind": kind, "material": material_name, "node": node["name"], "reason": reason,
                          "fallback": fallback})
    return found


def summarise(issues, limit=3):
    """One line for messages: 'material "wall", node "Hue": hue/saturation mixes colour channels; ... (+2 more)'."""
    parts = [describe_issue(i) for i in issues[:limit]]
    more = f" (+{len(issues) - limit} more)" if len(issues) > limit else ""
    return "; ".join(parts) + more


# ---- colour paths -------------------------------------------------------------------------------------------

# Nodes that act on each colour channel alike and separately: the colour inputs (identifiers) they pass on.
_PER_CHANNEL = {
    "ShaderNodeMixRGB": ("Color1", "Color2"),
    "ShaderNodeMix": ("A_Color", "B_Color"),
    "ShaderNodeGamma": ("Color",),
    "ShaderNodeInvert": ("Color",),
    "ShaderNodeBrightContrast": ("Color",),
}
# Channel-mixing nodes whose colour input can still be given a spectrum (the one-band fallback renders them).
_MIXING_PASS = {
    "ShaderNodeHueSaturation": ("Color",),
    "ShaderNodeRGBCurve": ("Color",),
}
_NOT_A_SPECTRUM = {
    "ShaderNodeValToRGB": "a colour ramp's colours are RGB, not spectra",
    "ShaderNodeCombineRGB": "combining channels makes an RGB colour from three values, not a spectrum",
    "ShaderNodeCombineColor": "combining channels makes an RGB colour from three values, not a spectrum",
    "ShaderNodeTexSky": "the sky texture makes RGB colours, not spectra",
    "ShaderNodeObjectInfo": "the object colour is RGB, not a spectrum",
    "ShaderNodeParticleInfo": "particle colours are RGB, not spectra",
    "ShaderNodeAmbientOcclusion": "the ambient-occlusion colour output is not converted",
}
_NOT_A_SPECTRUM.update(_NOT_SPECTRAL)


def colour_node(node):
    """What a node does to a colour on its way to a shader, from its description (as node_issues takes):
    {"kind": "constant" | "blackbody" | "pass" | "refused", "inputs": colour input identifiers to follow,
     "issue": (reason, fallback_helps) or None}."""
    t, props = node["type"], node.get("props", {})
    if t == "ShaderNodeRGB":
        return {"kind": "constant", "inputs": (), "issue": None}
    if t == "ShaderNodeBlackbody":
        return {"kind": "blackbody", "inputs": (), "issue": None}
    if t in IMAGE_NODES:
        return {"kind": "image", "inputs": (), "issue": None}
    if t in _PER_CHANNEL and not (t == "ShaderNodeMix" and props.get("data_type", "RGBA") != "RGBA"):
        issue = None
        if t in ("ShaderNodeMixRGB", "ShaderNodeMix") and props.get("blend_type") in _MIXING_BLENDS:
            issue = (f"the {props['blend_type'].lower()} blend mode mixes colour channels", True)
        return {"kind": "pass", "inputs": _PER_CHANNEL[t], "issue": issue}
    if t in _MIXING_PASS:
        return {"kind": "pass", "inputs": _MIXING_PASS[t], "issue": (_CHANNEL_NODES[t], True)}
    if t in _NOT_A_SPECTRUM:
        return {"kind": "refused", "inputs": (), "issue": (_NOT_A_SPECTRUM[t], False)}
    if t.startswith("ShaderNodeTex"):
        return {"kind": "refused", "inputs": (), "issue": ("an RGB texture's colours are not spectra", False)}
    return {"kind": "refused", "inputs": (),
            "issue": (f"the add-on cannot give the colours of a {t} node spectra", False)}


def owner_label(issue):
    """'material "wall"', 'light "Area"' or 'world "World"'."""
    return f"{issue.get('kind', 'material')} \"{issue['material']}\""


def describe_issue(issue):
    """One issue in one line: 'material "wall", node "Hue" (into "Principled BSDF"/"Base Color"): reason'."""
    where = f" (into {issue['socket']})" if issue.get("socket") else ""
    return f"{owner_label(issue)}, node \"{issue['node']}\"{where}: {issue['reason']}"
