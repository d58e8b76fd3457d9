# SPDX-License-Identifier: Apache-2.0
"""Test helper: blender -b --factory-startup --python make_blend.py -- SCENE.json OUT.blend
imports a chromatrace scene with the add-on and saves it as a .blend."""

import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blender_addon"))
import chromatrace  # noqa: E402
from chromatrace import scene_import, tool  # noqa: E402

scene_file, blend = sys.argv[sys.argv.index("--") + 1:][:2]
chromatrace.register()
for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras,
                   bpy.data.worlds):
    for item in list(collection):
        collection.remove(item)
scene_import.import_scene(scene_file, bpy.context.scene, tool.Tool(tool.find_executable()))
bpy.ops.wm.save_as_mainfile(filepath=blend)
