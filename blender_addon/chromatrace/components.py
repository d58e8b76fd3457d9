# SPDX-License-Identifier: GPL-3.0-or-later
"""Which Cycles renders and passes make each output component (pure Python, no bpy).

Cycles counts bounces after the first hit: its `max_bounces` = 0 still computes direct light. chromatrace
counts scattering events (0: emitters only, 1: direct light; docs/scene-format.md), so a render with
chromatrace's K uses Cycles' K - 1. Components, as the spectral EXR layout names them:

  emission            Emit (+ Env, the world seen directly, when the world is lit)
  diffuse_direct      DiffDir × DiffCol        (Cycles stores light passes divided by their colour pass)
  diffuse_indirect    DiffInd × DiffCol
  glossy_direct       GlossDir × GlossCol
  glossy_indirect     GlossInd × GlossCol
  transmission_*      TransDir/TransInd × TransCol   (only when the scene has transmissive materials)
  light.<group>       Combined_<group>          (Cycles light groups, Blender 3.2 and later)
  bounce.0            Emit of the render with chromatrace K = 1
  bounce.1            Combined − Emit of that render
  bounce.k, k >= 2    Combined(K = k) − Combined(K = k − 1)

Bounce orders need one render per K = 1 .. max_bounces (each Cycles render with the same seed, so their
differences are less noisy than independent renders would be); the render with K = max_bounces is the
main render that all other components come from.
"""

FAMILIES = ("paths", "lights", "bounces")
MAIN = "main"

PATH_PASSES = {
    "emission": [["Emit"]],
    "diffuse_direct": [["DiffDir", "DiffCol"]],
    "diffuse_indirect": [["DiffInd", "DiffCol"]],
    "glossy_direct": [["GlossDir", "GlossCol"]],
    "glossy_indirect": [["GlossInd", "GlossCol"]],
    "transmission_direct": [["TransDir", "TransCol"]],
    "transmission_indirect": [["TransInd", "TransCol"]],
}
TRANSMISSION = ("transmission_direct", "transmission_indirect")


class ComponentError(ValueError):
    """A component list the user gave that cannot be parsed."""


def parse_components(text, what="--components"):
    """'paths,lights' -> {'paths', 'lights'}; 'all' is every family, 'none' (alone) no family; spaces around items
    are ignored. The grammar and its cases: tests/data/component_grammar.json, shared with the tracer's parser
    (reference_tracer/integrator.cpp)."""
    known = "(known: paths, lights, bounces, all, none)"
    selected, none, family = set(), False, False
    for item in (part.strip(" ") for part in text.split(",")):
        if not item:
            raise ComponentError(f"{what}: an empty item {known}")
        if item == "none":
            none = True
            continue
        family = True
        if item == "all":
            selected.update(FAMILIES)
        elif item in FAMILIES:
            selected.add(item)
        else:
            raise ComponentError(f"{what}: unknown component family \"{item}\" {known}")
    if none and family:
        raise ComponentError(f"{what}: \"none\" cannot be combined with other families")
    return selected


def bounce_variant(k, max_bounces):
    """Name of the render with chromatrace bounce limit k (1 <= k <= max_bounces)."""
    return MAIN if k == max_bounces else f"k{k}"


def render_variants(max_bounces, bounces):
    """{variant name: Cycles max_bounces} of the renders each band group needs, main render last."""
    variants = {}
    if bounces:
        for k in range(1, max_bounces):
            variants[bounce_variant(k, max_bounces)] = k - 1
    variants[MAIN] = max(max_bounces - 1, 0)
    return variants


def _term(passes, file=MAIN, sign=1):
    term = {"passes": list(passes)}
    if file != MAIN:
        term["file"] = file
    if sign != 1:
        term["sign"] = sign
    return term


def component_plan(families, light_groups, max_bounces, transmission=False, environment=False):
    """The total's and each component's terms, for the manifest (see core/assembly.h).

    Returns (total_terms, [{"name": ..., "terms": [...]}, ...]) in the file's component order.
    With max_bounces 0 (emitters only) the caller renders with every reflectance set to 0, so that
    Combined is the emission alone. With `environment` (a lit world) the world seen directly (Cycles' Env
    pass) counts as emission.
    """
    components = []
    emitted = [["Emit"], ["Env"]] if environment else [["Emit"]]
    if "paths" in families:
        for name, products in PATH_PASSES.items():
            if name in TRANSMISSION and not transmission:
                continue
            if name == "emission":
                products = emitted
            components.append({"name": name, "terms": [_term(p) for p in products]})
    if "lights" in families:
        for group in light_groups:
            components.append({"name": f"light.{group}", "terms": [_term([f"Combined_{group}"])]})
    if "bounces" in families:
        if max_bounces == 0:
            components.append({"name": "bounce.0", "terms": [_term(p) for p in emitted]})
        else:
            first = bounce_variant(1, max_bounces)
            components.append({"name": "bounce.0", "terms": [_term(p, first) for p in emitted]})
            components.append({"name": "bounce.1",
                               "terms": [_term(["Combined"], first)] + [_term(p, first, -1) for p in emitted]})
            for k in range(2, max_bounces + 1):
                components.append({"name": f"bounce.{k}",
                                   "terms": [_term(["Combined"], bounce_variant(k, max_bounces)),
                                             _term(["Combined"], bounce_variant(k - 1, max_bounces), -1)]})
    return [_term(["Combined"])], components


def passes_needed(components):
    """Cycles pass names the components read (to switch on in the view layer)."""
    names = {"Combined"}
    for c in components:
        for term in c["terms"]:
            names.update(term["passes"])
    return names
