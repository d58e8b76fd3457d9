# SPDX-License-Identifier: Apache-2.0
"""Test helper: an ordinary artist's scene, built from Blender's default file, saved as a .blend.

    blender -b --factory-startup --python make_artist_scene.py -- library OUT.blend [--only "NAME|NAME|..."]
        one small sphere per material of Blender's bundled materials library (sample_materials.blend) that
        carries colour, an area light whose colour is a Blackbody node (4000 K) in its node tree, and a world
        lit by an HDRI of Blender's studio lights; --only keeps those materials, and a world without light
    blender -b --factory-startup --python make_artist_scene.py -- textured OUT.blend
        a diffuse plane whose colour is an Image Texture node of a 2×1 float image packed into the .blend (red
        0.8, 0.05, 0.05 on the left, blue 0.05, 0.1, 0.8 on the right, linear), under a white world of strength 1,
        seen from above by an orthographic camera; no lights
    blender -b --factory-startup --python make_artist_scene.py -- blackbody OUT.blend KELVIN
        a grey diffuse plane under an area light whose node tree's colour is a Blackbody node at KELVIN, no world
    blender -b --factory-startup --python make_artist_scene.py -- lights OUT.blend
        Blender's light objects in each power convention (blender_lights_scene) over a textured floor and a box
    blender -b --factory-startup --python make_artist_scene.py -- principled OUT.blend
        Principled BSDFs as an artist leaves them (principled_scene) under an area light
    blender -b --factory-startup --python make_artist_scene.py -- artist OUT.blend
        Principled BSDFs, a packed image texture, an HDRI world and a Blackbody area light, all of which Export
        writes exactly (artist_scene): bench/bench_plan_cycles.py's artist's scene
    blender -b --factory-startup --python make_artist_scene.py -- grey_floor OUT.blend (hdri | R,G,B)
        a large diffuse floor whose colour is an Image Texture node of a 2×2 float image of greys (R = G = B: 0.25
        and 0.6), packed into the .blend, seen at a slant by a perspective camera with the sky above the horizon;
        the world is Blender's studio HDRI courtyard.exr, or the RGB colour R,G,B; no lights

    blender -b --factory-startup --python make_artist_scene.py -- studio OUT.blend
        what an artist starts from in this version: the default file kept (its cube, with the default material, and
        its point light), Blender's own studio HDRI courtyard.exr as the world, a sphere whose Principled BSDF has
        coloured tints (Blender 4.0+: Specular, Coat and Sheen Tint colours; 3.x: Principled v1's tint factors and
        clearcoat), a floor whose colour is an Image Texture node of a 4×4 float image packed into the .blend, and
        an area light whose colour is a Blackbody node at 3000 K

The default cube and point light are removed (except in studio); the default camera is moved to look down on the
scene.
"""

import glob
import math
import os
import sys

import bpy

LIBRARY = os.path.join(bpy.utils.system_resource("SCRIPTS"), "addons", "materials_library_vx", "sample_materials.blend")
STUDIO_WORLDS = os.path.join(bpy.utils.system_resource("DATAFILES"), "studiolights", "world")


def carries_colour(material):
    """Whether a material's nodes hold any colour (a colour socket, an RGB or colour node, a ramp)."""
    def tree_has(tree, seen):
        if tree is None or tree.name in seen:
            return False
        seen.add(tree.name)
        for node in tree.nodes:
            if node.type == "GROUP" and tree_has(node.node_tree, seen):
                return True
            if any(s.type == "RGBA" for s in list(node.inputs) + list(node.outputs)):
                return True
        return False
    return material.use_nodes and tree_has(material.node_tree, set())


def area_light_with_blackbody(kelvin, location, size=1.0, power=300.0):
    data = bpy.data.lights.new("Area", "AREA")
    data.size = size
    data.energy = power
    data.use_nodes = True
    tree = data.node_tree
    emission = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeEmission")
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    blackbody.inputs["Temperature"].default_value = kelvin
    tree.links.new(blackbody.outputs["Color"], emission.inputs["Color"])
    ob = bpy.data.objects.new("Area", data)
    ob.location = location
    bpy.context.scene.collection.objects.link(ob)
    return ob


def look_down(camera, height, ortho_scale):
    camera.location = (0.0, 0.0, height)
    camera.rotation_euler = (0.0, 0.0, 0.0)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = ortho_scale


def look_ahead(camera, location, pitch_deg):
    """A 35 mm perspective camera at `location`, looking along +Y tilted down to `pitch_deg` from straight down."""
    camera.data.type = "PERSP"
    camera.data.lens = 35.0
    camera.location = location
    camera.rotation_euler = (math.radians(pitch_deg), 0.0, 0.0)


def link_light(name, data, location, pitch_deg=0.0):
    """A light object of `data` at `location`, turned `pitch_deg` about X, in the scene."""
    ob = bpy.data.objects.new(name, data)
    ob.location = location
    ob.rotation_euler = (math.radians(pitch_deg), 0.0, 0.0)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def clear_defaults():
    for name in ("Cube", "Light"):
        ob = bpy.data.objects.get(name)
        if ob is not None:
            bpy.data.objects.remove(ob)


def library_scene(only):
    with bpy.data.libraries.load(LIBRARY) as (source, loaded):
        loaded.materials = [n for n in source.materials if only is None or n in only]
    chosen = sorted((m for m in loaded.materials if carries_colour(m)), key=lambda m: m.name)
    columns = math.ceil(math.sqrt(len(chosen)))
    for i, material in enumerate(chosen):
        row, column = divmod(i, columns)
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.4, segments=24, ring_count=12,
                                             location=(column - (columns - 1) / 2, (columns - 1) / 2 - row, 0.0))
        sphere = bpy.context.object
        sphere.name = f"sphere {material.name}"
        sphere.data.materials.append(material)
    area_light_with_blackbody(4000.0, (0.0, 0.0, 4.0), size=2.0, power=400.0 * columns * columns)
    look_down(bpy.context.scene.camera, 10.0, columns + 0.5)
    world = bpy.context.scene.world
    if only is None:
        hdri = sorted(glob.glob(os.path.join(STUDIO_WORLDS, "*.exr")))[0]
        environment = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
        environment.image = bpy.data.images.load(hdri)
        background = world.node_tree.nodes["Background"]
        world.node_tree.links.new(environment.outputs["Color"], background.inputs["Color"])
    else:
        bpy.context.scene.world = None


def grey_diffuse(name="grey", grey=0.5):
    """A material whose node tree is a Diffuse BSDF of this grey."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (grey, grey, grey, 1.0)
    material.node_tree.links.new(diffuse.outputs[0], nodes["Material Output"].inputs["Surface"])
    return material


def blackbody_scene(kelvin):
    bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0.0, 0.0, 0.0))
    plane = bpy.context.object
    plane.name = "plane"
    plane.data.materials.append(grey_diffuse())
    area_light_with_blackbody(kelvin, (0.0, 0.0, 1.5), size=1.0, power=100.0)
    look_down(bpy.context.scene.camera, 5.0, 3.0)
    bpy.context.scene.world = None


def packed_float_image(name, width, height, rgba, out):
    """A float image saved as an OpenEXR beside OUT.blend and packed into it (a texture the .blend carries)."""
    image = bpy.data.images.new(name, width, height, alpha=False, float_buffer=True)
    image.pixels[:] = rgba
    image.filepath_raw = os.path.join(os.path.dirname(os.path.abspath(out)), name.replace(" ", "_") + ".exr")
    image.file_format = "OPEN_EXR"
    image.save()
    image.pack()
    image.source = "FILE"
    return image


def principled_with_tints(name):
    """A Principled BSDF whose tints are coloured: version 2's colour inputs where the node has them, else
    version 1's factors (Specular Tint, Sheen Tint) and its Clearcoat."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    node = material.node_tree.nodes["Principled BSDF"]
    inputs = node.inputs
    inputs["Base Color"].default_value = (0.7, 0.15, 0.1, 1.0)
    inputs["Roughness"].default_value = 0.3
    if "Coat Tint" in inputs:  # Principled v2 (Blender 4.0+)
        inputs["Specular Tint"].default_value = (1.0, 0.85, 0.6, 1.0)
        inputs["Coat Weight"].default_value = 0.5
        inputs["Coat Tint"].default_value = (0.9, 0.75, 0.4, 1.0)
        inputs["Sheen Weight"].default_value = 0.4
        inputs["Sheen Tint"].default_value = (0.4, 0.6, 1.0, 1.0)
    else:
        inputs["Specular Tint"].default_value = 0.6
        inputs["Clearcoat"].default_value = 0.5
        inputs["Sheen"].default_value = 0.4
        inputs["Sheen Tint"].default_value = 0.8
    return material


def studio_scene(out):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.8, location=(2.5, 0.0, 0.8))
    sphere = bpy.context.object
    sphere.name = "tinted sphere"
    sphere.data.materials.append(principled_with_tints("tinted"))

    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0.0, 0.0, -1.0))
    floor = bpy.context.object
    floor.name = "floor"
    checker = [v for i in range(16) for v in ((0.6, 0.5, 0.3, 1.0) if (i + i // 4) % 2 else (0.2, 0.3, 0.5, 1.0))]
    image = packed_float_image("tiles", 4, 4, checker, out)
    material = bpy.data.materials.new("tiles")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    texture.interpolation = "Closest"
    material.node_tree.links.new(texture.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    floor.data.materials.append(material)

    area_light_with_blackbody(3000.0, (0.0, -2.0, 4.0), size=2.0, power=500.0)
    world = bpy.context.scene.world
    world.use_nodes = True
    environment = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
    environment.image = bpy.data.images.load(os.path.join(STUDIO_WORLDS, "courtyard.exr"))
    world.node_tree.links.new(environment.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])


def diffuse_image_material(name, image, tiles=None):
    """A Diffuse BSDF whose colour is an Image Texture node of `image` (nearest texel), repeated `tiles` times
    across the UV square when given."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    texture.interpolation = "Closest"
    if tiles is not None:
        coordinates = nodes.new("ShaderNodeTexCoord")
        mapping = nodes.new("ShaderNodeMapping")
        mapping.inputs["Scale"].default_value = (tiles, tiles, 1.0)
        links.new(coordinates.outputs["UV"], mapping.inputs["Vector"])
        links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    links.new(texture.outputs["Color"], diffuse.inputs["Color"])
    links.new(diffuse.outputs[0], nodes["Material Output"].inputs["Surface"])
    return material


def grey_floor_scene(out, world_colour):
    bpy.ops.mesh.primitive_plane_add(size=200.0, location=(0.0, 0.0, 0.0))
    floor = bpy.context.object
    floor.name = "floor"
    greys = [v for i in range(4) for v in ((0.6,) * 3 + (1.0,) if (i + i // 2) % 2 else (0.25,) * 3 + (1.0,))]
    image = packed_float_image("greys", 2, 2, greys, out)
    floor.data.materials.append(diffuse_image_material("grey tiles", image, tiles=50.0))  # a tile: a few pixels
    world = bpy.context.scene.world
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    if world_colour == "hdri":
        environment = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
        environment.image = bpy.data.images.load(os.path.join(STUDIO_WORLDS, "courtyard.exr"))
        world.node_tree.links.new(environment.outputs["Color"], background.inputs["Color"])
    else:
        background.inputs["Color"].default_value = (*(float(c) for c in world_colour.split(",")), 1.0)
    background.inputs["Strength"].default_value = 1.0
    camera = bpy.context.scene.camera
    camera.data.type = "PERSP"
    camera.location = (0.0, -8.0, 1.6)
    camera.rotation_euler = (math.radians(78.0), 0.0, 0.0)  # the horizon in the picture's top fifth


def textured_scene(out):
    bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0.0, 0.0, 0.0))  # u = (x + 2) / 4
    plane = bpy.context.object
    plane.name = "plane"
    image = packed_float_image("two colours", 2, 1, (0.8, 0.05, 0.05, 1.0, 0.05, 0.1, 0.8, 1.0), out)
    plane.data.materials.append(diffuse_image_material("painted", image))
    world = bpy.context.scene.world
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    look_down(bpy.context.scene.camera, 5.0, 3.0)


def blender_lights_scene():
    """Blender's own light objects in each power convention, out of the camera's view, over a textured floor and a
    grey box: a rectangular area light whose node tree's colour is a Blackbody node (3500 K), a point light of
    radius 0.05 m with an RGB colour (Soft Falloff off where the light has it), and a square area light with its
    Temperature (Blender 4.5+: 5000 K, Exposure 1, not normalised; a white colour before)."""
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, 0.0))
    floor = bpy.context.object
    floor.name = "floor"
    checker = [v for i in range(16) for v in ((0.7, 0.6, 0.35, 1.0) if (i + i // 4) % 2 else (0.2, 0.35, 0.6, 1.0))]
    floor.data.materials.append(diffuse_image_material("tiles", packed_float_image("tiles", 4, 4, checker, OUT)))
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0.3, 0.8, 0.3))
    box = bpy.context.object
    box.name = "box"
    box.data.materials.append(grey_diffuse())

    area = area_light_with_blackbody(3500.0, (-0.6, 0.9, 1.6), size=1.0, power=120.0)
    area.data.shape = "RECTANGLE"
    area.data.size_y = 0.5
    area.rotation_euler = (math.radians(20.0), 0.0, math.radians(30.0))

    point = bpy.data.lights.new("Point", "POINT")
    point.energy, point.shadow_soft_size, point.color = 60.0, 0.05, (1.0, 0.8, 0.6)
    if hasattr(point, "use_soft_falloff"):
        point.use_soft_falloff = False
    link_light("Point", point, (1.4, -0.2, 1.2))

    square = bpy.data.lights.new("Square", "AREA")
    square.size, square.energy = 0.6, 40.0
    if hasattr(square, "use_temperature"):
        square.use_temperature, square.temperature = True, 5000.0
        square.exposure, square.normalize = 1.0, False
    link_light("Square", square, (0.8, 2.0, 1.4), -35.0)

    look_ahead(bpy.context.scene.camera, (0.0, -2.4, 1.5), 52.0)
    bpy.context.scene.world = None


def principled(name, base, roughness, ior=None):
    """A material of Blender's default Principled BSDF with this base colour and roughness (and IOR when given)."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    node = material.node_tree.nodes["Principled BSDF"]
    node.inputs["Base Color"].default_value = (*base, 1.0)
    node.inputs["Roughness"].default_value = roughness
    if ior is not None:
        node.inputs["IOR"].default_value = ior
    return material


def principled_scene():
    """Principled BSDFs as an artist leaves them (only the base colour, roughness and IOR set) under a rectangular
    area light: a floor (roughness 0.5), a red sphere (0.25), a blue sphere (0.1, IOR 1.6) and a white box (0.7)."""
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, 0.0))
    bpy.context.object.name = "floor"
    bpy.context.object.data.materials.append(principled("floor", (0.45, 0.42, 0.38), 0.5))
    for name, location, base, roughness, ior in (("red ball", (-0.5, 0.6, 0.35), (0.7, 0.08, 0.05), 0.25, None),
                                                 ("blue ball", (0.45, 0.9, 0.3), (0.05, 0.15, 0.6), 0.1, 1.6)):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=location[2], location=location, segments=64, ring_count=32)
        bpy.ops.object.shade_smooth()
        bpy.context.object.name = name
        bpy.context.object.data.materials.append(principled(name, base, roughness, ior))
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.2, 1.7, 0.25))
    bpy.context.object.name = "box"
    bpy.context.object.data.materials.append(principled("box", (0.8, 0.8, 0.8), 0.7))
    area = bpy.data.lights.new("Lamp", "AREA")
    area.shape, area.size, area.size_y, area.energy = "RECTANGLE", 1.2, 0.6, 150.0
    link_light("Lamp", area, (-0.3, 1.2, 2.2), 15.0)
    look_ahead(bpy.context.scene.camera, (0.0, -2.0, 1.6), 55.0)
    bpy.context.scene.world = None


def artist_scene(out):
    """An artist's scene that Export writes exactly: Principled BSDFs left at Blender's defaults but for their base
    colour and roughness (a floor whose base colour is an Image Texture of a 4×4 float image packed into the .blend,
    a red and a blue ball, a white box), Blender's studio HDRI courtyard.exr as the world (strength 0.5), and a
    rectangular area light coloured by a Blackbody node at 3200 K."""
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, 0.0))
    floor = bpy.context.object
    floor.name = "floor"
    checker = [v for i in range(16) for v in ((0.6, 0.5, 0.3, 1.0) if (i + i // 4) % 2 else (0.2, 0.3, 0.5, 1.0))]
    tiles = principled("tiles", (0.8, 0.8, 0.8), 0.6)
    texture = tiles.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = packed_float_image("tiles", 4, 4, checker, out)
    texture.interpolation = "Closest"
    tiles.node_tree.links.new(texture.outputs["Color"], tiles.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    floor.data.materials.append(tiles)
    for name, location, base, roughness in (("red ball", (-0.6, 0.5, 0.4), (0.7, 0.08, 0.05), 0.3),
                                            ("blue ball", (0.5, 0.9, 0.35), (0.05, 0.15, 0.6), 0.15)):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=location[2], location=location, segments=64, ring_count=32)
        bpy.ops.object.shade_smooth()
        bpy.context.object.name = name
        bpy.context.object.data.materials.append(principled(name, base, roughness))
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.3, 1.8, 0.25))
    bpy.context.object.name = "box"
    bpy.context.object.data.materials.append(principled("box", (0.8, 0.8, 0.8), 0.5))
    lamp = area_light_with_blackbody(3200.0, (-0.4, 1.0, 2.4), size=1.2, power=200.0)
    lamp.data.shape, lamp.data.size_y = "RECTANGLE", 0.6
    world = bpy.context.scene.world
    world.use_nodes = True
    environment = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
    environment.image = bpy.data.images.load(os.path.join(STUDIO_WORLDS, "courtyard.exr"))
    background = world.node_tree.nodes["Background"]
    world.node_tree.links.new(environment.outputs["Color"], background.inputs["Color"])
    background.inputs["Strength"].default_value = 0.5
    look_ahead(bpy.context.scene.camera, (0.0, -2.2, 1.5), 60.0)


argv = sys.argv[sys.argv.index("--") + 1:]
mode, out = argv[0], argv[1]
OUT = out
if mode != "studio":
    clear_defaults()
bpy.context.scene.render.engine = "CYCLES"
if mode == "library":
    only = set(argv[3].split("|")) if len(argv) > 3 and argv[2] == "--only" else None
    library_scene(only)
elif mode == "textured":
    textured_scene(out)
elif mode == "studio":
    studio_scene(out)
elif mode == "grey_floor":
    grey_floor_scene(out, argv[2])
elif mode == "blackbody":
    blackbody_scene(float(argv[2]))
elif mode == "lights":
    blender_lights_scene()
elif mode == "principled":
    principled_scene()
elif mode == "artist":
    artist_scene(out)
else:
    raise SystemExit(f"unknown mode {mode}")
bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out))
