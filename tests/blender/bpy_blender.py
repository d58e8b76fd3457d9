# SPDX-License-Identifier: Apache-2.0
"""Blender's command line, for Blender as a Python module (PyPI's `bpy`): the add-on's tests run every Blender
they support through the one command line they were written for.

    PYTHON bpy_blender.py [--background|-b] [--factory-startup] [FILE.blend] [--python-exit-code N]
                          [--python FILE | --python-expr EXPR]... [-- ARGS...]

PYTHON is the interpreter of a virtual environment with `bpy` installed. The options are Blender's own and are
carried out in order, as Blender does: a .blend is opened where it stands, each script runs where it stands
with `sys.argv` as Blender gives it (this command line, so a script finds its arguments after `--`). A script's
`sys.exit(N)` ends the run with N. A script that raises ends it with the --python-exit-code given (Blender's
default, 0, otherwise), after printing the traceback. The module has no window: --background is implied, and
any other Blender option is refused, so a test cannot silently mean something else here. The process ends as
Blender's does, without the interpreter's teardown (where the module, its render threads still there, can
stall).
"""

import os
import runpy
import sys
import traceback


def main(argv):
    rest = []
    if "--" in argv:
        cut = argv.index("--")
        argv, rest = argv[:cut], argv[cut:]
    actions, exit_code, factory = [], 0, False
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg in ("--background", "-b"):
            pass
        elif arg == "--factory-startup":
            factory = True
        elif arg == "--python-exit-code":
            exit_code = int(argv[i + 1])
            i += 1
        elif arg in ("--python", "-P", "--python-expr"):
            actions.append((arg, argv[i + 1]))
            i += 1
        elif arg.endswith(".blend") and not arg.startswith("-"):
            actions.append(("open", arg))
        else:
            print(f"bpy_blender.py: error: Blender option {arg!r} is not supported for the bpy module", file=sys.stderr)
            return 2
        i += 1

    import bpy  # after the arguments are checked: importing the module takes a second
    if factory:
        bpy.ops.wm.read_factory_settings(use_empty=False)
    sys.argv = [sys.argv[0], *argv, *rest]
    for kind, value in actions:
        try:
            if kind == "open":
                bpy.ops.wm.open_mainfile(filepath=os.path.abspath(value))
            elif kind == "--python-expr":
                exec(compile(value, "<string>", "exec"), {"__name__": "__main__"})
            else:
                runpy.run_path(value, run_name="__main__")
        except SystemExit as e:
            if isinstance(e.code, int) or e.code is None:
                return e.code or 0
            print(e.code, file=sys.stderr)  # sys.exit("message"): Python prints it and exits with 1
            return 1
        except BaseException:  # Blender prints the traceback and goes on, or exits with --python-exit-code
            traceback.print_exc()
            if exit_code:
                return exit_code
    return 0


if __name__ == "__main__":
    code = main(sys.argv[1:])
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
