# SPDX-License-Identifier: GPL-3.0-or-later
"""Headless spectral rendering with Blender and Cycles.

    blender --background --factory-startup --python blender_addon/batch.py -- \
        --scene SCENE.json --out OUT.exr [--samples N] [--bands lo:hi:w | --bands-file F] [--max-bounces K]
        [--components paths,lights,bounces] [--resolution WxH] [--seed S] [--cache-dir DIR] [--keep-cache]
        [--on-mixing-nodes refuse|one-band] [--on-world refuse|omit] [--explain [FILE]] [--band-group G [--bounce-limit NAME]]
    (or --blend FILE.blend instead of --scene; the .blend is never written)
    python blender_addon/batch.py --scene SCENE.json --out OUT.exr ...
        the same from a Python with Blender as a module (PyPI's bpy 4.5, 5.2 or 5.3), arguments with or without `--`

The add-on installed as an extension (Blender 4.2+) carries the same entry as chromatrace.headless:
    blender -b --python-expr "import bl_ext.user_default.chromatrace.headless as h; h.main()" -- --scene ...

--band-group G renders only band group G (with all its bounce limits, or only --bounce-limit NAME's render) into
the cache and stops; a run without it
then finds every group there and assembles (chromatrace farm cycles runs one task per group, then that run).

Before rendering a --scene it prints what its settings leave out, one `chromatrace: warning: ...` line each (also
with --quiet): the band plan's colour errors, a bounce limit that drops light and samples whose noise is predicted
above a mean ΔE00 of 1 (`chromatrace check-scene --renderer cycles` with the batch's options; docs/render.md).

--explain prints the pre-flight summary as JSON (to stdout, or FILE) and renders nothing: every material,
light and the world, exact / upsampled / refused with the reasons in full, and the Cycles renders needed.

Exit status 0 on success, 1 on a runtime failure, 2 on bad input, with one line on stderr naming the file,
field or option at fault (as the `chromatrace` command). Progress lines go to stderr (--quiet: none).
A run that is killed resumes from the band groups already rendered when run again with the same input.

For tests: CHROMATRACE_TEST_FAIL_AT_RENDER=N raises an exception just before the N-th new Cycles render
(counting from 0), CHROMATRACE_TEST_KILL_AT_RENDER=N kills the process there (SIGKILL).
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from chromatrace import headless  # noqa: E402

headless.main(headless.script_arguments(sys.argv), prog="batch.py")
