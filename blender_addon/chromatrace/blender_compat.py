# SPDX-License-Identifier: GPL-3.0-or-later
"""What differs between the Blenders the add-on supports (3.4 to 5.3), each in one function, chosen by what the
running Blender has wherever its API can say so; the rest of the add-on asks here and never looks at a version.

- Node trees: up to 4.x a material, world or light renders its node tree only with `use_nodes` on; from 5.0
  materials and worlds always have one and `use_nodes` is deprecated (lights keep the switch).
- Multilayer OpenEXR: a file format up to 4.x; from 5.0 the format of the multilayer media type, written as
  one part per pass unless interleaved (cycles_setup.multilayer_exr).
- Pass names in the files Cycles writes: short ("DiffDir") up to 4.x, spelt out ("Diffuse Direct") from 5.0.
- The Smith masking of Cycles' GGX: separable up to 3.x, height-correlated from 4.0.
- Multiscatter GGX: a random walk shared by the colour channels up to 3.x, a per-channel albedo scaling from 4.0.
- The linear Rec.709 colour space: "Linear" up to 3.x, "Linear Rec.709" from 4.0.
- A light's power: an area light of P W and area A emits P/(4A) up to 3.x, P/(πA) from 4.0 (P/π where not
  normalised); a point light of radius r emits P/(4π·πr²) in every version (light_radiance_per_watt).
- Principled BSDF: version 1 up to 3.x (Specular, Sheen and Clearcoat weights, tints as factors of the base
  colour's hue), version 2 from 4.0 (Specular IOR Level, Coat and Sheen Weight, tints as colours, which Cycles
  layers by their strongest channel); the node rules read whichever inputs the node has
  (node_rules.node_issues).
"""

import math

import bpy

# Blender 5.0's names of the passes whose files' channels chromatrace reads (RE_PASSNAME_* in Blender's source);
# the short names before it are the keys. Only a render can list a Blender's pass names, so the version decides.
_SPELT_OUT_PASSES = {
    "Emit": "Emission", "Env": "Environment",
    "DiffDir": "Diffuse Direct", "DiffInd": "Diffuse Indirect", "DiffCol": "Diffuse Color",
    "GlossDir": "Glossy Direct", "GlossInd": "Glossy Indirect", "GlossCol": "Glossy Color",
    "TransDir": "Transmission Direct", "TransInd": "Transmission Indirect", "TransCol": "Transmission Color",
    "IndexOB": "Object Index",
}


def pass_names():
    """{short pass name: the name the running Blender writes into a multilayer EXR}, or {} where they are the same."""
    return dict(_SPELT_OUT_PASSES) if bpy.app.version >= (5, 0, 0) else {}


def _node_switch(idblock):
    """The `use_nodes` property of a material, world or light, or None where Blender no longer has one to set."""
    prop = idblock.bl_rna.properties.get("use_nodes")
    return None if prop is None or getattr(prop, "is_deprecated", False) else prop


def uses_nodes(idblock):
    """Whether Cycles renders this material's, world's or light's node tree."""
    if idblock is None or idblock.node_tree is None:
        return False
    return _node_switch(idblock) is None or idblock.use_nodes


def enable_nodes(idblock, journal=None):
    """Makes a material, world or light render its node tree (through the journal when given), and returns it."""
    if _node_switch(idblock) is not None and not idblock.use_nodes:
        if journal is not None:
            journal.set(idblock, "use_nodes", True)
        else:
            idblock.use_nodes = True
    return idblock.node_tree


def cycles_ggx_masking():
    """The Smith masking of the running Cycles' GGX (the scene format's "masking"): Cycles 4.0 rewrote its
    microfacet closures with height-correlated masking-shadowing. No API reports it, so the version decides."""
    return "height-correlated" if bpy.app.version >= (4, 0, 0) else "separable"


def cycles_multiscatter():
    """How the running Cycles' Multiscatter GGX adds the light of several microfacet bounces: Heitz's random walk
    up to 3.x, whose colour channels share one walk (so they couple), or from 4.0 an albedo-scaling factor that
    multiplies each channel by a function of its own Fresnel (bsdf_microfacet.h, microfacet_ggx_preserve_energy).
    No API reports it, so the version decides."""
    return "albedo-scaling" if bpy.app.version >= (4, 0, 0) else "random-walk"


def linear_rec709(image):
    """The name of linear Rec.709 (linear sRGB) among the colour spaces the running Blender offers an image."""
    names = image.colorspace_settings.bl_rna.properties["name"].enum_items.keys()
    return "Linear Rec.709" if "Linear Rec.709" in names else "Linear"


def principled_version():
    """The Principled BSDF's version in the running Blender: 2 from 4.0 (Specular IOR Level, layered), 1 before."""
    return 2 if bpy.app.version >= (4, 0, 0) else 1


def light_radiance_per_watt(light, area):
    """The radiance (in Cycles' units, those of an Emission shader of strength 1) that one watt of `light`'s power
    gives its surface: an area light of `area` m² (its size times its object's scale), or a point light's sphere.
    No API reports it, so the version decides; measured on 3.4, 4.5 and 5.3 against an emitting mesh of the light's
    shape; blender.cross_validate.blender_lights holds it (tests/blender/cross_validate.py). A 4.x light's Exposure multiplies it by 2^exposure."""
    normalised = getattr(light, "normalize", True)
    exposure = 2.0 ** float(getattr(light, "exposure", 0.0))
    if light.type == "AREA":
        if bpy.app.version < (4, 0, 0):
            return exposure * 0.25 / area
        return exposure / (math.pi * (area if normalised else 1.0))
    if light.type == "POINT":
        r = float(light.shadow_soft_size)
        return exposure / (math.pi * (4.0 * math.pi * r * r if normalised else 1.0))
    raise ValueError(f"no radiance per watt for a {light.type} light")
