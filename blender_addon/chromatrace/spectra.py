# SPDX-License-Identifier: GPL-3.0-or-later
"""Spectrum sources as the scene format writes them (pure Python, no bpy): building the JSON source object
from the add-on's settings, and reading one back into settings. The spectra themselves (CSV columns,
illuminants, blackbodies, RGB upsampling) are evaluated only by the `chromatrace` command.
"""

import csv
import os

from . import defaults
from .floats import short_float

ILLUMINANTS = defaults.ILLUMINANTS + ["D"]


def library_directory():
    """The project's spectra library: data/spectra inside the add-on when it is installed as an extension
    (blender_addon/build_extension.py puts scenes/spectra there); otherwise scenes/spectra beside the add-on, in
    the source tree and once installed (<prefix>/share/chromatrace/{blender_addon,scenes})."""
    here = os.path.dirname(os.path.realpath(__file__))  # through a symlink in Blender's add-ons folder
    packaged = os.path.join(here, "data", "spectra")
    if os.path.isdir(packaged):
        return packaged
    return os.path.normpath(os.path.join(here, "..", "..", "scenes", "spectra"))


def library_entries(directory=None):
    """'file.csv:column' for every value column of every CSV in the library."""
    directory = directory or library_directory()
    entries = []
    if not os.path.isdir(directory):
        return entries
    for name in sorted(os.listdir(directory)):
        if not name.endswith(".csv"):
            continue
        with open(os.path.join(directory, name), newline="") as f:
            header = next(csv.reader(f), [])
        entries += [f"{name}:{column}" for column in header[1:]]
    return entries


class SourceError(ValueError):
    pass


def source_json(kind, values, current_rgb=None, base_dir=None):
    """The scene-format source object (or spectrum name) for a kind and its values.

    values: dict with the settings the kind uses (name, library, constant, csv_path, csv_column, extend, rgb,
    use_current_colour, illuminant, cct_k, blackbody_k, samples). current_rgb: the colour the spectrum
    replaces, for RGB upsampling of the current colour. Relative CSV paths are made relative to base_dir.
    """
    if kind == "NAMED":
        return values["name"]
    if kind == "CONSTANT":
        return {"constant": short_float(values["constant"])}
    if kind == "LIBRARY":
        file, _, column = values["library"].partition(":")
        if not file or not column:
            raise SourceError(f"library spectrum \"{values['library']}\" is not file.csv:column")
        return {"csv": _path(os.path.join(library_directory(), file), base_dir), "column": column}
    if kind == "CSV":
        if not values.get("csv_path"):
            raise SourceError("no CSV file chosen")
        source = {"csv": _path(values["csv_path"], base_dir)}
        if values.get("csv_column"):
            source["column"] = values["csv_column"]
        if values.get("extend") == "clamp":
            source["extend"] = "clamp"
        return source
    if kind == "RGB":
        rgb = current_rgb if values.get("use_current_colour") and current_rgb is not None else values["rgb"]
        return {"rgb": [short_float(c) for c in rgb]}
    if kind == "ILLUMINANT":
        source = {"illuminant": values["illuminant"]}
        if values["illuminant"] == "D":
            source["cct_k"] = short_float(values["cct_k"])
        return source
    if kind == "BLACKBODY":
        return {"blackbody_k": short_float(values["blackbody_k"])}
    if kind == "TEXTURE":
        if not values.get("texture_path"):
            raise SourceError("no image file chosen")
        source = {"texture": _path(values["texture_path"], base_dir)}
        if values.get("texture_colour_space", "auto") != "auto":
            source["colour_space"] = values["texture_colour_space"]
        if values.get("texture_scale", 1.0) != 1.0:
            source["scale"] = short_float(values["texture_scale"])
        return source
    if kind == "SAMPLES":
        source = {"samples": [[float(a), float(b)] for a, b in values["samples"]]}
        if values.get("extend") == "clamp":
            source["extend"] = "clamp"
        return source
    raise SourceError(f"unknown spectrum kind {kind}")


def source_values(source, scene_dir):
    """(kind, values) from a scene-format source object or name: the inverse of source_json."""
    if isinstance(source, str):
        return "NAMED", {"name": source}
    if "constant" in source:
        return "CONSTANT", {"constant": source["constant"]}
    if "csv" in source:
        return "CSV", {"csv_path": os.path.normpath(os.path.join(scene_dir, source["csv"])),
                       "csv_column": source.get("column", ""), "extend": source.get("extend", "zero")}
    if "rgb" in source:
        return "RGB", {"rgb": list(source["rgb"]), "use_current_colour": False}
    if "illuminant" in source:
        return "ILLUMINANT", {"illuminant": source["illuminant"], "cct_k": source.get("cct_k", 6504.0)}
    if "blackbody_k" in source:
        return "BLACKBODY", {"blackbody_k": source["blackbody_k"]}
    if "texture" in source:
        return "TEXTURE", {"texture_path": os.path.normpath(os.path.join(scene_dir, source["texture"])),
                           "texture_colour_space": source.get("colour_space", "auto"),
                           "texture_scale": source.get("scale", 1.0)}
    if "samples" in source:
        return "SAMPLES", {"samples": [list(s) for s in source["samples"]], "extend": source.get("extend", "zero")}
    raise SourceError(f"unknown spectrum source {source}")


def _path(path, base_dir):
    path = os.path.abspath(path)
    return os.path.relpath(path, base_dir) if base_dir else path


def rgb_for_upsampling(rgb):
    """(rgb scaled into [0, 1], the scale taken out): RGB upsampling gives reflectance shapes, so an emission
    colour above 1 is upsampled from its normalised colour and the factor moves to the strength."""
    peak = max(rgb)
    if peak <= 1.0:
        return [max(0.0, float(c)) for c in rgb], 1.0
    return [max(0.0, float(c)) / peak for c in rgb], float(peak)
