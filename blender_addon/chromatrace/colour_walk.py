# SPDX-License-Identifier: GPL-3.0-or-later
"""Every colour that reaches Cycles, found by following a node tree backwards from its output.

A material's, a light's or the world's tree is walked from the active output node through the links, into node
groups (group nodes, nested groups, their Group Input and Group Output nodes) and through reroutes. A Mix
Shader whose factor is a constant 0 or 1 reaches only one of its shaders (Cycles gives the other weight 0), so
what it does not reach is not checked. Every colour input of every shader reached (BSDFs, Emission,
Background, ...) is followed back to where its colour comes from (node_rules.colour_node):

- a constant (an unlinked colour input, an RGB node): a Leaf the render upsamples and sets per band group;
- a Blackbody node of constant temperature: a Leaf whose spectrum is Planck's law (the node is replaced by an
  RGB node for the render, through the journal);
- an Image or Environment Texture node's colour: a Leaf whose texture source every texel of the image is
  upsampled from (the render gives the node one prepared image per band group); refused when the image cannot
  be read as a file (generated, movie, UDIM tiles), its colour space is neither sRGB nor linear, or its alpha
  output is used (the prepared images carry no alpha);
- a scalar (a Fresnel factor, a Math node, a texture's Fac): grey, the same in every band, so spectrally flat;
- through per-channel nodes (Mix, Gamma, Invert, Bright/Contrast) to their colour inputs;
- through channel-mixing nodes (hue/saturation, RGB curves) to their colour inputs, with an issue the one-band
  fallback may accept;
- anything else (procedural textures, attributes, vertex colours, ramps, vectors used as colours): an issue that
  refuses.

A colour the render converts must not also drive a scalar input (a roughness, a mix factor) that Cycles
reaches: that value would change with the band group. Such a use refuses too.

Issues are node_rules dicts: {kind, material (the owner's name), node, socket, reason, fallback}.
"""

import os

import bpy

from . import blender_compat, node_rules

_SHADER = "SHADER"
_SCALAR = ("VALUE", "INT", "BOOLEAN")

# Roles of colour inputs of shader nodes (as in materials.py): reflectance, interface (spectrally flat when
# grey) or emission. Other colour inputs of shaders (Subsurface Color, ...) are reflectances.
REFLECTANCE_INPUTS = {
    "ShaderNodeBsdfDiffuse": ("Color",), "ShaderNodeBsdfPrincipled": ("Base Color",),
    "ShaderNodeBsdfTranslucent": ("Color",), "ShaderNodeBsdfVelvet": ("Color",), "ShaderNodeBsdfSheen": ("Color",),
    "ShaderNodeBsdfToon": ("Color",),
}
INTERFACE_INPUTS = {
    "ShaderNodeBsdfGlossy": ("Color",), "ShaderNodeBsdfAnisotropic": ("Color",), "ShaderNodeBsdfGlass": ("Color",),
    "ShaderNodeBsdfRefraction": ("Color",), "ShaderNodeBsdfTransparent": ("Color",),
    "ShaderNodeBsdfMetallic": ("Base Color",),
}
EMISSION_INPUTS = {"ShaderNodeEmission": ("Color",), "ShaderNodeBsdfPrincipled": ("Emission", "Emission Color"),
                   "ShaderNodeBackground": ("Color",)}
_STRENGTH = {"ShaderNodeEmission": "Strength", "ShaderNodeBackground": "Strength",
             "ShaderNodeBsdfPrincipled": "Emission Strength"}


def sink_role(node, socket):
    t, name = node.bl_idname, socket.name
    if name in EMISSION_INPUTS.get(t, ()):
        return "emission"
    if name in INTERFACE_INPUTS.get(t, ()):
        return "interface"
    return "reflectance"


class Leaf:
    """A colour the render sets per band group: target.attribute (a socket's default_value, a world's color, an
    image node's image), or a Blackbody node to replace (blackbody_k set, target None). texture: the scene-format
    texture source of an image node's colour ({"texture": path, "colour_space": ...}; "packed:<image>" for an
    image packed into the .blend), else None."""

    def __init__(self, target, attribute, rgb, alpha, label, blackbody_k=None, replace=None, texture=None):
        self.target, self.attribute, self.rgb, self.alpha, self.label = target, attribute, rgb, alpha, label
        self.blackbody_k, self.replace, self.texture = blackbody_k, replace, texture
        self.roles = set()
        self.sinks = []

    @property
    def role(self):
        if self.texture is not None:
            return "emission" if self.roles == {"emission"} else "reflectance"
        if "reflectance" in self.roles or ("interface" in self.roles and max(self.rgb) - min(self.rgb) > 1e-6):
            return "reflectance"
        if "interface" in self.roles:
            return "interface"
        return "emission"


def _ptr(thing):
    return thing.as_pointer()


def _by_identifier(sockets, identifier):
    for s in sockets:
        if s.identifier == identifier:
            return s
    return None


def _live_links(socket):
    if not socket.is_linked:
        return []
    return [l for l in socket.links if l.is_valid and not l.is_muted]


def describe(node):
    props = {}
    for key in ("distribution", "blend_type", "data_type"):
        if hasattr(node, key):
            props[key] = getattr(node, key)
    if props.get("distribution") == "MULTI_GGX":
        props["multiscatter"] = blender_compat.cycles_multiscatter()
    inputs = {}
    for key in ("Specular Tint", "Sheen Tint", "Subsurface", "Subsurface Weight", "Specular", "Specular IOR Level",
                "Sheen", "Sheen Weight"):
        socket = node.inputs.get(key)
        if socket is not None and hasattr(socket, "default_value"):
            value = socket.default_value
            inputs[key] = None if socket.is_linked else (tuple(value) if hasattr(value, "__len__") else value)
    return {"name": node.name, "type": node.bl_idname, "props": props, "inputs": inputs}


class Walk:
    """The walk of one owner's tree. kind: "material", "light" or "world"; name: the owner's name."""

    def __init__(self, kind, name):
        self.kind, self.name = kind, name
        self.issues = []
        self.leaves = {}          # key -> Leaf
        self.shaders = []         # (path, node) of every shader node reached, in order
        self.volume = False
        self._uses = {}           # key of a colour source -> [{modes}, (ctx, node, socket)]
        self._carries = {}        # key -> whether a converted colour flows out of it
        self._seen = set()

    # ---- helpers ---------------------------------------------------------------------------------------

    def _path(self, ctx, node):
        return "".join(f"{g.name} > " for g in ctx) + node.name

    def _issue(self, ctx, node, reason, fallback, sink=None):
        issue = {"kind": self.kind, "material": self.name, "node": self._path(ctx, node) if node is not None else "",
                 "socket": sink, "reason": reason, "fallback": fallback}
        if issue not in self.issues:
            self.issues.append(issue)

    def source(self, ctx, socket):
        """(ctx, node, output socket) that feeds an input socket, through reroutes and group boundaries;
        (ctx, None, socket) when nothing does (its own value counts). ctx: the group nodes entered."""
        for _ in range(10000):
            links = _live_links(socket)
            if not links:
                return ctx, None, socket
            node, out = links[0].from_node, links[0].from_socket
            if node.bl_idname == "NodeReroute":
                socket = node.inputs[0]
                continue
            if node.type == "GROUP":
                tree = node.node_tree
                outputs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"] if tree is not None else []
                active = [n for n in outputs if n.is_active_output] or outputs
                inner = _by_identifier(active[0].inputs, out.identifier) if active else None
                if inner is None:
                    return ctx, None, None  # an empty group output: nothing (black, zero)
                ctx, socket = ctx + (node,), inner
                continue
            if node.type == "GROUP_INPUT":
                if not ctx:
                    return ctx, None, None
                outer = _by_identifier(ctx[-1].inputs, out.identifier)
                if outer is None:
                    return ctx, None, None
                ctx, socket = ctx[:-1], outer
                continue
            return ctx, node, out
        raise RuntimeError("node tree walk does not end (a cycle of reroutes or groups)")

    def constant_scalar(self, ctx, socket):
        """The value of a scalar input when it is a constant (unlinked, through groups), else None."""
        _ctx, node, out = self.source(ctx, socket)
        if node is None and out is not None and out.type in _SCALAR:
            return float(out.default_value)
        if node is None and out is None:
            return 0.0
        if node is not None and node.bl_idname == "ShaderNodeValue":
            return float(node.outputs[0].default_value)
        return None

    def _use(self, key, mode, label):
        entry = self._uses.setdefault(key, [set(), label])
        entry[0].add(mode)

    # ---- the walk --------------------------------------------------------------------------------------

    def walk_output(self, output_node, inputs=("Surface",)):
        if output_node is None:
            return
        for name in inputs:
            socket = output_node.inputs.get(name)
            if socket is not None:
                self.visit_input((), socket, "shader")
        volume = output_node.inputs.get("Volume")
        if volume is not None and _live_links(volume):
            self.volume = True
            self._issue((), output_node, "volume shaders are not supported", False)
        displacement = output_node.inputs.get("Displacement")
        if displacement is not None:
            self.visit_input((), displacement, "other")

    def visit_input(self, ctx, socket, mode, sink=None):
        """Follows one input back; in colour mode, returns whether a converted colour flows into it."""
        sctx, node, out = self.source(ctx, socket)
        if out is None:
            return False
        if node is None:  # a constant: the socket's own value
            key = ("const", tuple(_ptr(g) for g in sctx), _ptr(out))
            self._use(key, mode, (sctx, out.node, out))
            if mode == "colour":
                self._carries[key] = self._constant(key, sctx, out, sink)
                return self._carries[key]
            return False
        key = ("out", tuple(_ptr(g) for g in sctx), _ptr(out))
        self._use(key, mode, (sctx, node, out))
        if out.type == _SHADER:
            self._visit_shader(sctx, node)
            return False
        if mode != "colour" or out.type in _SCALAR:  # a scalar as a colour is grey: the same in every band
            self._visit_other(sctx, node)
            return False
        if out.type != "RGBA":
            self._issue(sctx, node, f"its {out.type.lower()} output is used as a colour", False, sink[2])
            self._visit_other(sctx, node)
            return False
        carries = self._colour_node(key, sctx, node, out, sink)
        self._carries[key] = self._carries.get(key, False) or carries
        return carries

    def _colour_node(self, key, sctx, node, out, sink):
        rule = node_rules.colour_node(describe(node))
        if rule["issue"] is not None:
            self._issue(sctx, node, rule["issue"][0], rule["issue"][1], sink[2])
        if rule["kind"] == "constant":
            self._add_leaf(key, lambda: Leaf(out, "default_value", tuple(out.default_value[:3]), out.default_value[3],
                                             f"{self.name}/{self._path(sctx, node)}"), sink)
            return True
        if rule["kind"] == "blackbody":
            return self._blackbody(key, sctx, node, sink)
        if rule["kind"] == "image":
            return self._image(key, sctx, node, out, sink)
        if rule["kind"] == "pass":
            seen = (key, "colour-pass")
            first = seen not in self._seen
            self._seen.add(seen)
            carries = False
            for s in node.inputs:
                if not getattr(s, "enabled", True):
                    continue
                if s.identifier in rule["inputs"]:
                    carries = self.visit_input(sctx, s, "colour", sink) or carries
                elif first:
                    self.visit_input(sctx, s, "other")
            return carries
        self._visit_other(sctx, node)
        return False

    def _constant(self, key, ctx, socket, sink):
        if socket.type in _SCALAR:
            return False  # grey
        if socket.type != "RGBA" or not hasattr(socket, "default_value"):
            self._issue(ctx, socket.node, f"its {socket.type.lower()} input \"{socket.name}\" is used as a colour",
                        False, sink[2])
            return False
        value = socket.default_value
        node = socket.node
        self._add_leaf(key, lambda: Leaf(socket, "default_value", tuple(value[:3]), value[3],
                                         f"{self.name}/{self._path(ctx, node)}/{socket.name}"), sink)
        return True

    def _blackbody(self, key, ctx, node, sink):
        temperature = self.constant_scalar(ctx, node.inputs["Temperature"])
        if temperature is None:
            self._issue(ctx, node, "its temperature is not a constant, so it has no single spectrum", False, sink[2])
            return False
        bb_key = ("blackbody", _ptr(node))
        leaf = self.leaves.get(bb_key)
        if leaf is not None and leaf.blackbody_k != temperature:
            self._issue(ctx, node, "the group that holds it is used with different temperatures", False, sink[2])
            return False
        self._add_leaf(bb_key, lambda: Leaf(None, "default_value", (1.0, 1.0, 1.0), 1.0,
                                            f"{self.name}/{self._path(ctx, node)}", blackbody_k=temperature,
                                            replace=node), sink)
        return True

    def _image(self, key, ctx, node, out, sink):
        reason = image_problem(node, out)
        if reason is not None:
            self._issue(ctx, node, reason, False, sink[2])
            return False
        image_key = ("image", _ptr(node))
        self._add_leaf(image_key, lambda: Leaf(node, "image", None, None, f"{self.name}/{self._path(ctx, node)}",
                                               texture=texture_source(node.image)), sink)
        leaf = self.leaves[image_key]
        if "emission" in leaf.roles and len(leaf.roles) > 1:
            self._issue(ctx, node, "its image is both an emission and a reflectance, which need different "
                        "upsampling", False, sink[2])
        return True

    def _add_leaf(self, key, make, sink):
        leaf = self.leaves.get(key)
        if leaf is None:
            leaf = self.leaves[key] = make()
        leaf.roles.add(sink[0])
        if sink[2] not in leaf.sinks:
            leaf.sinks.append(sink[2])

    def _visit_other(self, ctx, node):
        key = ("other", tuple(_ptr(g) for g in ctx), _ptr(node))
        if key in self._seen:
            return
        self._seen.add(key)
        for s in node.inputs:
            if getattr(s, "enabled", True) and s.is_linked:
                self.visit_input(ctx, s, "other")

    def _visit_shader(self, ctx, node):
        key = ("shader", tuple(_ptr(g) for g in ctx), _ptr(node))
        if key in self._seen:
            return
        self._seen.add(key)
        path = self._path(ctx, node)
        self.shaders.append((path, node))
        described = describe(node)
        described["name"] = path
        for reason, fallback in node_rules.node_issues(described):
            self._issue(ctx, node, reason, fallback)
        skip = set()
        if node.bl_idname == "ShaderNodeMixShader":
            fac = self.constant_scalar(ctx, node.inputs[0])
            shaders = [s for s in node.inputs if s.type == _SHADER]
            if fac is not None and fac <= 0.0:
                skip.add(_ptr(shaders[1]))
            elif fac is not None and fac >= 1.0:
                skip.add(_ptr(shaders[0]))
        strength_name = _STRENGTH.get(node.bl_idname)
        strength = node.inputs.get(strength_name) if strength_name else None
        no_emission = strength is not None and self.constant_scalar(ctx, strength) == 0.0
        for s in node.inputs:
            if not getattr(s, "enabled", True) or _ptr(s) in skip:
                continue
            if s.type == _SHADER:
                self.visit_input(ctx, s, "shader")
            elif s.type == "RGBA":
                role = sink_role(node, s)
                if role == "emission" and no_emission:
                    continue
                self.visit_input(ctx, s, "colour", (role, node, f"\"{path}\"/\"{s.name}\""))
            else:
                self.visit_input(ctx, s, "other")

    def finish(self):
        """Checks that no converted colour also drives a scalar input; returns self."""
        for key, (modes, (ctx, node, socket)) in self._uses.items():
            if "colour" in modes and "other" in modes and self._carries.get(key):
                self._issue(ctx, node, f"its colour (\"{socket.name}\") also drives a non-colour input, which would "
                            "change with the band", False)
        # Black emission constants emit nothing: not leaves of an emitter.
        for key in [k for k, leaf in self.leaves.items() if leaf.roles == {"emission"} and leaf.blackbody_k is None
                    and leaf.texture is None and max(leaf.rgb) == 0.0]:
            del self.leaves[key]
        return self


def image_problem(node, out):
    """Why an Image or Environment Texture node's colour cannot be upsampled texel by texel, or None."""
    if out.name != "Color":
        return f"its {out.name} output is used as a colour"
    image = node.image
    if image is None:
        return "it has no image"
    if image.source != "FILE":
        kind = {"TILED": "UDIM tiles", "SEQUENCE": "an image sequence", "MOVIE": "a movie",
                "GENERATED": "a generated image", "VIEWER": "a viewer image"}.get(image.source, image.source.lower())
        return f"its image \"{image.name}\" is {kind}, not an image file"
    space = image.colorspace_settings.name
    if space not in node_rules.IMAGE_COLOUR_SPACES:
        return (f"its image \"{image.name}\" has colour space \"{space}\" (only "
                f"{', '.join(sorted(node_rules.IMAGE_COLOUR_SPACES))} are read)")
    alpha = node.outputs.get("Alpha")
    if alpha is not None and _live_links(alpha):
        return "its alpha output is used, which the per-band images the render makes do not carry"
    if image.packed_file is None:
        path = bpy.path.abspath(image.filepath, library=image.library)
        if not os.path.isfile(path):
            return f"its image file {path} does not exist"
    return None


def texture_source(image):
    """The scene-format texture source of an image as Cycles reads it."""
    colour_space = node_rules.IMAGE_COLOUR_SPACES[image.colorspace_settings.name]
    if image.packed_file is not None:
        return {"texture": f"packed:{image.name}", "colour_space": colour_space}
    return {"texture": bpy.path.abspath(image.filepath, library=image.library), "colour_space": colour_space}
