#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `pip install .` (pyproject.toml, scikit-build-core) into a fresh virtual environment beside Debian's packages, built
# in a scratch directory; then the module imports from there, outside the source tree, and analyses an array.
# Usage: check_pip_install.sh SOURCE_DIR PYTHON
set -euo pipefail
source_dir=$1
python=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$python" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --quiet --disable-pip-version-check --config-settings=build-dir="$work/build" "$source_dir"
cd "$work"
env -u PYTHONPATH "$work/venv/bin/python" - "$work/venv" <<'PYTHON'
import pathlib, sys
import numpy as np
import chromatrace
assert pathlib.Path(chromatrace.__file__).is_relative_to(sys.argv[1]), chromatrace.__file__
analysis = chromatrace.analyze(np.full((8, 8, 3), 0.5, np.float32))
assert analysis.regions[0]["pixels"] == 64 and analysis.data["input"]["curve"]["source"] == "a float array: linear"
print("pip install: ok,", chromatrace.__file__)
PYTHON
