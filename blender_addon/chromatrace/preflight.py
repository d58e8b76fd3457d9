# SPDX-License-Identifier: GPL-3.0-or-later
"""The pre-flight check of a spectral render (batch.py --explain, the panel's Check button): what a render would
do, without rendering or changing anything."""

import json
import shutil
import tempfile

from . import components, node_resolution, node_rules, textures
from .bands import band_groups, group_samples
from .errors import BadInput
from .scene_parts import scene_parts


def _owner_entry(scene, tool, request, kind, thing, walk, issues, key_of, status_override=None):
    """The pre-flight's entry of one material, light or world: its status, reasons and colours (with the key of
    each colour's source, which preflight replaces by its band values)."""
    name = thing.name
    entry = {"kind": kind, "name": name, "status": None, "reasons": [node_rules.describe_issue(i) for i in issues],
             "colours": []}
    inputs = []
    if status_override is None:
        try:
            inputs = node_resolution.owner_inputs(scene, kind, thing, walk)
        except BadInput as e:
            entry["reasons"].append(str(e))
            entry["status"] = "refused"
    for spectral_input, source, scale in inputs:
        texture = node_resolution.is_texture(source)
        colour = {"input": spectral_input.label, "role": spectral_input.role, "source": source,
                  "scale": scale, "key": key_of(source, spectral_input.role),
                  "upsampled": node_resolution.upsampled(source)}
        if texture:
            try:
                colour["negative_texels"] = textures.texture_noise(tool, source, spectral_input.role)
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
    return entry


def _add_band_values(owners, bands):
    """Each colour's band values (scaled) in place of its source's key; a reflectance above 1 refuses its owner."""
    for entry in owners:
        for colour in entry["colours"]:
            if node_resolution.is_texture(colour["source"]):  # every texel upsampled when the render prepares it
                colour["bands"] = None
                del colour["key"]
                continue
            values = bands["spectra"][colour["key"]]
            colour["bands"] = [v * colour["scale"] for v in values["bands"]]
            problem = colour["role"] == "reflectance" and node_resolution.reflectance_above_one(values, colour["input"])
            if problem:
                entry["status"] = "refused"
                entry["reasons"].append(f"{entry['kind']} \"{entry['name']}\": {problem}")
            del colour["key"]


def preflight(scene, request, tool):
    """Every material, light and the world with its status — "exact" (every colour a spectrum: the add-on's
    spectra, Blackbody nodes, grey), "upsampled" (some colour upsampled from RGB), "refused" (with every reason in
    full), or for the world also "none", "dark" (no light) and "omitted" (refused, rendered without it as asked) —
    and the number of Cycles renders the plan needs (null when something is refused)."""
    _view_layer, _objects, used, lights = scene_parts(scene)
    walks = node_resolution.walks(scene, used, lights)
    world = node_resolution.world_state(scene, walks, request.on_world)
    hard, mixing = node_resolution.node_issues(used, walks, world)
    keys = {}

    def key_of(source, role):
        return keys.setdefault(node_resolution.source_text(source, role), f"s{len(keys)}")

    def report(kind, thing, walk, status_override=None):
        issues = [i for i in hard + mixing if i["kind"] == kind and i["material"] == thing.name]
        return _owner_entry(scene, tool, request, kind, thing, walk, issues, key_of, status_override)

    owners = [report("material", m, walks[("material", m.name)]) for m in used]
    owners += [report("light", ob, walks[("light", ob.name)]) for ob in lights]
    if scene.world is not None:
        status = world["status"]
        owners.append(report("world", scene.world, world["walk"], None if status in ("lit", "refused") else status))
        if status == "omitted":
            owners[-1]["reasons"] = [node_resolution.world_warning(world)]
    else:
        owners.append({"kind": "world", "name": None, "status": "none", "reasons": [], "colours": []})

    work_dir = tempfile.mkdtemp(prefix="chromatrace-")
    try:
        bands = node_resolution.evaluate(tool, request, work_dir, keys)
    finally:
        shutil.rmtree(work_dir, ignore_errors=True)
    _add_band_values(owners, bands)
    edges = bands["bands"]["edges_nm"]
    refused = [e for e in owners if e["status"] == "refused"]
    replicate = bool(mixing) and request.on_mixing_nodes == "one-band"
    per_render = 1 if replicate else request.bands_per_render
    groups = band_groups(len(edges) - 1, per_render)
    variants = components.render_variants(request.max_bounces, "bounces" in request.families)
    renders = None if refused else len(groups) * len(variants) + (1 if request.object_ids else 0)
    return {"format": "chromatrace-preflight/1", "scene": scene.name,
            "ok": not refused, "renders": renders, "bands": len(edges) - 1, "edges_nm": edges,
            "bands_per_render": per_render, "band_groups": len(groups),
            "samples": group_samples(groups, bands["bands"].get("cycles_samples"), request.samples),
            "bounce_limits": len(variants),
            "render_variants": list(variants),
            "object_id_render": bool(request.object_ids), "owners": owners}
