# SPDX-License-Identifier: Apache-2.0
"""Inside a real Blender window (under Xvfb): the artist's path from an imported scene to the picture.

The textured scene (image textures, an HDRI world) is imported; Check Spectra fills the pre-flight panel
(every material and the world upsampled, nothing refused); Render Spectral runs as a modal operator (progress,
one Cycles render per step) until it ends; its preview opens in an Image Editor, which must then show the
preview file. A screenshot of the window is written to CHROMATRACE_SCREENSHOT when that is set, and one of the
render tab as it opens beside it (NAME_render_tab.png); docs/images/blender_gui.png and
blender_render_tab.png are made this way.

Run: CHROMATRACE_EXE=... CHROMATRACE_SOURCE_DIR=... xvfb-run -a -s "-screen 0 1600x1000x24" \
         blender --factory-startup --python tests/blender/test_gui.py
(the script quits Blender itself, with exit code 1 on failure).
"""

import os
import sys
import tempfile

import bpy

sys.path.insert(0, os.path.join(os.environ["CHROMATRACE_SOURCE_DIR"], "tests", "blender"))
from harness import SOURCE, expect, run_in_window  # noqa: E402
from chromatrace.operators import PREFLIGHT  # noqa: E402

WORK = tempfile.mkdtemp(prefix="chromatrace-gui-")
SCREENSHOT = os.environ.get("CHROMATRACE_SCREENSHOT")
TIMEOUT_S = 240


def window_area(kind):
    window = bpy.context.window_manager.windows[0]
    areas = sorted(window.screen.areas, key=lambda a: -a.width * a.height)
    return window, next(a for a in areas if a.type == kind)


def script():
    """A generator of steps; each yields the seconds to wait before the next (the window redraws meanwhile)."""
    scene = bpy.context.scene
    window, view = window_area("VIEW_3D")
    view.type = "IMAGE_EDITOR"  # where an artist looks at renders (the add-on shows its preview in one)
    for name in ("Cube", "Light", "Camera"):  # the default file's objects: the scene is the imported one
        bpy.data.objects.remove(bpy.data.objects[name])
    with bpy.context.temp_override(window=window, area=view):
        bpy.ops.chromatrace.import_scene(filepath=os.path.join(SOURCE, "scenes", "textured", "textured.json"))
    s = scene.chromatrace
    s.samples, s.max_bounces = 64, 4
    s.bands_lo, s.bands_hi, s.bands_width = 400, 700, 50
    scene.render.resolution_x = scene.render.resolution_y = 128
    s.output_path = os.path.join(WORK, "textured.exr")
    s.cache_dir = os.path.join(WORK, "cache")
    yield 0.5

    # The properties editor on the render tab, the chromatrace panels open; Check Spectra.
    _, properties = window_area("PROPERTIES")
    properties.spaces.active.context = "RENDER"
    region = next(r for r in properties.regions if r.type == "WINDOW")
    with bpy.context.temp_override(window=window, area=properties):
        expect(bpy.ops.chromatrace.preflight() == {"FINISHED"}, "Check Spectra did not finish")
    summary = PREFLIGHT.get(scene.name)
    expect(summary is not None and summary["ok"], f"the textured scene is refused: {summary}")
    statuses = {(o["kind"], o["name"]): o["status"] for o in (summary or {}).get("owners", [])}
    expect(statuses.get(("world", "environment")) == "upsampled", f"the HDRI world is not upsampled: {statuses}")
    expect(statuses.get(("material", "floor")) == "upsampled", f"the textured floor is not upsampled: {statuses}")
    yield 0.5
    if SCREENSHOT:  # the render tab as it opens: Render Spectral and Analyze Histogram under the engine
        with bpy.context.temp_override(window=window):
            bpy.ops.screen.screenshot(filepath=os.path.splitext(SCREENSHOT)[0] + "_render_tab.png")
    for _ in range(60):  # the chromatrace panel follows Cycles' on the render tab
        with bpy.context.temp_override(window=window, area=properties, region=region):
            bpy.ops.view2d.scroll_down(deltay=200)
        yield 0.02

    # Render Spectral, as the button does: modal, one Cycles render per step.
    with bpy.context.temp_override(window=window, area=properties):
        result = bpy.ops.chromatrace.render_spectral("INVOKE_DEFAULT")
    expect(result == {"RUNNING_MODAL"}, f"Render Spectral did not start modally: {result}")
    waited = 0.0
    while not os.path.isfile(os.path.join(WORK, "textured.preview.png")) and waited < TIMEOUT_S:
        yield 1.0
        waited += 1.0
    yield 2.0  # the operator's last step shows the preview

    preview = os.path.join(WORK, "textured.preview.png")
    expect(os.path.isfile(s.output_path), "Render Spectral wrote no spectral file")
    expect(os.path.isfile(preview), f"no preview after {TIMEOUT_S} s")
    shown = [a.spaces.active.image for w in bpy.context.window_manager.windows for a in w.screen.areas
             if a.type == "IMAGE_EDITOR" and a.spaces.active.image is not None]
    expect(any(os.path.abspath(bpy.path.abspath(i.filepath)) == preview for i in shown),
           f"no Image Editor shows the preview: {[i.filepath for i in shown]}")
    image_area = next((a for a in window.screen.areas if a.type == "IMAGE_EDITOR"), None)
    if image_area is not None:
        image_region = next(r for r in image_area.regions if r.type == "WINDOW")
        with bpy.context.temp_override(window=window, area=image_area, region=image_region):
            bpy.ops.image.view_all(fit_view=True)
        yield 0.5
    if SCREENSHOT:
        with bpy.context.temp_override(window=window):
            bpy.ops.screen.screenshot(filepath=SCREENSHOT)
        expect(os.path.isfile(SCREENSHOT), f"no screenshot at {SCREENSHOT}")


run_in_window(script(), "gui", WORK)
