# SPDX-License-Identifier: Apache-2.0
# The Python module's tests (docs/python.md), run by CTest (tests/CMakeLists.txt) with the build's python/ directory on
# PYTHONPATH and CHROMATRACE_EXE naming the command they are compared with.
import json
import os
import subprocess
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[2]
DATA = SOURCE / "tests" / "data"


def exe() -> str:
    return os.environ["CHROMATRACE_EXE"]


def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    """The command with `args`; its exit code is checked unless check=False."""
    result = subprocess.run([exe(), *map(str, args)], capture_output=True, text=True)
    if check and result.returncode != 0:
        raise AssertionError(f"chromatrace {' '.join(map(str, args))}: exit {result.returncode}: {result.stderr}")
    return result


def command_error(*args: str) -> str:
    """The message the command prints for bad input (exit 2), without its "chromatrace CMD: error: " prefix."""
    result = run(*args, check=False)
    assert result.returncode == 2, result.stderr
    line = result.stderr.strip().splitlines()[-1]
    assert ": error: " in line, line
    return line.split(": error: ", 1)[1]


def photographs() -> list[Path]:
    """The test photographs: every file of tests/data/photos/masks.json."""
    photos = json.loads((DATA / "photos" / "masks.json").read_text())["photos"]
    return [Path(p["file"]) if Path(p["file"]).is_absolute() else DATA / "photos" / p["file"] for p in photos]


@pytest.fixture(scope="session")
def chromatrace():
    import chromatrace as module
    return module
