# SPDX-License-Identifier: GPL-3.0-or-later
"""What of a scene a spectral render renders: the view layer, the objects and lights it shows, the materials they
use, the light groups that split the light by emitter, and the object ids."""

import re

from .errors import BadInput

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES", "POINTCLOUD", "VOLUME"}


def used_materials(objects):
    """The materials of the objects' slots, each once, in slot order."""
    used = []
    for ob in objects:
        for slot in getattr(ob, "material_slots", []):
            if slot.material is not None and slot.material not in used:
                used.append(slot.material)
    return used


def render_view_layer(scene):
    for layer in scene.view_layers:
        if layer.use:
            return layer
    raise BadInput(f"scene \"{scene.name}\": no view layer is enabled for rendering")


def scene_parts(scene):
    """(view layer, objects, used materials, light objects (one per light datablock))."""
    view_layer = render_view_layer(scene)
    if scene.camera is None:
        raise BadInput(f"scene \"{scene.name}\": no camera")
    objects = [ob for ob in view_layer.objects
               if not ob.hide_render and (ob.type in GEOMETRY_TYPES or ob.type == "LIGHT")]
    lights, seen = [], set()
    for ob in objects:
        if ob.type == "LIGHT" and ob.data.as_pointer() not in seen:
            seen.add(ob.data.as_pointer())
            lights.append(ob)
    return view_layer, objects, used_materials(objects), lights


def group_name(name):
    """A light group's name from an object's: letters, digits, _ and - only."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", name) or "group"


def light_groups(scene, families, view_layer, objects, emitters, world):
    """Light groups: every emitter in one (its own, or one named after it), a lit world too; none without the
    lights family. Returns (groups, {object name: group}, the world's group or None)."""
    groups, assignments = [], {}
    if "lights" not in families:
        return groups, assignments, None
    if not hasattr(view_layer, "lightgroups"):
        raise BadInput("light-group components need Blender 3.2 or later (or leave out the lights family)")
    for ob in objects:
        emits = ob.type == "LIGHT" or any(
            slot.material is not None and slot.material.name in emitters for slot in ob.material_slots)
        if not emits:
            continue
        group = ob.lightgroup or group_name(ob.name)
        assignments[ob.name] = group
        if group not in groups:
            groups.append(group)
    world_group = None
    if world["status"] == "lit":
        world_group = scene.world.lightgroup or "environment"  # the scene format's default, as Export writes it
        if world_group not in groups:
            groups.append(world_group)
    return groups, assignments, world_group


def object_ids(objects, wanted):
    """Object ids, written by their own render (manifest.IDS_FILE), not by the band renders: the objects' pass
    indices when they are distinct and positive, else 1, 2, … by name; none unless `wanted`."""
    if not wanted:
        return {}
    geometry = [ob for ob in objects if ob.type in GEOMETRY_TYPES]
    indices = [ob.pass_index for ob in geometry]
    if all(i > 0 for i in indices) and len(set(indices)) == len(indices):
        return {ob.name: ob.pass_index for ob in geometry}
    return {ob.name: i + 1 for i, ob in enumerate(sorted(geometry, key=lambda o: o.name))}
