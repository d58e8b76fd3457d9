# SPDX-License-Identifier: GPL-3.0-or-later
"""The description of everything that decides a spectral render's pixels — the add-on and Blender, bands and
band values, textures, samples and bounces, passes, geometry, node trees, camera, world and every Cycles and
render setting the render does not set itself — which cache.cache_key hashes into the name of its cache."""

import hashlib
import json

import bpy

from . import VERSION, blender_compat, cycles_setup, materials, render_setup
from .geometry_digest import update_with_mesh

# Settings that cannot change a final render's pixels (the viewport's, baking, stamps and output naming, which
# Cycles writes as metadata, debugging), by name prefix: left out of the cache key, so that changing one does not
# render again.
_NOT_PIXELS = ("name", "preview_", "debug_", "bake", "use_bake", "use_stamp", "stamp_", "metadata_", "threads",
               "use_lock_interface", "use_auto_tile", "tile_size", "use_placeholder", "use_overwrite", "frame_map",
               "fps", "file_extension", "is_movie_format", "views_format", "sequencer_gl_preview", "use_render_cache",
               "has_multiple_engines", "simplify_gpencil", "line_thickness")
# An object's (and a light object's) visibility to each kind of ray.
_RAY_VISIBILITY = ("visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission",
                   "visible_volume_scatter", "visible_shadow", "is_holdout", "is_shadow_catcher",
                   "show_instancer_for_render")
# The view layer's filter: which kinds of things it renders.
_VIEW_LAYER_FILTER = ("use_solid", "use_sky", "use_ao", "use_strand", "use_volumes", "use_motion_blur")


def _rna_plain(struct):
    values = {}
    if struct is None:
        return values
    for prop in struct.bl_rna.properties:
        if prop.type in ("BOOLEAN", "INT", "FLOAT", "ENUM", "STRING") and prop.identifier != "rna_type":
            value = getattr(struct, prop.identifier)
            values[prop.identifier] = materials._plain(value)
    return values


def _pixel_settings(struct, fixed=()):
    """The plain settings of an RNA struct that may change a render's pixels: all but those that cannot
    (_NOT_PIXELS) and those the render sets itself (`fixed`)."""
    return {k: v for k, v in _rna_plain(struct).items() if k not in fixed and not k.startswith(_NOT_PIXELS)}


def _object_digest(ob, depsgraph):
    """A hash of what an object brings to the pixels: its place, ray visibility and Cycles settings, and a
    light's settings and nodes or a geometry's evaluated mesh, smoothing and material slots."""
    digest = hashlib.sha256()
    digest.update(repr([list(row) for row in ob.matrix_world]).encode())
    digest.update(json.dumps([[getattr(ob, a, None) for a in _RAY_VISIBILITY],
                              _rna_plain(getattr(ob, "cycles", None))], sort_keys=True).encode())
    if ob.type == "LIGHT":
        digest.update(json.dumps([_rna_plain(ob.data), _rna_plain(getattr(ob.data, "cycles", None))],
                                 sort_keys=True).encode())
        if blender_compat.uses_nodes(ob.data):
            digest.update(json.dumps(materials.node_tree_digest(ob.data.node_tree)).encode())
    else:
        evaluated = ob.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        if mesh is not None:
            update_with_mesh(digest, mesh)
            digest.update(repr([p.use_smooth for p in mesh.polygons]).encode())
            evaluated.to_mesh_clear()
        digest.update(repr([s.material.name if s.material else None for s in ob.material_slots]).encode())
    return digest.hexdigest()


def cache_description(scene, request, plan, resolution):
    """The JSON-able description of the renders `plan` makes of `scene` at `resolution`."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    geometry = {ob.name: _object_digest(ob, depsgraph) for ob in plan.objects}
    camera = scene.camera
    world = scene.world
    world_map = render_setup.world_map(world, plan)
    focus = camera.data.dof.focus_object
    view_layer = plan.view_layer
    return {
        "addon": list(VERSION), "blender": bpy.app.version_string,
        "edges": plan.edges, "per_render": plan.per_render, "replicate": plan.replicate,
        # Each render's bands (interleaved: bands.band_groups); caches of consecutive groups are not these renders.
        "groups": plan.groups,
        "inputs": [[i.label, i.role, key, scale] for i, key, scale, _owner in plan.inputs],
        "averages": {k: v["bands"] for k, v in plan.bands["spectra"].items()},
        "textures": {k: v["hash"] for k, v in plan.textures.items()},
        # A plan's samples per band group; otherwise the one number, as before (caches made earlier stay valid).
        "samples": plan.samples if plan.planned_samples else request.samples,
        # The guided groups' adaptive sampling, where the band plan asks for it (absent otherwise, as before).
        **({"adaptive": plan.adaptive} if any(plan.adaptive) else {}),
        # Cycles' light tree where the band plan sets it (absent otherwise, as before: then the scene's own, below).
        **({"light_tree": plan.light_tree} if plan.light_tree is not None else {}),
        "seed": request.seed, "max_bounces": request.max_bounces,
        "device": request.device, "variants": plan.variants, "point_filter": request.point_filter,
        "resolution": resolution,
        "passes": sorted(plan.passes), "light_groups": plan.assignments, "ids": plan.ids,
        "geometry": geometry,
        "nodes": {m.name: materials.node_tree_digest(m.node_tree) for m in plan.materials},
        "material_settings": {m.name: _rna_plain(getattr(m, "cycles", None)) for m in plan.materials},
        "camera": [repr([list(r) for r in camera.matrix_world]), _rna_plain(camera.data),
                   _rna_plain(getattr(camera.data, "cycles", None))],
        # Depth of field: f-stop, focus distance or object, the aperture's blades, rotation and ratio.
        "depth_of_field": [_rna_plain(camera.data.dof),
                           repr([list(r) for r in focus.matrix_world]) if focus is not None else None],
        "world": materials.node_tree_digest(world.node_tree) if blender_compat.uses_nodes(world) else None,
        "world_state": [plan.world["status"], plan.world_group,
                        list(world.color) if world is not None else None],
        "world_settings": [_rna_plain(getattr(world, "cycles", None)),
                           _rna_plain(getattr(world, "cycles_visibility", None))] if world is not None else None,
        # The importance map the groups' renders give it (absent where they leave it, as before).
        **({"world_map": world_map} if world_map else {}),
        # Cycles and render settings the render does not set itself: light paths (transparent bounces,
        # minimum bounces, volume steps), sampling pattern, dicing, culling, film transparency of glass, …
        "cycles": _pixel_settings(scene.cycles, cycles_setup.FIXED["cycles"]),
        "render": _pixel_settings(scene.render, cycles_setup.FIXED["render"]),
        "view_layer": [[getattr(view_layer, a, None) for a in _VIEW_LAYER_FILTER],
                       view_layer.material_override.name if view_layer.material_override else None],
    }
