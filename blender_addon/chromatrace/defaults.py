# SPDX-License-Identifier: GPL-3.0-or-later
"""The defaults chromatrace's parts share, from core/data/defaults.json — the file the C++ library embeds — so
that the add-on renders what the tracer renders when a scene leaves a setting out (pure Python, no bpy)."""

import json
import os


def defaults_file():
    """data/defaults.json inside the add-on when it is installed as an extension (blender_addon/build_extension.py
    puts it there); otherwise core/data/defaults.json beside the add-on, in the source tree and once installed
    (<prefix>/share/chromatrace/{blender_addon,core/data})."""
    here = os.path.dirname(os.path.realpath(__file__))  # through a symlink in Blender's add-ons folder
    packaged = os.path.join(here, "data", "defaults.json")
    if os.path.isfile(packaged):
        return packaged
    return os.path.normpath(os.path.join(here, "..", "..", "core", "data", "defaults.json"))


with open(defaults_file()) as _f:
    _DEFAULTS = json.load(_f)

RENDER = _DEFAULTS["render"]           # samples, max_bounces, seed, pixel_filter, spectral_mode, bands
ILLUMINANTS = _DEFAULTS["illuminants"]  # the CIE illuminants by name ("D" at any CCT is the format's own)


def band_range(bands=None):
    """(lo, hi, width) in nm of a lo:hi:width band plan, the default one unless given."""
    lo, hi, width = (float(v) for v in (bands or RENDER["bands"]).split(":"))
    return lo, hi, width
