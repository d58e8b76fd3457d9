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
from mathutils import Vector

from . import blender_compat, materials, ply, scene_parts
from .errors import BadInput
from .floats import short_float
from .geometry_digest import camera_digest, object_digest


def _spectrum_ref(settings, current_rgb, out_dir):
    return settings.to_json(current_rgb=current_rgb, base_dir=out_dir)


def _reflectance_rgb(material):
    node = material.node_tree.nodes.get("ct_reflectance") if material.node_tree else None
    return tuple(node.outputs[0].default_value[:3]) if node else tuple(material.diffuse_color[:3])


def _texture_file(source, texture_dir, out_dir):
    """A scene-format texture source with its file relative to the scene file; an image packed into the .blend is
    written out into `texture_dir` first (its bytes as packed: the file it was)."""
    source = dict(source)
    path = source["texture"]
    if path.startswith("packed:"):
        image = bpy.data.images[path[len("packed:"):]]
        extension = os.path.splitext(image.filepath)[1] or {"OPEN_EXR": ".exr", "PNG": ".png", "JPEG": ".jpg",
                                                             "TIFF": ".tif", "HDR": ".hdr"}.get(image.file_format, "")
        safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in image.name)
        os.makedirs(texture_dir, exist_ok=True)
        path = os.path.join(texture_dir, safe + (extension if not safe.endswith(extension) else ""))
        with open(path + ".partial", "wb") as f:
            f.write(image.packed_file.data)
        os.replace(path + ".partial", path)
    source["texture"] = os.path.relpath(path, out_dir)
    return source


# Shader nodes whose material a scene file holds exactly (as `lambert`), with the inputs that must be 0 for it.
_LAMBERTIAN = {"ShaderNodeBsdfDiffuse": ("Roughness",)}

# A Principled BSDF's inputs that must hold these values for a scene file's `principled` material (an opaque
# dielectric), by version: 2 from Blender 4.0 (it has Specular IOR Level), 1 before. Inputs a Blender lacks are
# skipped. The base colour, roughness and IOR (v2) or Specular (v1) are read, and must not be linked.
_PRINCIPLED_FIXED = {
    2: {"Metallic": 0.0, "Transmission Weight": 0.0, "Coat Weight": 0.0, "Sheen Weight": 0.0,
        "Subsurface Weight": 0.0, "Emission Strength": 0.0, "Anisotropic": 0.0, "Alpha": 1.0,
        "Specular Tint": (1.0, 1.0, 1.0), "Diffuse Roughness": 0.0, "Thin Film Thickness": 0.0},
    1: {"Metallic": 0.0, "Transmission": 0.0, "Clearcoat": 0.0, "Sheen": 0.0, "Subsurface": 0.0,
        "Emission Strength": 0.0, "Anisotropic": 0.0, "Alpha": 1.0, "Specular Tint": 0.0},
}
# Colour inputs the walk reports beside the base colour, which the values above leave without effect.
_PRINCIPLED_TINTS = ("Specular Tint", "Coat Tint", "Sheen Tint", "Subsurface Color")


def _principled_entry(material, walk, base, approximate):
    """The material as a scene file's `principled` (docs/scene-format.md) when its tree is one Principled BSDF that
    is an opaque dielectric with a smooth enough interface, else None with the reason."""
    shaders = [node for _path, node in walk.shaders]
    if len(shaders) != 1 or shaders[0].bl_idname != "ShaderNodeBsdfPrincipled":
        return None, None
    node = shaders[0]
    version = 2 if "Specular IOR Level" in node.inputs else 1
    emission = node.inputs.get("Emission Color") or node.inputs.get("Emission")
    for name, wanted in _PRINCIPLED_FIXED[version].items():
        socket = node.inputs.get(name)
        if socket is None or (name == "Emission Strength" and not emission.is_linked
                              and max(emission.default_value[:3]) == 0.0):  # a black emission emits nothing
            continue
        value = socket.default_value
        value = tuple(value[:3]) if isinstance(wanted, tuple) else value
        if socket.is_linked or value != wanted:
            return None, f"its Principled BSDF's {name} is {'linked' if socket.is_linked else value}, not {wanted}"
    numbers = ("Roughness", "IOR", "Specular IOR Level") if version == 2 else ("Roughness", "Specular")
    for name in numbers + ("Normal",):
        if node.inputs[name].is_linked:
            return None, f"its Principled BSDF's {name} is linked"
    roughness = node.inputs["Roughness"].default_value
    if roughness < 0.02:
        return None, f"its Principled BSDF's Roughness {roughness:g} is below 0.02, where Cycles makes a mirror"
    entry = {"type": "principled", "version": version, "base_color": base, "roughness": short_float(roughness)}
    if version == 2:
        entry["ior"] = short_float(node.inputs["IOR"].default_value)
        entry["specular_ior_level"] = short_float(node.inputs["Specular IOR Level"].default_value)
        entry["distribution"] = "multiscatter-ggx" if node.distribution == "MULTI_GGX" else "ggx"
    else:
        entry["specular"] = short_float(node.inputs["Specular"].default_value)
        entry["distribution"] = "ggx"
        if node.distribution == "MULTI_GGX" and roughness > 0.075:
            approximate(f"material \"{material.name}\": its Principled BSDF's Multiscatter GGX (Blender 3.x's random "
                        "walk) is written as single-scatter GGX, which reflects a little less at high roughness")
    return entry, None


def _node_material_entry(scene, material, texture_dir, out_dir, approximate):
    """A material of the node-tree model as a scene-format material, from the colours the spectral render gives
    it (materials.spectral_inputs). A Diffuse BSDF of roughness 0 (or no nodes: the viewport colour, which Cycles
    renders diffusely) is `lambert` of its colour or texture, exactly. Any other tree is `lambert` of its first
    reflectance colour (a Principled BSDF's base colour), which `approximate` says. BadInput for a tree that emits:
    a scene file's emitters are lights."""
    from . import node_resolution
    what = f"material \"{material.name}\""
    walk = materials.walk_material(material)
    inputs = materials.spectral_inputs(material, walk)
    if any(i.role == "emission" for i in inputs):
        raise BadInput(f"{what}: its nodes emit light, which a scene file holds only as a light (a quad or a "
                       "sphere): set the object's chromatrace role to Light, or make it a Blender area light")

    def colour(spectral_input):  # its image texture (written out if packed), or its colour's spectrum
        if spectral_input.attribute == "image" and spectral_input.source is not None:
            return _texture_file(spectral_input.source, texture_dir, out_dir)
        return node_resolution.node_source(spectral_input, what)[0]

    reflectances = [i for i in inputs if i.role == "reflectance"]
    bases = [i for i in reflectances if not i.label.endswith(tuple("/" + t for t in _PRINCIPLED_TINTS))]
    reason = None
    if len(bases) == 1:
        entry, reason = _principled_entry(material, walk, colour(bases[0]), approximate)
        if entry is not None:
            return entry
    if reflectances:
        first = reflectances[0]
        source = colour(first)
    else:  # only spectrally flat colours (a glossy's grey): their grey, or black
        greys = [i.current_rgb[0] for i in inputs if i.role == "interface"]
        source = {"constant": max(0.0, min(1.0, greys[0])) if greys else 0.0}
    shaders = [node for _path, node in walk.shaders]
    exact = len(reflectances) == len(inputs) <= 1 and all(
        node.bl_idname in _LAMBERTIAN and all(node.inputs[k].default_value == 0.0 and not node.inputs[k].is_linked
                                              for k in _LAMBERTIAN[node.bl_idname]) for node in shaders)
    if not exact:
        kinds = sorted({node.bl_label for node in shaders}) or ["no shader"]
        approximate(f"{what}: its nodes ({', '.join(kinds)}) are written as a Lambertian material of "
                    f"{'its colour ' + first.label if reflectances else 'their grey'}"
                    + (f" ({reason})" if reason else "") + "; the scene file holds them only approximately")
    return {"type": "lambert", "reflectance": source}


def _material_entry(material, out_dir):
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
    if s.model == "PRINCIPLED":
        entry = {"type": "principled", "version": blender_compat.principled_version(), "base_color": reflectance,
                 "roughness": short_float(s.roughness)}
        if entry["version"] == 2:
            entry.update(ior=short_float(s.ior), specular_ior_level=short_float(s.specular_ior_level),
                         distribution="multiscatter-ggx" if s.distribution == "MULTI_GGX" else "ggx")
        else:
            entry.update(specular=short_float(s.principled_specular), distribution="ggx")
        return entry
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


def _environment(world, out_dir, texture_dir, log):
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
    entry["radiance"] = _texture_file(source, texture_dir, out_dir)
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


def _light_node_strength(ob):
    """The Strength of the Emission node a light's node tree ends in (1 without a tree); BadInput for a tree that
    is more than that, whose light a scene file's one spectrum and scale cannot hold."""
    light = ob.data
    if not blender_compat.uses_nodes(light):
        return 1.0
    output = light.node_tree.get_output_node("CYCLES")
    surface = output.inputs["Surface"] if output is not None else None
    links = [l for l in surface.links if l.is_valid and not l.is_muted] if surface is not None else []
    node = links[0].from_node if links else None
    if node is None or node.bl_idname != "ShaderNodeEmission" or node.inputs["Strength"].is_linked:
        raise BadInput(f"light \"{ob.name}\": its node tree is more than an Emission node of constant strength, "
                       "which a scene file's light (one spectrum and a scale) cannot hold")
    return float(node.inputs["Strength"].default_value)


def _light_spectrum(scene, ob):
    """(radiance source, scale) of a Blender light as the spectral render emits it (node_resolution.owner_inputs):
    the product of its colours' spectra, where all but one of them are flat; BadInput otherwise."""
    from . import node_resolution
    inputs = node_resolution.owner_inputs(scene, "light", ob, materials.walk_light(ob.data))
    shaped = [(source, scale) for _input, source, scale in inputs if "constant" not in source]
    scale = math.prod(scale * source.get("constant", 1.0) for _input, source, scale in inputs)
    if len(shaped) > 1:
        raise BadInput(f"light \"{ob.name}\": its colour and its nodes' colours make a product of spectra, which a "
                       "scene file's light cannot hold; make all but one of them grey")
    return (shaped[0][0] if shaped else {"constant": 1.0}), scale


def _blender_light(scene, ob, approximate):
    """A Blender light object as a scene-format light, emitting what Cycles' spectral render of it emits: an area
    light (square or rectangle) as a one-sided quad facing its −Z, a point light of some radius as a sphere. The
    rest (sun, spot, disk, a spread below 180°, a point without radius) has no scene-format shape: BadInput."""
    light, what = ob.data, f"light \"{ob.name}\""
    m = ob.matrix_world
    if light.type == "AREA":
        if light.shape not in ("SQUARE", "RECTANGLE"):
            raise BadInput(f"{what}: a {light.shape.lower()} area light has no scene-format shape (quads and spheres "
                           "only); make it a square or a rectangle")
        if getattr(light, "spread", math.pi) < math.pi - 1e-6:
            raise BadInput(f"{what}: its spread of {math.degrees(light.spread):g} degrees focuses its light, which a "
                           "scene file's quad (a diffuse emitter) cannot; set the spread to 180")
        sx = light.size
        sy = light.size if light.shape == "SQUARE" else light.size_y
        corner = m @ Vector((-sx / 2, -sy / 2, 0.0))
        edge1, edge2 = m.to_3x3() @ Vector((0.0, sy, 0.0)), m.to_3x3() @ Vector((sx, 0.0, 0.0))  # normal: −Z
        area = edge1.cross(edge2).length
        if area <= 0.0:
            raise BadInput(f"{what}: its size is 0")
        shape = {"type": "quad", "corner": [short_float(c) for c in corner], "edge1": [short_float(c) for c in edge1],
                 "edge2": [short_float(c) for c in edge2]}
    elif light.type == "POINT":
        if light.shadow_soft_size <= 0.0:
            raise BadInput(f"{what}: a point light of radius 0 has no surface; give it a radius (a sphere light)")
        area = None
        if bpy.app.version < (4, 0, 0) or getattr(light, "use_soft_falloff", False):
            approximate(f"{what}: this Cycles lights each point as if the point light of radius "
                        f"{light.shadow_soft_size:g} m were a disk facing it (Soft Falloff), which gives d²/(d² + r²) "
                        "of the light of the sphere the scene file has, at distance d: within 1 % beyond 10 radii")
        shape = {"type": "sphere", "center": [short_float(c) for c in m.translation],
                 "radius": short_float(light.shadow_soft_size)}
    else:
        raise BadInput(f"{what}: a {light.type.lower()} light has no scene-format shape; use an area light (square "
                       "or rectangle), a point light with a radius, or an emitting mesh")
    source, scale = _light_spectrum(scene, ob)
    watts = float(light.energy) * _light_node_strength(ob)
    scale *= watts * blender_compat.light_radiance_per_watt(light, area)
    return {"name": ob.chromatrace.scene_name or ob.name, "shape": shape, "radiance": source,
            "scale": short_float(scale), "group": getattr(ob, "lightgroup", "") or scene_parts.group_name(ob.name)}


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


def export_scene(scene, path, tool, log=print, approximations=None):
    """Writes `scene` to the scene file `path` (meshes and unpacked textures in folders beside it), checked by
    `chromatrace check-scene`; returns the document. What the file holds only approximately or leaves out (a node
    tree as a Lambertian material, a world it cannot write) is logged and, when given, appended to
    `approximations`."""
    out_dir = os.path.dirname(os.path.abspath(path))
    stem = os.path.splitext(os.path.basename(path))[0]
    mesh_dir = os.path.join(out_dir, f"{stem}_meshes")
    texture_dir = os.path.join(out_dir, f"{stem}_textures")

    def approximate(message):
        log(message)
        if approximations is not None:
            approximations.append(message)
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
    blender_lights = sorted((ob for ob in scene.objects if ob.type == "LIGHT" and not ob.hide_render),
                            key=lambda ob: ob.name)
    portals = [ob.name for ob in blender_lights if getattr(getattr(ob.data, "cycles", None), "is_portal", False)]
    if portals:
        approximate(f"portals are not lights and are not written: {', '.join(portals)}")
    blender_lights = [ob for ob in blender_lights if ob.name not in portals]

    materials, names = {}, {}

    def material_name(material):
        if material.name not in names:
            name = material.chromatrace.scene_name or material.name
            names[material.name] = name
            materials[name] = (_node_material_entry(scene, material, texture_dir, out_dir, approximate)
                               if material.chromatrace.model == "NODES" else _material_entry(material, out_dir))
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
    light_entries += [_blender_light(scene, ob, approximate) for ob in blender_lights]
    # Scene materials that no object uses (kept by a fake user since import).
    for material in bpy.data.materials:
        if material.use_fake_user and material.chromatrace.scene_name and material.chromatrace.model != "NODES":
            material_name(material)

    document["materials"] = materials
    document["objects"] = object_entries
    document["lights"] = light_entries
    environment = _environment(scene.world, out_dir, texture_dir, approximate)
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
