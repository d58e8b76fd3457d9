# SPDX-License-Identifier: Apache-2.0
"""What every test script that runs inside Blender shares: the add-on loaded from the source tree and
registered, the chromatrace command, the source tree's scenes as this Blender renders them, and failures
collected as the script goes and reported at its end."""

import os
import shutil
import sys
import tempfile

import bpy

SOURCE = os.environ["CHROMATRACE_SOURCE_DIR"]
sys.path.insert(0, os.path.join(SOURCE, "blender_addon"))
import chromatrace  # noqa: E402
from chromatrace import tool  # noqa: E402

sys.path.insert(0, os.path.join(SOURCE, "tests", "blender"))
from scene_for_blender import scene_for_blender  # noqa: E402

chromatrace.register()
TOOL = tool.Tool(tool.find_executable())
failures = []
_SCENES = tempfile.mkdtemp(prefix="chromatrace-scenes-")


def scene_file(*parts):
    """scenes/<parts> of the source tree as this Blender's Cycles renders it (its GGX masking), as a copy whose
    paths are absolute (tests/blender/scene_for_blender.py)."""
    out = os.path.join(_SCENES, "_".join(parts))
    return scene_for_blender(os.path.join(SOURCE, "scenes", *parts), bpy.app.version_string.split()[0], out)


def expect(condition, message):
    if not condition:
        failures.append(message)


def finish(name):
    """Reports every failure on stderr and exits 1 (Blender runs these with --python-exit-code 1), or says ok."""
    shutil.rmtree(_SCENES, ignore_errors=True)
    if failures:
        for f in failures:
            print(f"FAIL: {f}", file=sys.stderr)
        sys.exit(1)
    print(f"{name}: all ok")


def run_in_window(steps, name, work):
    """Runs a GUI script in Blender's window: `steps` is a generator that yields the seconds to wait before its next
    step (the window redraws meanwhile). At its end, or at any exception, removes `work`, reports every failure
    and quits Blender with exit code 1 on failure (from a timer, sys.exit would only end the timer)."""
    def quit_blender():
        shutil.rmtree(work, ignore_errors=True)
        shutil.rmtree(_SCENES, ignore_errors=True)
        for f in failures:
            print(f"FAIL: {f}", file=sys.stderr, flush=True)
        if not failures:
            print(f"{name}: all ok", flush=True)
        os._exit(1 if failures else 0)

    def tick():
        try:
            return next(steps)
        except StopIteration:
            quit_blender()
        except Exception as e:  # a failure inside a timer must still end Blender
            failures.append(f"{type(e).__name__}: {e}")
            quit_blender()
        return None

    bpy.context.preferences.view.show_splash = False
    bpy.app.timers.register(tick, first_interval=1.0)
