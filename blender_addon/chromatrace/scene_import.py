# SPDX-License-Identifier: GPL-3.0-or-later
"""Importing a `chromatrace-scene/1` file into a Blender scene.

`chromatrace check-scene` validates the file (and gives the camera's focal length), `chromatrace
export-meshes` tessellates every shape into PLY files with core's one rule, so Cycles renders the triangles
the reference tracer traces. Objects and lights become mesh objects with their object ids as pass
indices; lights are one-sided (or two-sided) emitters in their light groups; materials get the node
trees of their models. What the format says and Blender cannot hold (analytic shapes, the camera as
given, spectrum sources, render defaults) is kept in chromatrace properties, so export writes it back.
"""

import json
import math
import os
import shutil
import tempfile

import bpy
from mathutils import Matrix

from . import blender_compat, camera_math, defaults, materials, ply
from .errors import BadInput
from .geometry_digest import camera_digest, object_digest


def _spectrum(settings, source, scene_dir):
    settings.set_from_json(source, scene_dir)


def _ggx_masking(entry):
    """The GGX masking a material asks for (the format's default, separable, when it names none); None when it has
    no GGX lobe."""
    if entry["type"] != "dichromatic" or entry.get("lobe", "ggx") != "ggx":
        return None
    return entry.get("masking", "separable")


def _material(name, entry, scene_dir):
    material = bpy.data.materials.new(name)
    s = material.chromatrace
    s.scene_name = name
    kind = entry["type"]
    if kind == "principled":
        _spectrum(s.reflectance, entry["base_color"], scene_dir)
        s.roughness = entry.get("roughness", 0.5)
        s.ior = entry.get("ior", 1.5)
        s.specular_ior_level = entry.get("specular_ior_level", 0.5)
        s.principled_specular = entry.get("specular", 0.5)
        default = "multiscatter-ggx" if entry.get("version", 2) == 2 else "ggx"
        s.distribution = "MULTI_GGX" if entry.get("distribution", default) == "multiscatter-ggx" else "GGX"
    elif kind == "dichromatic":
        _spectrum(s.reflectance, entry["diffuse"], scene_dir)
        s.specular = entry["specular"]
        s.lobe = entry.get("lobe", "ggx")
        if s.lobe == "ggx":
            s.roughness = entry["roughness"]
        else:
            s.exponent = entry["exponent"]
    else:
        _spectrum(s.reflectance, entry["reflectance"], scene_dir)
    s.model = kind.upper()  # builds the nodes
    materials.build_material_nodes(material)
    return material


def _emitter_material(light, reflect, scene_dir):
    material = bpy.data.materials.new(f"{light['name']} (emitter)")
    s = material.chromatrace
    if reflect is not None:
        r = reflect.chromatrace
        s.reflectance.set_from_json(json.loads(_source_of(r.reflectance)), scene_dir)
        s.specular, s.lobe, s.roughness, s.exponent = r.specular, r.lobe, r.roughness, r.exponent
    s.emissive = True
    _spectrum(s.emission, light["radiance"], scene_dir)
    s.emission_scale = light.get("scale", 1.0)
    s.two_sided = light.get("two_sided", False)
    s.model = reflect.chromatrace.model if reflect is not None else "NONE"
    materials.build_material_nodes(material)
    return material


def _show_spectra_in_colour(scene, imported, tool, work_dir):
    """Gives every imported material's spectrum that is neither RGB nor a texture the colour chromatrace computes
    of it (`chromatrace scene-bands`: a reflectance's linear sRGB under D65, an emission's relative to D65, at its
    radiance), and rebuilds the material's nodes: Blender's viewport and a plain RGB render then show the scene's
    colours and its lights' brightness instead of a grey and a unit emission. The spectral render sets its own
    values and puts these back."""
    named = {entry.name: entry.source for entry in scene.chromatrace.spectra}
    wanted = []  # (material, source settings, "reflected" or "emitted")
    for material in imported:
        s = material.chromatrace
        if s.model in ("LAMBERT", "DICHROMATIC", "MIRROR", "PRINCIPLED"):
            wanted.append((material, s.reflectance, "reflected"))
        if s.emissive:
            wanted.append((material, s.emission, "emitted"))
    reflected, emitted, keys = {}, {}, []
    for material, settings, role in wanted:
        resolved = named[settings.spectrum_name] if settings.kind == "NAMED" else settings
        if settings.kind in ("RGB", "TEXTURE") or resolved.kind in ("RGB", "TEXTURE"):
            continue
        key = f"s{len(keys)}"
        (reflected if role == "reflected" else emitted)[key] = resolved.to_json()
        keys.append((key, material, settings, role))
    if not keys:
        return
    request = os.path.join(work_dir, "preview-spectra.json")
    with open(request, "w") as f:
        json.dump({"format": "chromatrace-spectra/1", "spectra": reflected, "radiance": emitted}, f)
    report = tool.band_averages(request)["spectra"]
    for key, _material, settings, role in keys:
        settings.set_preview(report[key][f"linear_srgb_{role}"])
    for material in {material for _key, material, _settings, _role in keys}:
        materials.build_material_nodes(material)


def _source_of(settings):
    return json.dumps(settings.to_json())


def _mesh_object(name, path, collection):
    data = ply.read_ply(path)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(data.positions, [], data.triangles)
    if data.normals:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
        if hasattr(mesh, "use_auto_smooth"):  # Blender < 4.1 applies custom normals only with auto smooth
            mesh.use_auto_smooth = True
        mesh.normals_split_custom_set_from_vertices(data.normals)
    if data.uvs:  # per vertex in the file (export-meshes --uvs splits seams), per face corner in Blender
        layer = mesh.uv_layers.new(name="UVMap")
        corners = [0] * len(mesh.loops)
        mesh.loops.foreach_get("vertex_index", corners)
        layer.data.foreach_set("uv", [c for v in corners for c in data.uvs[v]])
    mesh.update()
    ob = bpy.data.objects.new(name, mesh)
    collection.objects.link(ob)
    return ob


def _world(environment, scene_dir, view_layer, warn):
    """Blender's world for the scene's environment: a Background (strength = scale) fed by an Environment Texture
    (nearest texel, as the tracer looks it up; rotation_deg α as a Mapping node turning the vector by −α about Z)
    or by the colour of an rgb or constant spectrum. A world's colour is RGB, relative to D65: a constant (flat)
    spectrum becomes D65 of the same luminance, said through `warn`."""
    world = bpy.data.worlds.new("environment")
    tree = blender_compat.enable_nodes(world)
    nodes, links = tree.nodes, tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputWorld")
    background = nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = environment.get("scale", 1.0)
    links.new(background.outputs[0], output.inputs["Surface"])
    radiance = environment["radiance"]
    if isinstance(radiance, dict) and "texture" in radiance:
        texture = nodes.new("ShaderNodeTexEnvironment")
        texture.image = materials.load_image(os.path.join(scene_dir, radiance["texture"]),
                                             radiance.get("colour_space", "auto"))
        texture.interpolation = "Closest"
        if radiance.get("scale", 1.0) != 1.0:
            background.inputs["Strength"].default_value *= radiance["scale"]
        links.new(texture.outputs["Color"], background.inputs["Color"])
        rotation = environment.get("rotation_deg", 0.0)
        if rotation:
            coordinates = nodes.new("ShaderNodeTexCoord")
            mapping = nodes.new("ShaderNodeMapping")
            mapping.inputs["Rotation"].default_value[2] = -math.radians(rotation)
            links.new(coordinates.outputs["Generated"], mapping.inputs["Vector"])
            links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    elif isinstance(radiance, dict) and ("rgb" in radiance or "constant" in radiance):
        rgb = radiance["rgb"] if "rgb" in radiance else [radiance["constant"]] * 3
        background.inputs["Color"].default_value = (*rgb, 1.0)
        if "constant" in radiance:
            warn(f"warning: environment.radiance: the flat spectrum {radiance['constant']:g} becomes the world colour "
                 f"{radiance['constant']:g} (grey), which is D65 of that luminance: Blender's colours are relative to "
                 "its white, D65")
    else:
        raise BadInput("environment.radiance: only a texture, an rgb or a constant spectrum can be imported as "
                       "Blender's world")
    group = environment.get("group", "environment")
    if hasattr(world, "lightgroup"):
        _ensure_lightgroup(view_layer, group)
        world.lightgroup = group
    return world


def _dark_world(name):
    """A world that adds no light: black, and, where a new world has a node tree (Blender 5.0), black there too."""
    world = bpy.data.worlds.new(name)
    world.color = (0.0, 0.0, 0.0)
    if blender_compat.uses_nodes(world):
        for node in world.node_tree.nodes:
            if node.bl_idname in ("ShaderNodeBackground", "ShaderNodeEmission"):
                node.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
                node.inputs["Strength"].default_value = 0.0
    return world


def _dark(world):
    """Whether a world adds no light (as far as a constant colour or strength tells)."""
    if not blender_compat.uses_nodes(world):
        return max(world.color) <= 0.0
    for node in world.node_tree.nodes:
        if node.bl_idname in ("ShaderNodeBackground", "ShaderNodeEmission"):
            colour, strength = node.inputs["Color"], node.inputs["Strength"]
            if strength.is_linked or strength.default_value > 0.0 and (colour.is_linked or max(colour.default_value[:3]) > 0.0):
                return False
    return True


def _ensure_lightgroup(view_layer, group):
    if group not in view_layer.lightgroups.keys():
        view_layer.lightgroups.add(name=group)


def _refuse_other_principled(document, path):
    """Refuses, before anything is added to the scene, a principled material of the other Principled BSDF version
    than this Blender's: its node would be another BSDF."""
    here = blender_compat.principled_version()
    for name, entry in document["materials"].items():
        if entry["type"] == "principled" and entry.get("version", 2) != here:
            raise BadInput(f"{path}: materials.{name}.version: {entry.get('version', 2)}, but Blender "
                           f"{bpy.app.version_string}'s Principled BSDF is version {here}: Cycles would render another "
                           "material")


def _refuse_other_masking(document, path, option):
    """Refuses, before anything is added to the scene, a GGX material whose masking is not this Cycles': Cycles
    would render another material. `option` names what renders it with Cycles' masking instead."""
    cycles = blender_compat.cycles_ggx_masking()
    for name, entry in document["materials"].items():
        masking = _ggx_masking(entry)
        if masking is not None and masking != cycles:
            raise BadInput(f"{path}: materials.{name}.masking: \"{masking}\", but the GGX of Cycles in Blender "
                           f"{bpy.app.version_string} has {cycles} masking: Cycles would render another material "
                           f"({option} renders it with Cycles' masking, and says so)")


def _use_cycles_masking(document, log, option):
    """Gives every GGX material this Cycles' masking, with a warning naming each one changed (--ggx-masking cycles):
    the document, which the output's header carries, then says what was rendered."""
    cycles = blender_compat.cycles_ggx_masking()
    for name, entry in document["materials"].items():
        masking = _ggx_masking(entry)
        if masking is not None and masking != cycles:
            entry["masking"] = cycles
            log(f"warning: materials.{name}.masking: \"{masking}\" rendered with the {cycles} masking of Cycles in "
                f"Blender {bpy.app.version_string} ({option})")


def import_scene(path, scene, tool, log=print, ggx_masking="scene", warn=None, masking_option="--ggx-masking cycles"):
    """Adds the scene file's objects, lights and camera to `scene` and sets its chromatrace settings. With
    `ggx_masking` "cycles", GGX materials take this Cycles' masking instead of being refused for the other, each
    one changed said through `warn` (`log` when None); the refusal and the warnings name `masking_option`, the
    caller's way to ask for that."""
    summary = tool.check_scene(path)["scene"]
    with open(path) as f:
        document = json.load(f)
    if ggx_masking == "cycles":
        _use_cycles_masking(document, warn or log, masking_option)
    _refuse_other_masking(document, path, masking_option)
    _refuse_other_principled(document, path)
    scene_dir = os.path.dirname(os.path.abspath(path))
    s = scene.chromatrace
    s.scene_name = document.get("name", "")
    s.description = document.get("description", "")
    s.source_file = os.path.abspath(path)
    s.source_json = json.dumps(document)

    s.spectra.clear()
    for name, source in document.get("spectra", {}).items():
        entry = s.spectra.add()
        entry.name = name
        entry.source.set_from_json(source, scene_dir)

    # The render settings as the tool resolved them, the scene's own or the shared defaults.
    render, resolved = document.get("render", {}), summary["render"]
    s.samples = resolved["samples"]
    s.max_bounces = resolved["max_bounces"]
    s.seed = resolved["seed"]
    s.pixel_filter = resolved["pixel_filter"]
    s.spectral_mode = resolved["spectral_mode"]
    s.band_plan = "RANGE"
    s.bands_lo, s.bands_hi, s.bands_width = defaults.band_range(render.get("bands"))
    tessellation = render.get("tessellation", {})
    s.tessellation_segments = tessellation.get("segments", 0)
    s.tessellation_rings = tessellation.get("rings", 0)
    scene.render.engine = "CYCLES"
    scene.cycles.samples = s.samples

    mesh_dir = tempfile.mkdtemp(prefix="chromatrace-import-")
    try:
        index = tool.export_meshes(path, mesh_dir)
        collection = bpy.data.collections.new(s.scene_name or os.path.splitext(os.path.basename(path))[0])
        scene.collection.children.link(collection)

        built = {name: _material(name, entry, scene_dir) for name, entry in document["materials"].items()}
        for entry, obj in zip(index["objects"], document["objects"]):
            ob = _mesh_object(obj["name"], os.path.join(mesh_dir, entry["file"]), collection)
            ob.data.materials.append(built[obj["material"]])
            ob.pass_index = entry["id"]
            ob.chromatrace.role = "OBJECT"
            ob.chromatrace.scene_name = obj["name"]
            ob.chromatrace.shape_json = json.dumps(obj["shape"])
        view_layer = scene.view_layers[0]
        for i, light in enumerate(document["lights"]):
            if isinstance(light["radiance"], dict) and "texture" in light["radiance"]:
                raise BadInput(f"lights[{i}].radiance: a textured light is not imported (give the emitter an Image "
                               "Texture node in Blender instead)")
        emitters = []
        for entry, light in zip(index["lights"], document["lights"]):
            reflect = built.get(light["material"]) if "material" in light else None
            ob = _mesh_object(light["name"], os.path.join(mesh_dir, entry["file"]), collection)
            emitters.append(_emitter_material(light, reflect, scene_dir))
            ob.data.materials.append(emitters[-1])
            ob.pass_index = entry["id"]
            group = light.get("group", light["name"])
            ob.chromatrace.role = "LIGHT"
            ob.chromatrace.scene_name = light["name"]
            ob.chromatrace.shape_json = json.dumps(light["shape"])
            ob.chromatrace.light_group = group
            ob.chromatrace.light_material = light.get("material", "")
            if hasattr(ob, "lightgroup"):
                _ensure_lightgroup(view_layer, group)
                ob.lightgroup = group
        _show_spectra_in_colour(scene, list(built.values()) + emitters, tool, mesh_dir)
        if "environment" in document:
            scene.world = _world(document["environment"], scene_dir, view_layer, warn or log)
        elif scene.world is not None and not _dark(scene.world):
            # The scene's light is the file's: a world that lights the scene would add light the file has not.
            dark = _dark_world("no environment")
            log(f"the scene has no environment: its world \"{scene.world.name}\" is replaced by a dark one")
            scene.world = dark
        for material in built.values():
            if material.users == 0:
                material.use_fake_user = True  # a scene material no object uses: keep it for export

        camera = document["camera"]
        data = bpy.data.cameras.new("camera")
        data.sensor_fit = "HORIZONTAL"
        data.sensor_width = summary["camera"]["sensor_width_mm"]
        data.lens = summary["camera"]["focal_length_mm"]
        data.clip_start, data.clip_end = 1e-4, 1e5  # the format's pinhole clips nothing
        ob = bpy.data.objects.new("camera", data)
        collection.objects.link(ob)
        basis = camera_math.camera_basis(camera["position"], camera["look_at"], camera.get("up", [0, 0, 1]))
        ob.matrix_world = Matrix([basis[0] + [camera["position"][0]], basis[1] + [camera["position"][1]],
                                  basis[2] + [camera["position"][2]], [0, 0, 0, 1]])
        scene.camera = ob
        width, height = camera["resolution"]
        scene.render.resolution_x, scene.render.resolution_y = width, height
        scene.render.resolution_percentage = 100
        view_layer.update()  # matrices as Blender keeps them, for the digests
        for imported in collection.objects:
            if imported.type == "MESH":
                imported.chromatrace.geometry_digest = object_digest(imported)
        data.chromatrace.scene_json = json.dumps(camera)
        data.chromatrace.digest = camera_digest(ob)
    finally:
        shutil.rmtree(mesh_dir, ignore_errors=True)
    log(f"imported {path}: {len(document['objects'])} objects, {len(document['lights'])} lights, "
        f"{len(document['materials'])} materials{', an environment' if 'environment' in document else ''}")
    return collection
