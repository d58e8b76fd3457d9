# SPDX-License-Identifier: GPL-3.0-or-later
"""The manifest that `chromatrace assemble` turns into a spectral EXR (pure Python, no bpy).

Format `chromatrace-assemble/1`, documented in core/assembly.h.
"""

import os

from .bands import channel_of
from .components import MAIN

FORMAT = "chromatrace-assemble/1"


def render_file_name(group_index, variant):
    """File of one Cycles render in the cache: g003_main.exr, g003_k2.exr."""
    return f"g{group_index:03d}_{variant}.exr"


# The object-id render: one sample at each pixel's centre (cycles_setup.pixel_filter(point=True)), so that a
# pixel's id is the object at its centre, as in the reference tracer, whichever sample Cycles takes data passes
# from in the band renders.
IDS_FILE = "ids.exr"


def build_manifest(edges_nm, groups, variants, view_layer, total, components, object_names=None,
                   attributes=None, replicate=False, sum_tolerance=1e-4, reconstruction=None, pass_names=None,
                   guided_bands=None, guided_adaptive=None):
    """The manifest dict, with file paths relative to the directory the manifest is written to.

    groups: lists of band indices, one per render; variants: names of the renders every group has
    (components.render_variants); object_names: {id: name} when the renders carry the Object Index pass;
    replicate: one band per render copied to R, G and B (read back from R); reconstruction: the band plan's
    reconstruction ({"lo_nm", "step_nm", "matrix"}), which the EXR header carries; pass_names: {short pass name:
    the name in the files} where the running Blender writes other names than the components use
    (blender_compat.pass_names); guided_bands: the bands rendered with few samples, which the assembly reconstructs
    from the others (core/guided.h); guided_adaptive: (threshold, most samples) of their renders' adaptive sampling
    (bands.guided_adaptive), which the header records.
    """
    renamed = dict(pass_names or {})
    total = _renamed_terms(total, renamed)
    components = [dict(c, terms=_renamed_terms(c["terms"], renamed)) for c in components]
    band_count = len(edges_nm) - 1
    bands = [None] * band_count
    for g, group in enumerate(groups):
        for band in group:
            bands[band] = {"channel": "R" if replicate else channel_of(group, band),
                           "files": {v: render_file_name(g, v) for v in variants}}
    missing = [i for i, b in enumerate(bands) if b is None]
    if missing:
        raise ValueError(f"bands {missing} are in no group")
    manifest = {
        "format": FORMAT,
        "edges_nm": list(edges_nm),
        "view_layer": view_layer,
        "bands": bands,
        "total": total,
        "components": components,
        "sum_tolerance": sum_tolerance,
    }
    if object_names is not None:
        manifest["object_ids"] = {"file": IDS_FILE,
                                  "channel": _join(view_layer, f"{renamed.get('IndexOB', 'IndexOB')}.X")}
        manifest["object_names"] = {str(i): name for i, name in sorted(object_names.items())}
    if attributes:
        manifest["attributes"] = dict(attributes)
    if reconstruction is not None:
        manifest["reconstruction"] = reconstruction
    if guided_bands:
        manifest["guided"] = {"bands": sorted(guided_bands)}
        if guided_adaptive:
            manifest["guided"]["adaptive"] = {"threshold": guided_adaptive[0], "max_samples": guided_adaptive[1]}
    return manifest


def channels_by_file(document):
    """{render file: the channels `chromatrace assemble` reads from it} of a manifest: what each file in the cache
    must hold to be used."""
    view_layer = document["view_layer"]
    wanted = {}
    expressions = [document["total"]] + [c["terms"] for c in document.get("components", [])]
    for band in document["bands"]:
        for terms in expressions:
            for term in terms:
                channels = wanted.setdefault(band["files"][term.get("file", MAIN)], set())
                channels.update(_join(view_layer, f"{p}.{band['channel']}") for p in term["passes"])
    if "object_ids" in document:
        wanted.setdefault(document["object_ids"]["file"], set()).add(document["object_ids"]["channel"])
    return wanted


def _renamed_terms(terms, names):
    return [dict(t, passes=[names.get(p, p) for p in t["passes"]]) for t in terms]


def _join(view_layer, name):
    return f"{view_layer}.{name}" if view_layer else name


def missing_renders(directory, groups, variants):
    """(group index, variant) of the renders not yet in `directory` (a resumed run renders only these)."""
    return [(g, v) for g in range(len(groups)) for v in variants
            if not os.path.isfile(os.path.join(directory, render_file_name(g, v)))]
