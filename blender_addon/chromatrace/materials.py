"""Node trees: building the ones for chromatrace's material models, finding the spectral colour inputs of
any tree, and describing trees for the channel-mixing checks (node_rules.py)."""

from collections import namedtuple

import bpy

from .errors import BadInput

REFLECTANCE_NODE = "ct_reflectance"
EMISSION_NODE = "ct_emission"
MANAGED_MODELS = ("LAMBERT", "DICHROMATIC", "MIRROR", "NONE")

# Unlinked colour inputs that are reflectances (they get the material's reflectance spectrum) …
_REFLECTANCE_INPUTS = {
    "ShaderNodeBsdfDiffuse": ("Color",), "ShaderNodeBsdfPrincipled": ("Base Color",),
    "ShaderNodeBsdfTranslucent": ("Color",), "ShaderNodeBsdfVelvet": ("Color",), "ShaderNodeBsdfSheen": ("Color",),
    "ShaderNodeBsdfToon": ("Color",),
}
# … interface colours, spectrally flat when grey (left alone then; a non-grey one gets the reflectance) …
_INTERFACE_INPUTS = {
    "ShaderNodeBsdfGlossy": ("Color",), "ShaderNodeBsdfAnisotropic": ("Color",), "ShaderNodeBsdfGlass": ("Color",),
    "ShaderNodeBsdfRefraction": ("Color",), "ShaderNodeBsdfTransparent": ("Color",),
    "ShaderNodeBsdfMetallic": ("Base Color",),
}
# … and emission colours.
_EMISSION_INPUTS = {"ShaderNodeEmission": ("Color",), "ShaderNodeBsdfPrincipled": ("Emission", "Emission Color")}
_TRANSMISSION_NODES = ("ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction")
_RULE_INPUTS = ("Specular Tint", "Sheen Tint", "Subsurface", "Subsurface Weight", "Specular", "Specular IOR Level",
                "Sheen", "Sheen Weight")

# A colour the spectral render sets: target.attribute gets the band values (× scale), keeping alpha. Roles:
# "reflectance" and "emission" get spectra; "interface" is a grey (spectrally flat) reflectance that keeps its
# value in every band, and like the reflectances becomes 0 when the render shows emitters only.
SpectralInput = namedtuple("SpectralInput", "target attribute role current_rgb alpha label managed")


def _new(nodes, kind, name, location):
    node = nodes.new(kind)
    node.name = node.label = name
    node.location = location
    return node


def cycles_ggx_masking():
    """The Smith masking of the running Cycles' GGX (the scene format's "masking"): separable up to Blender 3.x,
    height-correlated from 4.0."""
    return "height-correlated" if bpy.app.version >= (4, 0, 0) else "separable"


def build_material_nodes(material):
    """Replaces the material's nodes with those of its chromatrace model: RGB nodes named ct_reflectance and
    ct_emission hold the colours the spectral render sets; a one-sided emitter's strength is 0 on back faces."""
    s = material.chromatrace
    material.use_nodes = True
    tree = material.node_tree
    nodes, links = tree.nodes, tree.links
    nodes.clear()
    output = _new(nodes, "ShaderNodeOutputMaterial", "ct_output", (600, 0))
    shader = None
    if s.model in ("LAMBERT", "DICHROMATIC", "MIRROR"):
        colour = _new(nodes, "ShaderNodeRGB", REFLECTANCE_NODE, (-400, 100))
        preview = tuple(s.reflectance.rgb) if s.reflectance.kind == "RGB" else (0.8, 0.8, 0.8)
        colour.outputs[0].default_value = (*preview, 1.0)
        if s.model in ("LAMBERT", "DICHROMATIC"):
            diffuse = _new(nodes, "ShaderNodeBsdfDiffuse", "ct_diffuse", (-100, 150))
            diffuse.inputs["Roughness"].default_value = 0.0
            links.new(colour.outputs[0], diffuse.inputs["Color"])
            shader = diffuse
        if s.model == "DICHROMATIC":
            glossy = _new(nodes, "ShaderNodeBsdfGlossy", "ct_glossy", (-100, -50))
            glossy.distribution = "GGX"
            # Phong has no Cycles counterpart (the render refuses it); this roughness only previews it.
            glossy.inputs["Roughness"].default_value = (
                s.roughness if s.lobe == "ggx" else (2.0 / (s.exponent + 2.0)) ** 0.25)
            glossy.inputs["Color"].default_value = (s.specular, s.specular, s.specular, 1.0)
            add = _new(nodes, "ShaderNodeAddShader", "ct_add", (150, 50))
            links.new(diffuse.outputs[0], add.inputs[0])
            links.new(glossy.outputs[0], add.inputs[1])
            shader = add
        if s.model == "MIRROR":
            glossy = _new(nodes, "ShaderNodeBsdfGlossy", "ct_mirror", (-100, 100))
            glossy.distribution = "GGX"
            glossy.inputs["Roughness"].default_value = 0.0
            links.new(colour.outputs[0], glossy.inputs["Color"])
            shader = glossy
    if s.emissive:
        colour = _new(nodes, "ShaderNodeRGB", EMISSION_NODE, (-400, -250))
        colour.outputs[0].default_value = (*(s.emission.rgb if s.emission.kind == "RGB" else (1.0, 1.0, 1.0)), 1.0)
        emission = _new(nodes, "ShaderNodeEmission", "ct_emit", (-100, -250))
        links.new(colour.outputs[0], emission.inputs["Color"])
        if s.two_sided:
            emission.inputs["Strength"].default_value = s.emission_scale
        else:
            geometry = _new(nodes, "ShaderNodeNewGeometry", "ct_geometry", (-700, -400))
            front = _new(nodes, "ShaderNodeMath", "ct_front", (-500, -400))
            front.operation = "SUBTRACT"
            front.inputs[0].default_value = 1.0
            links.new(geometry.outputs["Backfacing"], front.inputs[1])
            strength = _new(nodes, "ShaderNodeMath", "ct_strength", (-300, -400))
            strength.operation = "MULTIPLY"
            strength.inputs[1].default_value = s.emission_scale
            links.new(front.outputs[0], strength.inputs[0])
            links.new(strength.outputs[0], emission.inputs["Strength"])
        if shader is None:
            shader = emission
        else:
            add = _new(nodes, "ShaderNodeAddShader", "ct_add_emission", (350, 0))
            links.new(shader.outputs[0], add.inputs[0])
            links.new(emission.outputs[0], add.inputs[1])
            shader = add
    if shader is not None:
        links.new(shader.outputs[0], output.inputs["Surface"])


def output_node(material):
    if not material.use_nodes or material.node_tree is None:
        return None
    return material.node_tree.get_output_node("CYCLES")


def upstream_nodes(material, into_groups=False):
    """Nodes that feed the active output, as (path name, node); group contents when into_groups."""
    out = output_node(material)
    if out is None:
        return []
    found, order = set(), []

    def visit(node, prefix):
        key = (prefix, node.name)
        if key in found:
            return
        found.add(key)
        order.append((prefix + node.name, node))
        for socket in node.inputs:
            for link in socket.links:
                if link.is_valid and not link.is_muted:
                    visit(link.from_node, prefix)
        if into_groups and node.type == "GROUP" and node.node_tree is not None:
            for inner in node.node_tree.nodes:
                visit(inner, f"{prefix}{node.name} > ")

    visit(out, "")
    return order


def describe_node_tree(material):
    """(node descriptions for node_rules.tree_issues, whether a volume shader is linked)."""
    described = []
    for name, node in upstream_nodes(material, into_groups=True):
        props = {}
        for key in ("distribution", "blend_type", "data_type"):
            if hasattr(node, key):
                props[key] = getattr(node, key)
        inputs = {}
        for key in _RULE_INPUTS:
            socket = node.inputs.get(key)
            if socket is not None:
                value = socket.default_value
                inputs[key] = None if socket.is_linked else (tuple(value) if hasattr(value, "__len__") else value)
        linked = any(o.type == "RGBA" and o.is_linked for o in node.outputs)
        described.append({"name": name, "type": node.bl_idname, "props": props, "inputs": inputs,
                          "colour_output_linked": linked})
    out = output_node(material)
    volume = out is not None and out.inputs.get("Volume") is not None and out.inputs["Volume"].is_linked
    return described, volume


def has_transmission(material):
    for _name, node in upstream_nodes(material, into_groups=True):
        if node.bl_idname in _TRANSMISSION_NODES:
            return True
        for key in ("Transmission", "Transmission Weight"):
            socket = node.inputs.get(key) if node.bl_idname == "ShaderNodeBsdfPrincipled" else None
            if socket is not None and (socket.is_linked or socket.default_value > 0):
                return True
    return False


def _strength_is_zero(node):
    """An emission input whose strength is an unlinked 0 (Blender 4's Principled default) emits nothing."""
    for name in ("Strength", "Emission Strength"):
        socket = node.inputs.get(name)
        if socket is not None:
            return not socket.is_linked and socket.default_value == 0.0
    return False


def _is_grey(rgb):
    return max(rgb) - min(rgb) <= 1e-6


def spectral_inputs(material):
    """The colour inputs of a material that get spectra, as SpectralInputs."""
    s = material.chromatrace
    if s.model in MANAGED_MODELS:
        nodes = material.node_tree.nodes if material.node_tree else {}
        found = []
        for name, role, wanted in ((REFLECTANCE_NODE, "reflectance", s.model != "NONE"),
                                   (EMISSION_NODE, "emission", s.emissive)):
            if not wanted:
                continue
            node = nodes.get(name)
            if node is None:
                raise BadInput(f"material \"{material.name}\": its chromatrace node {name} is missing; "
                               "choose the model again to rebuild the nodes")
            value = node.outputs[0].default_value
            found.append(SpectralInput(node.outputs[0], "default_value", role, tuple(value[:3]), value[3],
                                       f"{material.name}/{name}", True))
        glossy = nodes.get("ct_glossy") if s.model == "DICHROMATIC" else None
        if glossy is not None:  # k_s: spectrally flat, but a reflectance all the same (0 when max bounces is 0)
            value = glossy.inputs["Color"].default_value
            found.append(SpectralInput(glossy.inputs["Color"], "default_value", "interface", tuple(value[:3]),
                                       value[3], f"{material.name}/ct_glossy", True))
        return found
    if not material.use_nodes or material.node_tree is None:  # Cycles renders the viewport colour, diffusely
        value = material.diffuse_color
        return [SpectralInput(material, "diffuse_color", "reflectance", tuple(value[:3]), value[3],
                              f"{material.name}/diffuse_color", False)]

    found = []
    for name, node in upstream_nodes(material):
        kind = node.bl_idname
        candidates = ([(n, "reflectance") for n in _REFLECTANCE_INPUTS.get(kind, ())] +
                      [(n, "interface") for n in _INTERFACE_INPUTS.get(kind, ())] +
                      [(n, "emission") for n in _EMISSION_INPUTS.get(kind, ())])
        for socket_name, role in candidates:
            socket = node.inputs.get(socket_name)
            if socket is None or socket.is_linked or socket.type != "RGBA":
                continue
            rgb = tuple(socket.default_value[:3])
            if role == "interface" and not _is_grey(rgb):
                role = "reflectance"  # a coloured interface: the material's colour after all
            if role == "emission" and (max(rgb) == 0.0 or _strength_is_zero(node)):
                continue
            found.append(SpectralInput(socket, "default_value", role, rgb, socket.default_value[3],
                                       f"{material.name}/{name}/{socket_name}", False))
        if kind == "ShaderNodeRGB":
            targets = [link.to_socket for link in node.outputs[0].links]
            emission_only = targets and all(t.node.bl_idname in _EMISSION_INPUTS and t.name in
                                            _EMISSION_INPUTS[t.node.bl_idname] for t in targets)
            value = node.outputs[0].default_value
            found.append(SpectralInput(node.outputs[0], "default_value", "emission" if emission_only else "reflectance",
                                       tuple(value[:3]), value[3], f"{material.name}/{name}", False))
    return found


def node_tree_digest(tree):
    """A JSON-able description of a node tree (types, settings, unlinked input values, links) for cache keys."""
    if tree is None:
        return None
    nodes = []
    for node in tree.nodes:
        entry = [node.name, node.bl_idname]
        for prop in node.bl_rna.properties:
            if prop.type in ("BOOLEAN", "INT", "FLOAT", "ENUM", "STRING") and not prop.is_readonly \
                    and prop.identifier not in ("name", "label", "location", "width", "height", "select",
                                                "show_options", "show_preview", "hide", "show_texture", "width_hidden"):
                entry.append([prop.identifier, _plain(getattr(node, prop.identifier))])
        for socket in node.inputs:
            if not socket.is_linked and hasattr(socket, "default_value"):
                entry.append([socket.identifier, _plain(socket.default_value)])
        if node.type == "GROUP":
            entry.append(node_tree_digest(node.node_tree))
        nodes.append(entry)
    links = sorted([l.from_node.name, l.from_socket.identifier, l.to_node.name, l.to_socket.identifier]
                   for l in tree.links)
    return [nodes, links]


def _plain(value):
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    if isinstance(value, (set, frozenset)):
        return sorted(value)
    try:
        return [_plain(v) for v in value]
    except TypeError:
        return str(value)
