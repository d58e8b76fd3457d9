# SPDX-License-Identifier: GPL-3.0-or-later
"""Node trees: building the ones for chromatrace's material models, and the spectral colour inputs of any
material's, light's or world's tree (found by colour_walk.py, checked by node_rules.py)."""

from collections import namedtuple

import bpy

from . import blender_compat, colour_walk
from .errors import BadInput

REFLECTANCE_NODE = "ct_reflectance"
EMISSION_NODE = "ct_emission"
MANAGED_MODELS = ("LAMBERT", "DICHROMATIC", "MIRROR", "PRINCIPLED", "NONE")
PRINCIPLED_NODE = "ct_principled"

_TRANSMISSION_NODES = ("ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction")
# A colour the spectral render sets: target.attribute gets the band values (× scale), keeping alpha. Roles:
# "reflectance" and "emission" get spectra; "interface" is a grey (spectrally flat) reflectance that keeps its
# value in every band, and like the reflectances becomes 0 when the render shows emitters only.
# source: the spectrum when it is fixed by the node (a Blackbody node's Planck's law), else None; replace: a
# Blackbody node the render replaces by an RGB node (whose colour is then the target), else None.
SpectralInput = namedtuple("SpectralInput", "target attribute role current_rgb alpha label managed source replace",
                           defaults=(None, None))


def _new(nodes, kind, name, location):
    node = nodes.new(kind)
    node.name = node.label = name
    node.location = location
    return node


def build_material_nodes(material):
    """Replaces the material's nodes with those of its chromatrace model: RGB nodes named ct_reflectance and
    ct_emission hold the colours the spectral render sets; a one-sided emitter's strength is 0 on back faces."""
    s = material.chromatrace
    tree = blender_compat.enable_nodes(material)
    nodes, links = tree.nodes, tree.links
    nodes.clear()
    output = _new(nodes, "ShaderNodeOutputMaterial", "ct_output", (600, 0))
    shader = None
    if s.model in ("LAMBERT", "DICHROMATIC", "MIRROR", "PRINCIPLED"):
        if s.reflectance.kind == "TEXTURE":
            colour = _new(nodes, "ShaderNodeTexImage", REFLECTANCE_NODE, (-500, 100))
            colour.image = load_image(s.reflectance.texture_path, s.reflectance.texture_colour_space)
            colour.interpolation = "Closest"  # the reference tracer looks up the nearest texel
        else:
            colour = _new(nodes, "ShaderNodeRGB", REFLECTANCE_NODE, (-400, 100))
            preview = (tuple(s.reflectance.rgb) if s.reflectance.kind == "RGB"
                       else tuple(min(c, 1.0) for c in s.reflectance.preview_colour((0.8, 0.8, 0.8))))
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
        if s.model == "PRINCIPLED":
            principled = _new(nodes, "ShaderNodeBsdfPrincipled", PRINCIPLED_NODE, (-100, 100))
            set_principled(principled, s)
            links.new(colour.outputs[0], principled.inputs["Base Color"])
            shader = principled
        if s.model == "MIRROR":
            glossy = _new(nodes, "ShaderNodeBsdfGlossy", "ct_mirror", (-100, 100))
            glossy.distribution = "GGX"
            glossy.inputs["Roughness"].default_value = 0.0
            links.new(colour.outputs[0], glossy.inputs["Color"])
            shader = glossy
    if s.emissive:
        colour = _new(nodes, "ShaderNodeRGB", EMISSION_NODE, (-400, -250))
        colour.outputs[0].default_value = (*(s.emission.rgb if s.emission.kind == "RGB"
                                             else s.emission.preview_colour((1.0, 1.0, 1.0))), 1.0)
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


def set_principled(node, s):
    """A Principled BSDF node set as the scene format's principled material of `s` (the node's version is the
    running Blender's: 2 from 4.0, with IOR and Specular IOR Level; 1 before, with Specular)."""
    node.distribution = s.distribution if "Specular IOR Level" in node.inputs else "GGX"
    node.inputs["Roughness"].default_value = s.roughness
    if "Specular IOR Level" in node.inputs:
        node.inputs["IOR"].default_value = s.ior
        node.inputs["Specular IOR Level"].default_value = s.specular_ior_level
    else:
        node.inputs["Specular"].default_value = s.principled_specular


def load_image(path, colour_space="auto"):
    """An image file as a Blender image (an existing one of the same file reused), its colour space set as the scene
    format reads it: "sRGB", "linear", or "auto" (Blender's own guess: linear for float files, else sRGB). None
    when the file cannot be read (the render then refuses the node by name)."""
    try:
        image = bpy.data.images.load(bpy.path.abspath(path), check_existing=True)
    except RuntimeError:
        return None
    if colour_space == "sRGB":
        image.colorspace_settings.name = "sRGB"
    elif colour_space == "linear":
        image.colorspace_settings.name = blender_compat.linear_rec709(image)
    return image


def output_node(material):
    if not blender_compat.uses_nodes(material):
        return None
    return material.node_tree.get_output_node("CYCLES")


def walk_material(material):
    """The colour walk of a material's node tree (colour_walk.Walk): its shaders, colours and issues."""
    walk = colour_walk.Walk("material", material.name)
    if material.chromatrace.model == "NODES":
        walk.walk_output(output_node(material))
    else:  # the add-on's own nodes: their colours are its spectral inputs; the shaders are still checked
        walk.walk_output(output_node(material))
        walk.leaves.clear()
    return walk.finish()


def walk_light(light):
    """The colour walk of a light's node tree (when it uses nodes; Cycles ignores the tree otherwise)."""
    walk = colour_walk.Walk("light", light.name)
    if blender_compat.uses_nodes(light):
        walk.walk_output(light.node_tree.get_output_node("CYCLES"))
    return walk.finish()


def walk_world(world):
    """The colour walk of the world: its node tree, or its colour when it uses none (as Cycles renders it)."""
    walk = colour_walk.Walk("world", world.name)
    if blender_compat.uses_nodes(world):
        walk.walk_output(world.node_tree.get_output_node("CYCLES"))
    elif max(world.color) > 0.0:
        leaf = colour_walk.Leaf(world, "color", tuple(world.color), None, f"{world.name}/color")
        leaf.roles.add("emission")
        leaf.sinks.append("\"color\"")
        walk.leaves[("world color",)] = leaf
    return walk.finish()


def has_transmission(walk):
    for _name, node in walk.shaders:
        if node.bl_idname in _TRANSMISSION_NODES:
            return True
        for key in ("Transmission", "Transmission Weight"):
            socket = node.inputs.get(key) if node.bl_idname == "ShaderNodeBsdfPrincipled" else None
            if socket is not None and (socket.is_linked or socket.default_value > 0):
                return True
    return False


def leaf_inputs(walk):
    """The walk's colours as SpectralInputs (a Blackbody node's with its Planck source)."""
    found = []
    for leaf in walk.leaves.values():
        source = {"blackbody_k": leaf.blackbody_k} if leaf.blackbody_k is not None else leaf.texture
        found.append(SpectralInput(leaf.target, leaf.attribute, leaf.role, leaf.rgb, leaf.alpha, leaf.label, False,
                                   source, leaf.replace))
    return found


def spectral_inputs(material, walk):
    """The colour inputs of a material that get spectra, as SpectralInputs (walk: walk_material's)."""
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
            if node.bl_idname == "ShaderNodeTexImage":  # an image texture: its source is the spectrum setting's
                found.append(SpectralInput(node, "image", role, None, None, f"{material.name}/{name}", True))
                continue
            value = node.outputs[0].default_value
            found.append(SpectralInput(node.outputs[0], "default_value", role, tuple(value[:3]), value[3],
                                       f"{material.name}/{name}", True))
        glossy = nodes.get("ct_glossy") if s.model == "DICHROMATIC" else None
        if glossy is not None:  # k_s: spectrally flat, but a reflectance all the same (0 when max bounces is 0)
            value = glossy.inputs["Color"].default_value
            found.append(SpectralInput(glossy.inputs["Color"], "default_value", "interface", tuple(value[:3]),
                                       value[3], f"{material.name}/ct_glossy", True))
        return found
    if not blender_compat.uses_nodes(material):  # Cycles renders the viewport colour, diffusely
        value = material.diffuse_color
        return [SpectralInput(material, "diffuse_color", "reflectance", tuple(value[:3]), value[3],
                              f"{material.name}/diffuse_color", False)]
    return leaf_inputs(walk)


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
