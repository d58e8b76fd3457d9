# SPDX-License-Identifier: GPL-3.0-or-later
"""A render plan applied to the scene for Cycles, every change through the Journal (put back when the render
ends): Cycles' settings and device, the world dark or lit, Blackbody nodes replaced by colours, the prepared
textures, light groups, object indices, and each band group's colours."""

import bpy

from . import blender_compat, cycles_setup, node_resolution, textures
from .bands import group_colour


def _cycles_preferences():
    return bpy.context.preferences.addons["cycles"].preferences


def _replace_with_rgb(journal, node):
    """Replaces a Blackbody node's links by an RGB node's for the render (the node stays, unlinked); undone
    through the journal. Returns the RGB node's output socket, whose colour the render sets per band group."""
    tree = node.id_data
    targets = [link.to_socket for link in node.outputs[0].links if link.is_valid and not link.is_muted]
    rgb = tree.nodes.new("ShaderNodeRGB")
    rgb.label = f"chromatrace: {node.name}"
    rgb.location = node.location

    def undo():
        tree.nodes.remove(rgb)
        for socket in targets:
            tree.links.new(node.outputs[0], socket)

    journal.call_on_restore(undo)
    for socket in targets:
        tree.links.new(rgb.outputs[0], socket)
    return rgb.outputs[0]


def _remove_lightgroup(scene, view_layer, name):
    groups = view_layer.lightgroups
    if name not in groups.keys():
        return
    if hasattr(groups, "remove"):
        groups.remove(groups[name])
        return
    previous = view_layer.active_lightgroup_index
    view_layer.active_lightgroup_index = groups.keys().index(name)
    with bpy.context.temp_override(scene=scene, view_layer=view_layer):
        bpy.ops.scene.view_layer_remove_lightgroup()
    view_layer.active_lightgroup_index = min(previous, max(len(groups) - 1, 0))


def _set_world(journal, world, plan):
    if world is not None and plan.world["status"] != "lit":  # dark, or omitted as asked: strength 0
        journal.set(world, "color", (0.0, 0.0, 0.0))
        if blender_compat.uses_nodes(world):
            for node in world.node_tree.nodes:
                if node.bl_idname == "ShaderNodeBackground":
                    journal.set(node.inputs["Strength"], "default_value", 0.0)
    if world is not None and plan.world_group and world.lightgroup != plan.world_group:
        journal.set(world, "lightgroup", plan.world_group)
    resolution = world_map(world, plan)
    if resolution is not None:
        journal.set(world.cycles, "sampling_method", "MANUAL")
        journal.set(world.cycles, "sample_map_resolution", resolution)


def world_map(world, plan):
    """The importance map resolution the band groups' renders give a lit world (cycles_setup.world_map_resolution),
    or None where they leave its sampling as it is; part of the cache key."""
    settings = getattr(world, "cycles", None) if world is not None else None
    if settings is None or plan.world["status"] != "lit" or not blender_compat.uses_nodes(world):
        return None
    widths = [node.image.size[0] for node in world.node_tree.nodes
              if node.bl_idname == "ShaderNodeTexEnvironment" and node.image is not None]
    return cycles_setup.world_map_resolution(getattr(settings, "sampling_method", None), widths)


def apply_settings(journal, scene, request, plan, resolution):
    """Everything the renders of `plan` share, set on `scene`; plan.device is the device chosen."""
    view_layer = plan.view_layer
    cycles_setup.apply(journal, scene, view_layer, request.samples, request.seed, request.point_filter,
                       resolution, plan.passes)
    if plan.light_tree is not None:
        cycles_setup.set_light_tree(journal, scene, plan.light_tree)
    plan.device = cycles_setup.select_device(journal, scene, _cycles_preferences(), request.device)
    _set_world(journal, scene.world, plan)
    for ob in plan.lights:  # its Temperature is in the light's spectrum (node_resolution.owner_inputs)
        if node_resolution.light_temperature(ob.data) is not None:
            journal.set(ob.data, "use_temperature", False)
    for spectral_input, _key, _scale, _owner in plan.inputs:
        node = spectral_input.replace
        if node is not None and node.as_pointer() not in plan.replaced:
            plan.replaced[node.as_pointer()] = _replace_with_rgb(journal, node)
    textures.load_textures(journal, plan, request.max_bounces)
    existing = set(view_layer.lightgroups.keys()) if hasattr(view_layer, "lightgroups") else set()
    for group in plan.light_groups:
        if group not in existing:
            view_layer.lightgroups.add(name=group)
            existing.add(group)
            journal.call_on_restore(lambda name=group: _remove_lightgroup(scene, view_layer, name))
    for ob in plan.objects:
        if ob.name in plan.assignments and ob.lightgroup != plan.assignments[ob.name]:
            journal.set(ob, "lightgroup", plan.assignments[ob.name])
        if ob.name in plan.ids and ob.pass_index != plan.ids[ob.name]:
            journal.set(ob, "pass_index", plan.ids[ob.name])


# The roles whose colours show where emitters alone are rendered (max bounces 0).
EMITTING_ROLES = ("emission", node_resolution.FILTER)


def set_colours(journal, plan, group, max_bounces):
    """Every spectral input's colour (or prepared image) for the band group `group`; with `max_bounces` 0 only
    the emitters show, the reflectances black."""
    no_reflection = max_bounces == 0  # emitters only
    index = plan.groups.index(group)
    for spectral_input, key, scale, _owner in plan.inputs:
        if key in plan.textures:
            image = plan.texture_images[key][index]
            if no_reflection and spectral_input.role not in EMITTING_ROLES:
                image = plan.texture_images[None][0]
            journal.set(spectral_input.target, "image", image)
            continue
        values = plan.bands["spectra"][key]["bands"]
        r, g, b = group_colour(values, group, plan.replicate)
        factor = 0.0 if no_reflection and spectral_input.role not in EMITTING_ROLES else scale
        colour = (r * factor, g * factor, b * factor)
        if spectral_input.alpha is not None:
            colour = (*colour, spectral_input.alpha)
        target = spectral_input.target
        if spectral_input.replace is not None:
            target = plan.replaced[spectral_input.replace.as_pointer()]
        journal.set(target, spectral_input.attribute, colour)
