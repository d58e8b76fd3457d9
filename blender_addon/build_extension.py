# SPDX-License-Identifier: GPL-3.0-or-later
"""Builds the add-on as a Blender extension zip (Blender 4.2 and later) with Blender's own packager.

    PYTHON blender_addon/build_extension.py OUT_DIR

PYTHON is a Python with Blender's `bpy` module (build/bpy-4.5.15/bin/python after ./setup.sh); its packager,
`blender_ext.py build` (what `blender --command extension build` runs), checks blender_manifest.toml and writes
OUT_DIR/chromatrace-VERSION.zip. The package is staged with the one file it reads from outside its folder in the
source tree, core/data/defaults.json, as data/defaults.json (defaults.py looks there first), with the spectra
library, scenes/spectra's tables and their README (sources and licences), as data/spectra (spectra.py looks there
first), and with its licence, blender_addon/LICENSE (GPL-3.0-or-later, as the manifest says), which Blender's
extension platform requires. The add-on's `bl_info` version and the manifest's must be equal. Beside it,
OUT_DIR/chromatrace-VERSION-legacy.zip holds the same package as a folder, the form Blender 3.x installs from
Preferences > Add-ons > Install…. `cmake --build build --target blender_extension` runs this.
"""

import glob
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = os.path.join(HERE, "chromatrace")
DEFAULTS = os.path.join(HERE, "..", "core", "data", "defaults.json")
LICENSE = os.path.join(HERE, "LICENSE")
SPECTRA = os.path.join(HERE, "..", "scenes", "spectra")


def packager():
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        sys.exit("build_extension.py: error: this Python has no bpy module (use build/bpy-VERSION/bin/python)")
    found = glob.glob(os.path.join(spec.submodule_search_locations[0], "*", "scripts", "addons_core", "bl_pkg", "cli",
                                   "blender_ext.py"))
    if not found:
        sys.exit("build_extension.py: error: Blender's extension packager (bl_pkg/cli/blender_ext.py) not found")
    return found[0]


def versions_agree():
    with open(os.path.join(PACKAGE, "__init__.py")) as f:
        legacy = re.search(r'"version":\s*\((\d+),\s*(\d+),\s*(\d+)\)', f.read())
    with open(os.path.join(PACKAGE, "blender_manifest.toml")) as f:
        manifest = re.search(r'^version\s*=\s*"([^"]+)"', f.read(), re.M)
    if not legacy or not manifest or ".".join(legacy.groups()) != manifest.group(1):
        sys.exit("build_extension.py: error: bl_info's version in __init__.py and blender_manifest.toml's differ")
    return manifest.group(1)


def main(out_dir):
    version = versions_agree()
    os.makedirs(out_dir, exist_ok=True)
    with tempfile.TemporaryDirectory() as stage:
        source = os.path.join(stage, "chromatrace")
        shutil.copytree(PACKAGE, source, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        os.makedirs(os.path.join(source, "data"))
        shutil.copy(DEFAULTS, os.path.join(source, "data", "defaults.json"))
        shutil.copy(LICENSE, os.path.join(source, "LICENSE"))
        os.makedirs(os.path.join(source, "data", "spectra"))
        for table in glob.glob(os.path.join(SPECTRA, "*.csv")) + [os.path.join(SPECTRA, "README.md")]:
            shutil.copy(table, os.path.join(source, "data", "spectra"))
        result = subprocess.run([sys.executable, packager(), "build", "--source-dir", source, "--output-dir", out_dir],
                                capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit(f"build_extension.py: error: {(result.stdout + result.stderr).strip()}")
        print(result.stdout.strip().splitlines()[-1])
        # The same package as a legacy add-on zip for Blender 3.x (Preferences > Add-ons > Install…): the folder
        # chromatrace/ at its root, which 3.x unpacks into its add-ons folder as one module. (The extension zip
        # holds the package's files at its root, which 3.x would spill into the add-ons folder one by one.)
        legacy = os.path.join(out_dir, f"chromatrace-{version}-legacy.zip")
        with zipfile.ZipFile(legacy + ".partial", "w", zipfile.ZIP_DEFLATED) as z:
            for folder, dirs, files in os.walk(source):
                dirs.sort()
                for name in sorted(files):
                    path = os.path.join(folder, name)
                    z.write(path, os.path.relpath(path, stage))
        os.replace(legacy + ".partial", legacy)
        print(f"created: \"{legacy}\" (Blender 3.x add-on)")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
