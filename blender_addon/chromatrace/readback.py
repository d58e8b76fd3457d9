# SPDX-License-Identifier: GPL-3.0-or-later
"""A Cycles render read back in this process, with the OpenImageIO Python module Blender has.

Blender 4.x and 5.x bundle OpenImageIO's Python module (in the bpy module, under its own Python's site-packages,
which is not on sys.path); Debian's Blender 3.4 runs the system Python, where Debian's python3-openimageio is. Either
reads the file with the image library this process already has, so a render's check costs no process start (a
`chromatrace info` costs 0.2 s of start-up, most of a small preview's time: bench/README.md, "Python module"). Where
neither imports, read_back returns None and the caller asks the command.
"""

import importlib
import os
import sys

_module = None
_looked = False


def _open_image_io():
    global _module, _looked
    if _looked:
        return _module
    _looked = True
    try:
        _module = importlib.import_module("OpenImageIO")
        return _module
    except ImportError:
        pass
    try:
        import bpy
        version = f"python{sys.version_info.major}.{sys.version_info.minor}"
        site = os.path.join(bpy.utils.resource_path("LOCAL"), "python", "lib", version, "site-packages")
        if os.path.isdir(os.path.join(site, "OpenImageIO")):
            sys.path.append(site)
            _module = importlib.import_module("OpenImageIO")
    except (ImportError, AttributeError, OSError):
        _module = None
    return _module


def read_back(path):
    """{"width", "height", "channels": [{"name"}]} of an image read to the end of its pixel data, as `chromatrace
    info --json` gives them; a one-line reason (str) when it does not read; None when OpenImageIO is not here."""
    oiio = _open_image_io()
    if oiio is None:
        return None
    image = oiio.ImageInput.open(path)
    if image is None:
        return f"{path}: {oiio.geterror().strip() or 'cannot open'}"
    try:
        spec = image.spec()
        # In blocks of rows of about 64 MB, so that a large render never sits in memory whole.
        rows = max(1, (64 << 20) // max(1, spec.width * spec.nchannels * 4))
        for y in range(spec.y, spec.y + spec.height, rows):
            block = image.read_scanlines(0, 0, y, min(y + rows, spec.y + spec.height), 0, 0, spec.nchannels, "float")
            if block is None:
                why = image.geterror().strip().replace("\n", " ")
                return f"{path}: the pixel data does not read to its end (row {y - spec.y}): {why}"
        return {"width": spec.width, "height": spec.height, "channels": [{"name": n} for n in spec.channelnames]}
    finally:
        image.close()
