# SPDX-License-Identifier: GPL-3.0-or-later
"""Exporting a Blender scene to a `chromatrace-scene/1` file, meshes as PLY files beside it.

An object or camera still as imported is written as the scene file had it (its analytic shape, camera
and spectrum sources), so import followed by export loses nothing; anything changed or made in Blender is
written from Blender's data: meshes in world space (with vertex normals when smooth-shaded), the camera
with a horizontal field of view. The result is checked with `chromatrace check-scene`.
"""

import json
import math
import os

import bpy

from . import blender_compat, materials, ply
from .errors import BadInput
from .floats import short_float
from .geometry_digest import camera_digest, object_digest


def _spectrum_ref(settings, current_rgb, out_dir):
    return settings.to_json(current_rgb=current_rgb, base_dir=out_dir)


def _reflectance_rgb(material):
    node = material.node_tree.nodes.get("ct_reflectance") if material.node_tree else None
    return tuple(node.outputs[0].default_value[:3]) if node else tuple(material.diffuse_color[:3])


def _material_entry(material, out_dir, log):
    s = material.chromatrace
    reflectance = _spectrum_ref(s.reflectance, _reflectance_rgb(material), out_dir)
    if s.model == "DICHROMATIC":
        entry = {"type": "dichromatic", "diffuse": reflectance, "specular": short_float(s.specular), "lobe": s.lobe}
        entry["roughness" if s.lobe == "ggx" else "exponent"] = short_float(s.roughness if s.lobe == "ggx" else s.exponent)
        if s.lobe == "ggx" and blender_compat.cycles_ggx_masking() != "separable":  # the format's default
            entry["masking"] = blender_compat.cycles_ggx_masking()
        return entry
    if s.model == "MIRROR":
        return {"type": "mirror", "reflectance": reflectance}
    if s.model == "NODES":
        log(f"material \"{material.name}\": its node tree is written as a Lambertian material")
    return {"type": "lambert", "reflectance": reflectance}


def _relocate(path, from_dir, to_dir):
    return os.path.relpath(os.path.normpath(os.path.join(from_dir, path)), to_dir)


def _stored_shape(ob, source_dir, out_dir):
    c = ob.chromatrace
    if not c.shape_json or c.geometry_digest != object_digest(ob):
        return None
    shape = json.loads(c.shape_json)
    if shape.get("type") == "mesh":
        shape["file"] = _relocate(shape["file"], source_dir, out_dir)
    return shape


def _mesh_shape(ob, depsgraph, mesh_dir, out_dir):
    evaluated = ob.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        matrix = ob.matrix_world
        normal_matrix = matrix.to_3x3().inverted_safe().transposed()
        smooth = any(p.use_smooth for p in mesh.polygons)
        positions = [tuple(matrix @ v.co) for v in mesh.vertices]
        normals = [tuple((normal_matrix @ v.normal).normalized()) for v in mesh.vertices] if smooth else []
        triangles = [tuple(t.vertices) for t in mesh.loop_triangles]
        uvs = []
        layer = mesh.uv_layers.active
        if layer is not None:  # per face corner in Blender, per vertex in PLY: a vertex once per (u, v)
            corner_uv = [tuple(layer.data[loop].uv) for t in mesh.loop_triangles for loop in t.loops]
            index, split_positions, split_normals = {}, [], []
            split_triangles = []
            for t, triangle in enumerate(triangles):
                corners = []
                for c, v in enumerate(triangle):
                    key = (v, corner_uv[3 * t + c])
                    if key not in index:
                        index[key] = len(split_positions)
                        split_positions.append(positions[v])
                        if normals:
                            split_normals.append(normals[v])
                        uvs.append(key[1])
                    corners.append(index[key])
                split_triangles.append(tuple(corners))
            positions, normals, triangles = split_positions, split_normals, split_triangles
    finally:
        evaluated.to_mesh_clear()
    os.makedirs(mesh_dir, exist_ok=True)
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in ob.name)
    path = os.path.join(mesh_dir, f"{safe}.ply")
    ply.write_ply(path, ply.Mesh(positions, normals, triangles, uvs))
    return {"type": "mesh", "file": os.path.relpath(path, out_dir)}


def _environment(world, out_dir, log):
    """The scene format's environment from Blender's world: a Background's colour from an Environment Texture (its
    default vector, or a Mapping node that only turns it about Z) or a constant colour, × its strength; None for
    no world or a dark one. Anything else is said and left out."""
    if world is None:
        return None
    if not blender_compat.uses_nodes(world):
        if max(world.color) <= 0.0:
            return None
        return {"radiance": {"rgb": [short_float(c) for c in world.color]}, "group": _world_group(world)}
    output = world.node_tree.get_output_node("CYCLES")
    surface = output.inputs["Surface"] if output is not None else None
    links = [l for l in surface.links if l.is_valid and not l.is_muted] if surface is not None and surface.is_linked else []
    background = links[0].from_node if links else None
    if background is None or background.bl_idname != "ShaderNodeBackground":
        if background is not None:
            log(f"world \"{world.name}\": its surface is not a Background node, so no environment is written")
        return None
    strength = background.inputs["Strength"]
    if strength.is_linked:
        log(f"world \"{world.name}\": its strength is not a constant, so no environment is written")
        return None
    colour = background.inputs["Color"]
    entry = {"scale": short_float(strength.default_value), "group": _world_group(world)}
    if not colour.is_linked:
        if max(colour.default_value[:3]) <= 0.0 or strength.default_value <= 0.0:
            return None
        entry["radiance"] = {"rgb": [short_float(c) for c in colour.default_value[:3]]}
        return entry
    node = colour.links[0].from_node
    if node.bl_idname != "ShaderNodeTexEnvironment" or node.image is None or node.projection != "EQUIRECTANGULAR":
        log(f"world \"{world.name}\": its colour is not an equirectangular Environment Texture, so no environment "
            "is written")
        return None
    from .colour_walk import texture_source
    source = texture_source(node.image)
    if source["texture"].startswith("packed:"):
        log(f"world \"{world.name}\": its image is packed into the .blend; unpack it to export the environment")
        return None
    source["texture"] = os.path.relpath(source["texture"], out_dir)
    entry["radiance"] = source
    vector = node.inputs["Vector"]
    if vector.is_linked:
        mapping = vector.links[0].from_node
        rotation = mapping.inputs["Rotation"].default_value if mapping.bl_idname == "ShaderNodeMapping" else None
        plain = rotation is not None and mapping.vector_type == "POINT" and abs(rotation[0]) < 1e-9 and \
            abs(rotation[1]) < 1e-9 and tuple(mapping.inputs["Location"].default_value) == (0, 0, 0) and \
            tuple(mapping.inputs["Scale"].default_value) == (1, 1, 1)
        if not plain:
            log(f"world \"{world.name}\": its environment's mapping is more than a turn about Z, so no environment "
                "is written")
            return None
        entry["rotation_deg"] = short_float(-math.degrees(rotation[2]))
    return entry


def _world_group(world):
    return getattr(world, "lightgroup", "") or "environment"


def _light_quad(ob):
    """A light mesh that is one planar parallelogram (4 vertices) as a quad shape."""
    mesh = ob.data
    if len(mesh.vertices) != 4:
        raise BadInput(f"light \"{ob.name}\": a chromatrace light must be a quad or a sphere; "
                       f"this mesh has {len(mesh.vertices)} vertices")
    m = ob.matrix_world
    p = [m @ v.co for v in mesh.vertices]
    return {"type": "quad", "corner": list(p[0]), "edge1": list(p[1] - p[0]), "edge2": list(p[3] - p[0])}


def _camera(scene):
    ob = scene.camera
    if ob is None:
        raise BadInput(f"scene \"{scene.name}\": no camera")
    r = scene.render
    resolution = [r.resolution_x * r.resolution_percentage // 100, r.resolution_y * r.resolution_percentage // 100]
    c = ob.data.chromatrace
    if c.scene_json and c.digest == camera_digest(ob):
        camera = json.loads(c.scene_json)
        camera["resolution"] = resolution
        return camera
    from .camera_math import camera_description
    d = camera_description(scene, resolution)
    return {"position": d["position"], "look_at": d["look_at"], "up": d["up"], "fov_deg": d["horizontal_fov_deg"],
            "fov_axis": "horizontal", "resolution": resolution, "sensor_width_mm": d["sensor_width_mm"]}


def export_scene(scene, path, tool, log=print):
    out_dir = os.path.dirname(os.path.abspath(path))
    stem = os.path.splitext(os.path.basename(path))[0]
    mesh_dir = os.path.join(out_dir, f"{stem}_meshes")
    s = scene.chromatrace
    source_dir = os.path.dirname(s.source_file) if s.source_file else out_dir
    depsgraph = bpy.context.evaluated_depsgraph_get()

    document = {"format": "chromatrace-scene/1", "name": s.scene_name or scene.name}
    if s.description:
        document["description"] = s.description
    if len(s.spectra):
        document["spectra"] = {e.name: e.source.to_json(base_dir=out_dir) for e in s.spectra}

    candidates = [ob for ob in scene.objects if ob.type == "MESH" and not ob.hide_render]
    ordered = sorted(candidates, key=lambda o: (o.pass_index == 0, o.pass_index, o.name))
    objects = [ob for ob in ordered if ob.chromatrace.role == "OBJECT"]
    lights = [ob for ob in ordered if ob.chromatrace.role == "LIGHT"]
    if any(ob.type == "LIGHT" and not ob.hide_render for ob in scene.objects):
        log("Blender light objects are not written: chromatrace lights are emitting quads or spheres")

    materials, names = {}, {}

    def material_name(material):
        if material.name not in names:
            name = material.chromatrace.scene_name or material.name
            names[material.name] = name
            materials[name] = _material_entry(material, out_dir, log)
        return names[material.name]

    object_entries = []
    for ob in objects:
        if not ob.material_slots or ob.material_slots[0].material is None:
            raise BadInput(f"object \"{ob.name}\": no material")
        shape = _stored_shape(ob, source_dir, out_dir) or _mesh_shape(ob, depsgraph, mesh_dir, out_dir)
        object_entries.append({"name": ob.chromatrace.scene_name or ob.name, "shape": shape,
                               "material": material_name(ob.material_slots[0].material)})
    light_entries = []
    for ob in lights:
        emitter = ob.material_slots[0].material if ob.material_slots else None
        if emitter is None or not emitter.chromatrace.emissive:
            raise BadInput(f"light \"{ob.name}\": its material does not emit (tick Emits light)")
        e = emitter.chromatrace
        node = emitter.node_tree.nodes.get("ct_emission") if emitter.node_tree else None
        rgb = tuple(node.outputs[0].default_value[:3]) if node else None
        entry = {"name": ob.chromatrace.scene_name or ob.name,
                 "shape": _stored_shape(ob, source_dir, out_dir) or _light_quad(ob),
                 "radiance": e.emission.to_json(current_rgb=rgb, base_dir=out_dir), "scale": short_float(e.emission_scale),
                 "group": (getattr(ob, "lightgroup", "") or ob.chromatrace.light_group or ob.name),
                 "two_sided": e.two_sided}
        if ob.chromatrace.light_material:
            reflect = next((m for m in bpy.data.materials
                            if (m.chromatrace.scene_name or m.name) == ob.chromatrace.light_material), None)
            if reflect is None:
                raise BadInput(f"light \"{ob.name}\": material \"{ob.chromatrace.light_material}\" not found")
            entry["material"] = material_name(reflect)
        light_entries.append(entry)
    # Scene materials that no object uses (kept by a fake user since import).
    for material in bpy.data.materials:
        if material.use_fake_user and material.chromatrace.scene_name and material.chromatrace.model != "NODES":
            material_name(material)

    document["materials"] = materials
    document["objects"] = object_entries
    document["lights"] = light_entries
    environment = _environment(scene.world, out_dir, log)
    if environment is not None:
        document["environment"] = environment
    document["camera"] = _camera(scene)
    render = {"samples": s.samples, "max_bounces": s.max_bounces, "seed": s.seed, "pixel_filter": s.pixel_filter,
              "spectral_mode": s.spectral_mode}
    if s.band_plan == "RANGE":
        render["bands"] = s.bands_argument()
    else:
        log("a band plan file cannot be written into a scene file: render.bands left out")
    tessellation = {}
    if s.tessellation_segments:
        tessellation["segments"] = s.tessellation_segments
    if s.tessellation_rings:
        tessellation["rings"] = s.tessellation_rings
    if tessellation:
        render["tessellation"] = tessellation
    document["render"] = render

    temporary = f"{path}.partial"
    with open(temporary, "w") as f:
        json.dump(document, f, indent=2)
        f.write("\n")
    try:
        tool.check_scene(temporary)
    except Exception:
        os.remove(temporary)
        raise
    os.replace(temporary, path)
    log(f"exported {path}: {len(object_entries)} objects, {len(light_entries)} lights, {len(materials)} materials")
    return document
