"""Which shader nodes break band multiplexing (pure Python, no bpy).

Multiplexing puts three different bands in R, G and B and reads each channel back as its own band. That is
exact when every node treats the three channels alike and separately (any per-channel function, even a
non-linear one, gives each band what a render of that band alone would). It fails where a node mixes
channels or treats them differently — Principled specular or sheen tint (the highlight takes the hue of
the base colour), Multiscatter GGX, subsurface radii per channel, colour ramps, hue/saturation, RGB curves,
colour-to-BW, separating or combining channels, hue/saturation/colour/value blend modes. Rendering one band
per render, copied to all three channels, makes those nodes see grey and act on each band alone: the
"one-band" fallback. Some inputs are not spectra at all (RGB textures, vertex colours, the Blackbody and
Wavelength nodes, volumes): no fallback helps, so those always refuse.

A node is described as a dict (materials.describe_node_tree makes them from Blender nodes):
  {"name": "Principled BSDF", "type": "ShaderNodeBsdfPrincipled", "props": {"distribution": "GGX"},
   "inputs": {"Specular Tint": 0.0, ...}  (values of unlinked inputs),
   "colour_output_linked": True}         (whether a colour output feeds anything)
"""

_MIXING_BLENDS = {"HUE", "SATURATION", "COLOR", "VALUE"}
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
    "ShaderNodeBlackbody": "the Blackbody node makes an RGB colour, not a spectrum (use a blackbody emission spectrum)",
    "ShaderNodeWavelength": "the Wavelength node makes an RGB colour, not a spectrum",
    "ShaderNodeAttribute": "attribute colours are RGB, not spectra",
    "ShaderNodeVertexColor": "vertex colours are RGB, not spectra",
}
_MULTISCATTER_NODES = {"ShaderNodeBsdfPrincipled", "ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic",
                       "ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction"}


def _positive(value):
    if value is None:  # linked: a texture or other node decides, so it may be non-zero
        return True
    if isinstance(value, (tuple, list)):  # a colour (Blender 4 tints): only white is neutral
        return any(abs(c - 1.0) > 1e-6 for c in value[:3])
    return value > 0.0


def node_issues(node):
    """[(reason, fallback_helps)] for one node."""
    t, props, inputs = node["type"], node.get("props", {}), node.get("inputs", {})
    issues = []
    if t in _NOT_SPECTRAL:
        issues.append((_NOT_SPECTRAL[t], False))
    if t.startswith("ShaderNodeTex") and node.get("colour_output_linked"):
        issues.append(("an RGB texture's colours are not spectra", False))
    if t in _CHANNEL_NODES:
        issues.append((_CHANNEL_NODES[t], True))
    if t in ("ShaderNodeMixRGB", "ShaderNodeMix") and props.get("blend_type") in _MIXING_BLENDS \
            and props.get("data_type", "RGBA") == "RGBA":
        issues.append((f"the {props['blend_type'].lower()} blend mode mixes colour channels", True))
    if t in _MULTISCATTER_NODES and props.get("distribution") == "MULTI_GGX":
        issues.append(("Multiscatter GGX couples the colour channels", True))
    if t == "ShaderNodeBsdfPrincipled":
        # A tint matters only where its lobe has weight (Blender 3: Specular, Sheen; 4: ... IOR Level, Weight).
        for tint, weights in (("Specular Tint", ("Specular", "Specular IOR Level")),
                              ("Sheen Tint", ("Sheen", "Sheen Weight"))):
            lobe_on = any(w in inputs and _positive(inputs[w]) for w in weights) or not any(w in inputs for w in weights)
            if tint in inputs and _positive(inputs[tint]) and lobe_on:
                issues.append((f"{tint.lower()} takes the hue of the base colour", True))
        for name in ("Subsurface", "Subsurface Weight"):
            if name in inputs and _positive(inputs[name]):
                issues.append(("subsurface scattering has a radius per channel", True))
    return issues


def tree_issues(material_name, nodes, volume_linked=False):
    """Every issue of one material's node tree as dicts {material, node, reason, fallback}."""
    found = []
    if volume_linked:
        found.append({"material": material_name, "node": "Material Output",
                      "reason": "volume shaders are not supported", "fallback": False})
    for node in nodes:
        for reason, fallback in node_issues(node):
            found.append({"material": material_name, "node": node["name"], "reason": reason, "fallback": fallback})
    return found


def summarise(issues, limit=3):
    """One line for messages: 'material "wall", node "Hue": hue/saturation mixes colour channels; ... (+2 more)'."""
    parts = [f"material \"{i['material']}\", node \"{i['node']}\": {i['reason']}" for i in issues[:limit]]
    more = f" (+{len(issues) - limit} more)" if len(issues) > limit else ""
    return "; ".join(parts) + more
