# SPDX-License-Identifier: Apache-2.0
"""The add-on as a Blender extension (4.2 and later), as an artist installs it: the zip that
`cmake --build build --target blender_extension` builds, accepted by the running Blender's own `extension validate`
and holding its licence (GPL-3.0-or-later, the manifest's, which Blender's extension platform requires), installed headless into a user repository
(Preferences > Get Extensions > Install from Disk), enabled, its spectra library found by Check Spectra, and rendering the paper box through the installed
package's own headless entry, with nothing of the source tree on the path.

    blender -b --factory-startup --python-exit-code 1 --python test_extension.py -- ZIP SCENE.json OUT.exr

Run with BLENDER_USER_RESOURCES set to an empty folder: the install goes there, not into the user's Blender.
"""

import importlib
import os
import subprocess
import sys
import zipfile

import bpy

zip_path, scene, out = sys.argv[sys.argv.index("--") + 1:][:3]
user = os.environ.get("BLENDER_USER_RESOURCES", "")
if not user:
    sys.exit("test_extension.py: set BLENDER_USER_RESOURCES to an empty folder")
if any(p.endswith("blender_addon") for p in sys.path) or "chromatrace" in sys.modules:
    sys.exit("test_extension.py: the source tree's add-on is on the path")

packager = os.path.join(bpy.utils.system_resource("SCRIPTS"), "addons_core", "bl_pkg", "cli", "blender_ext.py")
validate = subprocess.run([sys.executable, packager, "validate", zip_path], capture_output=True, text=True)
if validate.returncode != 0:
    sys.exit(f"FAIL: Blender's extension validate refuses {zip_path}: {(validate.stdout + validate.stderr).strip()}")
with zipfile.ZipFile(zip_path) as package_zip:
    names = package_zip.namelist()
    licence = package_zip.read("LICENSE").decode() if "LICENSE" in names else ""
if "GNU GENERAL PUBLIC LICENSE" not in licence or "Version 3, 29 June 2007" not in licence:
    sys.exit(f"FAIL: {zip_path} holds no GPL-3.0 LICENSE at its root (the manifest's licence): {sorted(names)[:8]} ...")

result = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
if result != {"FINISHED"}:
    sys.exit(f"FAIL: install returned {result}")
package = "bl_ext.user_default.chromatrace"
if package not in bpy.context.preferences.addons:
    sys.exit(f"FAIL: {package} is not enabled: {list(bpy.context.preferences.addons.keys())}")
if not hasattr(bpy.types.Scene, "chromatrace"):
    sys.exit("FAIL: the extension did not register its scene settings")
# The spectra library travels with the extension: a material's Reflectance > Library spectrum is found and Check
# Spectra reads it (the zip once held no library: "…/extensions/scenes/spectra/cornell_box.csv: cannot open file").
spectra = importlib.import_module(package + ".spectra")
if "cornell_box.csv:red" not in spectra.library_entries():
    sys.exit(f"FAIL: the installed extension's spectra library lacks cornell_box.csv:red: {spectra.library_entries()}")
material = bpy.data.objects["Cube"].material_slots[0].material
material.chromatrace.reflectance.kind = "LIBRARY"
material.chromatrace.reflectance.library = "cornell_box.csv:red"
try:
    bpy.ops.chromatrace.preflight()
except RuntimeError as e:
    sys.exit(f"FAIL: Check Spectra with the library's cornell_box.csv:red: {e}")
headless = importlib.import_module(package + ".headless")
if not os.path.realpath(headless.__file__).startswith(os.path.realpath(user)):
    sys.exit(f"FAIL: headless came from {headless.__file__}, not from the installed extension")

headless.run(["--scene", scene, "--out", out, "--resolution", "16x16", "--samples", "4", "--bands", "400:700:50",
              "--components", "paths", "--cache-dir", os.path.join(os.path.dirname(out), "cache"), "--quiet"])
check = subprocess.run([os.environ["CHROMATRACE_EXE"], "info", "--check", out], capture_output=True, text=True)
if check.returncode != 0:
    sys.exit(f"FAIL: chromatrace info --check {out}: {check.stderr.strip()}")
print(f"extension: installed from {zip_path}, enabled as {package}, rendered {out}")
