# SPDX-License-Identifier: Apache-2.0
"""Test helper: a .blend's scene written as a scene file, as the Render panel's Export writes it.

    blender -b BLEND --factory-startup --python export_blend.py -- OUT.json

Environment: CHROMATRACE_EXE, CHROMATRACE_SOURCE_DIR. What the file holds only approximately is printed, one
line each, after "approximately:".
"""
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.environ["CHROMATRACE_SOURCE_DIR"], "blender_addon"))
import chromatrace  # noqa: E402
from chromatrace import scene_export  # noqa: E402
from chromatrace.tool import Tool  # noqa: E402

chromatrace.register()

out = sys.argv[sys.argv.index("--") + 1]
approximations = []
scene_export.export_scene(bpy.context.scene, out, Tool(os.environ["CHROMATRACE_EXE"]), log=lambda m: None,
                          approximations=approximations)
for line in approximations:
    print(f"approximately: {line}")
