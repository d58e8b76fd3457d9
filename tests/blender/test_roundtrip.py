# SPDX-License-Identifier: Apache-2.0
"""Inside Blender: importing a chromatrace scene and exporting it again loses nothing the format holds.

For the paper box (analytic shapes, named spectra), the Cornell box (PLY meshes, a light that also reflects, an
inline spectrum) and the textured scene (image textures, an HDRI world turned about Z), import -> export -> compare, semantically and through chromatrace itself:
- the documents: every object, light, camera and render setting equal, spectra equal once CSV paths are
  resolved against each file's directory;
- `chromatrace scene-bands` at 1 nm over 360-830 nm (every spectrum, material and light as the renderers
  see them) and `chromatrace check-scene --json` (ids, groups, camera focal length, triangle count) equal;
- `chromatrace export-meshes` of both: the same triangles, bit for bit.
Then an object moved in Blender is exported as a world-space PLY mesh whose vertices moved with it.

Run: CHROMATRACE_EXE=... CHROMATRACE_SOURCE_DIR=... blender -b --factory-startup --python-exit-code 1 \
         --python tests/blender/test_roundtrip.py
"""

import json
import os
import shutil
import sys
import tempfile

import bpy

sys.path.insert(0, os.path.join(os.environ["CHROMATRACE_SOURCE_DIR"], "tests", "blender"))
from harness import SOURCE, TOOL, chromatrace, expect, failures, finish, scene_file  # noqa: E402,F401
from chromatrace import materials, ply, scene_export, scene_import  # noqa: E402


def fresh_scene():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras,
                       bpy.data.collections):
        for item in list(collection):
            collection.remove(item)
    return bpy.context.scene


def resolved(document, directory):
    """The document with every file path absolute, so documents in different places compare."""
    document = json.loads(json.dumps(document))
    for source in document.get("spectra", {}).values():
        if isinstance(source, dict) and "csv" in source:
            source["csv"] = os.path.normpath(os.path.join(directory, source["csv"]))
    for entry in document["objects"] + document["lights"]:
        if entry["shape"].get("type") == "mesh":
            entry["shape"]["file"] = os.path.normpath(os.path.join(directory, entry["shape"]["file"]))
    for source in textures_of(document):
        source["texture"] = os.path.normpath(os.path.join(directory, source["texture"]))
    return document


def textures_of(document):
    sources = [m.get(k) for m in document["materials"].values() for k in ("reflectance", "diffuse", "base_color")]
    sources.append(document.get("environment", {}).get("radiance"))
    return [s for s in sources if isinstance(s, dict) and "texture" in s]


def normalised(document):
    """Defaults spelled out, as the format defines them."""
    d = json.loads(json.dumps(document))
    for light in d["lights"]:
        light.setdefault("scale", 1)
        light.setdefault("group", light["name"])
        light.setdefault("two_sided", False)
    if "environment" in d:
        d["environment"]["scale"] = float(d["environment"].get("scale", 1))
        d["environment"].setdefault("group", "environment")
    for source in textures_of(d):  # the format's default colour space: linear for float files, else sRGB
        source.setdefault("colour_space", "linear" if source["texture"].endswith((".exr", ".hdr")) else "sRGB")
    d["camera"].setdefault("up", [0, 0, 1])
    d["camera"].setdefault("fov_axis", "horizontal")
    d["camera"].setdefault("sensor_width_mm", 36)
    r = d.setdefault("render", {})
    for key, value in (("samples", 64), ("max_bounces", 8), ("seed", 1), ("pixel_filter", "box"),
                       ("spectral_mode", "bands"), ("bands", "380:780:10")):
        r.setdefault(key, value)
    return d


def same_numbers(a, b):
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def meshes_of(scene_file, directory):
    index = TOOL.export_meshes(scene_file, directory)
    return [ply.read_ply(os.path.join(directory, e["file"])) for e in index["objects"] + index["lights"]]


WORK = tempfile.mkdtemp(prefix="chromatrace-roundtrip-")


def round_trip(original):
    work = tempfile.mkdtemp(dir=WORK)
    name = os.path.basename(original)
    scene = fresh_scene()
    scene_import.import_scene(original, scene, TOOL, print)
    exported = os.path.join(work, "exported", name)
    os.makedirs(os.path.dirname(exported))
    scene_export.export_scene(scene, exported, TOOL, print)

    with open(original) as f:
        a = normalised(resolved(json.load(f), os.path.dirname(original)))
    with open(exported) as f:
        b = normalised(resolved(json.load(f), os.path.dirname(exported)))
    for key in sorted(set(a) | set(b)):
        expect(same_numbers(a.get(key), b.get(key)), f"{name}: \"{key}\" differs:\n  {a.get(key)}\n  {b.get(key)}")

    if not textures_of(a):  # (scene-bands evaluates spectra, not images; the documents hold the same textures)
        bands_a = TOOL.band_averages(original, bands="360:830:1")
        bands_b = TOOL.band_averages(exported, bands="360:830:1")
        for key in ("spectra", "materials", "lights", "objects"):
            expect(bands_a[key] == bands_b[key], f"{name}: scene-bands {key} differ")
    summary_a, summary_b = TOOL.check_scene(original)["scene"], TOOL.check_scene(exported)["scene"]
    expect(summary_a == summary_b, f"{name}: check-scene summaries differ:\n  {summary_a}\n  {summary_b}")
    for i, (ma, mb) in enumerate(zip(meshes_of(original, os.path.join(work, "a")),
                                     meshes_of(exported, os.path.join(work, "b")))):
        expect((ma.positions, ma.triangles) == (mb.positions, mb.triangles), f"{name}: mesh {i} differs")
    print(f"ok: {name} round trip", flush=True)
    return scene, work


round_trip(scene_file("cornell_box", "cornell_box.json"))
round_trip(scene_file("textured", "textured.json"))  # image textures, UVs, an HDRI world
scene, work = round_trip(scene_file("paper", "box.json"))

# Imported spectra show their colours in Blender (the viewport, a plain render): each managed material's colour node
# holds chromatrace's linear sRGB of its spectrum (scene-bands: a reflectance under D65, an emission relative to
# D65 at its radiance), not a grey; a source changed since shows the grey again, not a stale colour.
box_bands = TOOL.band_averages(scene_file("paper", "box.json"))["spectra"]


def node_colour(material, node):
    return list(bpy.data.materials[material].node_tree.nodes[node].outputs[0].default_value[:3])


for material, spectrum in (("left_wall", "cornell_red"), ("right_wall", "cornell_green"), ("ceiling", "white_paint")):
    want = [min(max(c, 0.0), 1.0) for c in box_bands[spectrum]["linear_srgb_reflected"]]
    got = node_colour(material, "ct_reflectance")
    expect(max(abs(a - b) for a, b in zip(got, want)) < 1e-6, f"{material}: preview {got}, not {spectrum}'s {want}")
red, green = node_colour("left_wall", "ct_reflectance"), node_colour("right_wall", "ct_reflectance")
expect(red[0] > 2 * max(red[1], red[2]) and green[1] > max(green[0], green[2]), f"walls not red and green: {red}, {green}")
lamp = node_colour("ceiling_lamp (emitter)", "ct_emission")
want = box_bands["lamp"]["linear_srgb_emitted"]
expect(max(abs(a - b) / b for a, b in zip(lamp, want)) < 1e-6 and min(lamp) > 50,
       f"the lamp's emission {lamp}, not D65's colour at its radiance {want}")
wall = bpy.data.materials["left_wall"]
wall.chromatrace.reflectance.kind = "CONSTANT"
materials.build_material_nodes(wall)
expect(max(abs(c - 0.8) for c in node_colour("left_wall", "ct_reflectance")) < 1e-6,
       f"a changed source kept its stale preview: {node_colour('left_wall', 'ct_reflectance')}")

# An object moved in Blender: written as a world-space mesh that moved with it.
sphere = bpy.data.objects["sphere"]
sphere.location.x += 0.1
bpy.context.view_layer.update()
moved = os.path.join(work, "moved", "box.json")
os.makedirs(os.path.dirname(moved))
scene_export.export_scene(scene, moved, TOOL, print)
with open(moved) as f:
    document = json.load(f)
shape = document["objects"][5]["shape"]
expect(shape["type"] == "mesh" and os.path.isfile(os.path.join(os.path.dirname(moved), shape["file"])),
       f"moved sphere not written as a mesh: {shape}")
before = meshes_of(os.path.join(SOURCE, "scenes", "paper", "box.json"), os.path.join(work, "c"))[5]
after = meshes_of(moved, os.path.join(work, "d"))[5]
expect(len(before.triangles) == len(after.triangles), "moved sphere: triangle count changed")
shift = max(max(abs(pa[0] + 0.1 - pb[0]), abs(pa[1] - pb[1]), abs(pa[2] - pb[2]))
            for pa, pb in zip(before.positions, after.positions))
expect(shift < 1e-6, f"moved sphere: vertices off by {shift}")
expect(len(after.normals) == len(after.positions), "moved sphere: smooth shading (vertex normals) lost")
expect(document["objects"][0]["shape"]["type"] == "quad", "an unmoved quad was not written as a quad")

# A flat (constant) environment becomes Blender's world colour, which is relative to D65: said as it is imported.
with open(scene_file("cornell_box", "cornell_box.json")) as f:
    flat = json.load(f)
flat["environment"] = {"radiance": {"constant": 0.5}}
flat_file = os.path.join(WORK, "flat_environment.json")
with open(flat_file, "w") as f:
    json.dump(flat, f)
said = []
scene_import.import_scene(flat_file, fresh_scene(), TOOL, print, warn=said.append)
expect(any("environment.radiance: the flat spectrum 0.5 becomes the world colour 0.5" in m and "D65" in m for m in said),
       f"no warning that the flat environment becomes D65: {said}")

# A principled material of this Blender's Principled BSDF (version 2 from 4.0, 1 before) comes back as it went in;
# one of the other version is refused before anything is added, naming it.
version = 2 if bpy.app.version >= (4, 0, 0) else 1
with open(scene_file("cornell_box", "cornell_box.json")) as f:
    principled = json.load(f)
first = sorted(principled["materials"])[0]
colour = principled["materials"][first].get("reflectance")
entry = {"type": "principled", "version": version, "base_color": colour, "roughness": 0.35, "distribution": "ggx"}
entry.update({"ior": 1.6, "specular_ior_level": 0.4} if version == 2 else {"specular": 0.6})
principled["materials"][first] = entry
principled_file = os.path.join(WORK, "principled", "cornell_box.json")
os.makedirs(os.path.dirname(principled_file))
with open(principled_file, "w") as f:
    json.dump(principled, f)
round_trip(principled_file)
other = dict(entry, version=3 - version)
for key in ("ior", "specular_ior_level", "specular", "distribution"):
    other.pop(key, None)
principled["materials"][first] = other
with open(principled_file, "w") as f:
    json.dump(principled, f)
held = len(bpy.data.objects)
try:
    scene_import.import_scene(principled_file, fresh_scene(), TOOL, print)
    failures.append("a principled material of the other version was imported")
except Exception as e:  # BadInput
    expect(f"materials.{first}.version: {3 - version}, but Blender" in str(e), f"refusal does not name the version: {e}")

# An artist's Principled BSDF that is not an opaque dielectric (metal) is written as a Lambertian material of its base
# colour, and Export says so and why; an opaque one is written as the scene format's principled material.
scene = fresh_scene()
scene_import.import_scene(scene_file("cornell_box", "cornell_box.json"), scene, TOOL, print)
for name, metallic in (("steel", 1.0), ("plastic", 0.0)):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.1, location=(0.3, 0.3, 0.1))
    ball = bpy.context.object
    ball.name = name
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    material.node_tree.nodes["Principled BSDF"].inputs["Metallic"].default_value = metallic
    ball.data.materials.append(material)
approximations = []
artist = os.path.join(WORK, "artist", "scene.json")
os.makedirs(os.path.dirname(artist))
written = scene_export.export_scene(scene, artist, TOOL, print, approximations=approximations)
expect(written["materials"]["steel"]["type"] == "lambert", f"the metal is not written as lambert: {written['materials']['steel']}")
expect(any('material "steel"' in line and "Metallic is 1.0, not 0.0" in line for line in approximations),
       f"Export does not say why the metal is approximate: {approximations}")
expect(written["materials"]["plastic"]["type"] == "principled"
       and written["materials"]["plastic"]["version"] == (2 if bpy.app.version >= (4, 0, 0) else 1),
       f"the opaque Principled BSDF is not written as principled: {written['materials']['plastic']}")
expect(not any('material "plastic"' in line for line in approximations), f"the plastic was said approximate: {approximations}")

shutil.rmtree(WORK, ignore_errors=True)
finish("round trip")
