# SPDX-License-Identifier: Apache-2.0
"""Test and benchmark helper: Cycles' own render of a .blend, as an artist gets it without chromatrace, to an
OpenEXR of scene-linear RGB (Blender's scene-linear space: linear sRGB, D65 white; no view transform applies to
it). Prints "PLAIN_RENDER_SECONDS wall cpu" of the render alone.

    blender -b --factory-startup BLEND --python render_plain.py -- OUT.exr WIDTHxHEIGHT SAMPLES
"""

import os
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
out, size, samples = argv[0], argv[1], int(argv[2])
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = samples
scene.cycles.seed = 1
if hasattr(scene.cycles, "use_denoising"):
    scene.cycles.use_denoising = False
scene.render.resolution_x, scene.render.resolution_y = (int(v) for v in size.split("x"))
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.filepath = os.path.abspath(out)
start, start_cpu = time.monotonic(), time.process_time()
bpy.ops.render.render(write_still=True)
print(f"PLAIN_RENDER_SECONDS {time.monotonic() - start:.3f} {time.process_time() - start_cpu:.3f}", flush=True)
