# SPDX-License-Identifier: Apache-2.0
"""The add-on as Blender 3.x installs it: the legacy zip the build makes beside the extension
(build/chromatrace-VERSION-legacy.zip), through Preferences > Add-ons > Install… headless, into an empty user
scripts folder: it unpacks as the one module chromatrace (the extension zip spilled 35 loose files there, and
enabling failed), enables, registers its settings and finds its spectra library.

    BLENDER_USER_SCRIPTS=EMPTY_DIR blender -b --factory-startup --python-exit-code 1 --python test_legacy_zip.py -- ZIP
"""

import importlib
import os
import sys

import addon_utils
import bpy

zip_path = sys.argv[sys.argv.index("--") + 1]
scripts = os.environ.get("BLENDER_USER_SCRIPTS", "")
if not scripts:
    sys.exit("test_legacy_zip.py: set BLENDER_USER_SCRIPTS to an empty folder")
if any(p.endswith("blender_addon") for p in sys.path) or "chromatrace" in sys.modules:
    sys.exit("test_legacy_zip.py: the source tree's add-on is on the path")

if bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True) != {"FINISHED"}:
    sys.exit(f"FAIL: installing {zip_path} did not finish")
addons = os.path.join(scripts, "addons")
unpacked = sorted(os.listdir(addons))
if unpacked != ["chromatrace"]:
    sys.exit(f"FAIL: {zip_path} unpacked into the add-ons folder as {unpacked}, not the one module chromatrace")
addon_utils.enable("chromatrace", default_set=True)
if "chromatrace" not in bpy.context.preferences.addons or not hasattr(bpy.types.Scene, "chromatrace"):
    sys.exit("FAIL: the installed add-on did not enable and register its settings")
spectra = importlib.import_module("chromatrace.spectra")
if not os.path.realpath(spectra.__file__).startswith(os.path.realpath(addons)):
    sys.exit(f"FAIL: chromatrace came from {spectra.__file__}, not from the installed add-on")
if "cornell_box.csv:red" not in spectra.library_entries():
    sys.exit(f"FAIL: the installed add-on's spectra library lacks cornell_box.csv:red: {spectra.library_entries()}")
print(f"legacy zip: installed from {zip_path} as one module, enabled")
