"""What every test script that runs inside Blender shares: the add-on loaded from the source tree and
registered, the chromatrace command, and failures collected as the script goes and reported at its end."""

import os
import sys

SOURCE = os.environ["CHROMATRACE_SOURCE_DIR"]
sys.path.insert(0, os.path.join(SOURCE, "blender_addon"))
import chromatrace  # noqa: E402
from chromatrace import tool  # noqa: E402

chromatrace.register()
TOOL = tool.Tool(tool.find_executable())
failures = []


def expect(condition, message):
    if not condition:
        failures.append(message)


def finish(name):
    """Reports every failure on stderr and exits 1 (Blender runs these with --python-exit-code 1), or says ok."""
    if failures:
        for f in failures:
            print(f"FAIL: {f}", file=sys.stderr)
        sys.exit(1)
    print(f"{name}: all ok")
