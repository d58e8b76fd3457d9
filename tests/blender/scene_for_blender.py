# SPDX-License-Identifier: Apache-2.0
"""Test helper (plain Python): a copy of a scene file as a given Blender's Cycles can render it, its GGX materials
with that Cycles' Smith masking (separable up to Blender 3.x, height-correlated from 4.0; the add-on refuses a
scene that asks for the other), its file paths made absolute as core/scene.cpp's rebase_scene_paths does (the
"csv", "texture" and a shape's "file" entries).

    python3 scene_for_blender.py SCENE.json BLENDER_VERSION OUT.json [--empty DIR]
        (--empty: DIR is removed and made anew first, for a test's fresh work folder)
"""

import json
import os
import shutil
import sys


def masking_of(blender_version):
    return "height-correlated" if int(str(blender_version).split(".")[0]) >= 4 else "separable"


def _absolute_paths(node, base, key=""):
    if isinstance(node, list):
        for element in node:
            _absolute_paths(element, base)
    elif isinstance(node, dict):
        for k, child in node.items():
            if (k in ("csv", "texture") or (k == "file" and key == "shape")) and isinstance(child, str):
                node[k] = os.path.normpath(os.path.join(base, child))
            else:
                _absolute_paths(child, base, k)


def scene_for_blender(scene, blender_version, out, change=None):
    """Writes `out`: `scene` for this Blender (and with change(document) applied, if given); returns `out`."""
    with open(scene) as f:
        document = json.load(f)
    _absolute_paths(document, os.path.dirname(os.path.abspath(scene)))
    for material in document.get("materials", {}).values():
        if material.get("lobe", "ggx") == "ggx" and material.get("type") == "dichromatic":
            if masking_of(blender_version) == "separable":  # the format's default, which exports leave out
                material.pop("masking", None)
            else:
                material["masking"] = masking_of(blender_version)
    if change is not None:
        change(document)
    with open(out, "w") as f:
        json.dump(document, f, indent=1)
    return out


if __name__ == "__main__":
    if "--empty" in sys.argv:
        folder = sys.argv[sys.argv.index("--empty") + 1]
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(folder)
    scene_for_blender(*sys.argv[1:4])
