# SPDX-License-Identifier: Apache-2.0
"""Inside a real Blender window (under Xvfb, events simulated): Esc pressed in a second window — the one an earlier
render's preview opened, which then has the focus — cancels a spectral render running from the main window. It
was lost: a modal operator hears only its own window's events.

Run: CHROMATRACE_EXE=... CHROMATRACE_SOURCE_DIR=... xvfb-run -a -s "-screen 0 1600x1000x24" \\
         blender --factory-startup --enable-event-simulate --python tests/blender/test_gui_escape.py
(the script quits Blender itself, with exit code 1 on failure).
"""

import os
import sys
import tempfile

import bpy

sys.path.insert(0, os.path.join(os.environ["CHROMATRACE_SOURCE_DIR"], "tests", "blender"))
from harness import expect, run_in_window  # noqa: E402
from chromatrace import operators  # noqa: E402

WORK = tempfile.mkdtemp(prefix="chromatrace-escape-")
TIMEOUT_S = 120


def script():
    scene = bpy.context.scene
    s = scene.chromatrace
    s.samples, s.max_bounces = 16, 2
    s.bands_lo, s.bands_hi, s.bands_width = 380, 780, 10  # 14 Cycles renders: time to press Esc in between
    scene.render.resolution_x, scene.render.resolution_y = 96, 64
    s.output_path = os.path.join(WORK, "escape.exr")
    s.cache_dir = os.path.join(WORK, "cache")
    main = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=main):
        bpy.ops.wm.window_new()
    yield 1.0
    windows = list(bpy.context.window_manager.windows)
    expect(len(windows) == 2, f"no second window: {len(windows)}")
    second = next(w for w in windows if w != main)
    area = max(main.screen.areas, key=lambda a: a.width * a.height)
    with bpy.context.temp_override(window=main, area=area):
        result = bpy.ops.chromatrace.render_spectral("INVOKE_DEFAULT")
    expect(result == {"RUNNING_MODAL"}, f"Render Spectral did not start modally: {result}")
    yield 3.0
    expect(scene.name in operators.RENDERING, "the render is not running three seconds in")
    second.event_simulate(type="ESC", value="PRESS")
    second.event_simulate(type="ESC", value="RELEASE")
    waited = 0.0
    while scene.name in operators.RENDERING and waited < TIMEOUT_S:
        yield 0.5
        waited += 0.5
    expect(scene.name not in operators.RENDERING, f"Esc in the second window did not cancel in {TIMEOUT_S} s")
    expect(not os.path.exists(s.output_path), "the cancelled render wrote its output")


run_in_window(script(), "escape", WORK)
