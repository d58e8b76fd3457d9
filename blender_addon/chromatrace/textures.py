# SPDX-License-Identifier: GPL-3.0-or-later
"""Image textures in a spectral render: each texture's per-band-group images (`chromatrace prepare-texture`,
cached by content in <cache root>/textures), loaded into Blender for the renders; and the pre-flight's look at a
texture's capture noise."""

import json
import os
import time

import bpy

from . import cache
from .errors import BadInput


def texture_file(texture, work_dir):
    """The file of a texture source; an image packed into the .blend is written out into work_dir first."""
    if not texture.startswith("packed:"):
        return texture
    image = bpy.data.images[texture[len("packed:"):]]
    name = os.path.basename(image.filepath) or f"{image.name}.png"
    path = os.path.join(work_dir, f"packed-{len(os.listdir(work_dir))}-{name}")
    with open(path, "wb") as f:
        f.write(image.packed_file.data)
    return path


def prepare_textures(tool, request, work_dir, inputs, texture_sources, edges, per_render, replicate):
    """Every image texture's per-band-group images: {key: prepare-texture's --json summary}."""
    textures = {}
    wanted = {key: (spectral_input, owner) for spectral_input, key, _scale, owner in inputs if key in texture_sources}
    if not wanted:
        return textures
    bands_file = os.path.join(work_dir, "bands.json")
    with open(bands_file, "w") as f:
        json.dump({"format": "chromatrace-bands/1", "edges_nm": edges}, f)
    directory = os.path.join(request.cache_root or cache.default_root(), "textures")
    os.makedirs(directory, exist_ok=True)
    for key, (spectral_input, owner) in wanted.items():
        source = texture_sources[key]
        kind = "radiance" if spectral_input.role == "emission" else "reflectance"
        scale = source.get("scale", 1.0)
        if kind == "reflectance" and scale > 1.0:
            raise BadInput(f"{owner}: the texture of {spectral_input.label} has scale {scale:g}, but a "
                           "reflectance's scale must be in [0, 1]")
        image = texture_file(source["texture"], work_dir)
        start = time.monotonic()
        textures[key] = tool.prepare_texture(image, kind, source.get("colour_space", "auto"), bands_file,
                                             per_render, replicate, scale, directory)
        summary = textures[key]
        request.log(f"texture {source['texture']} ({summary['width']}x{summary['height']}, "
                    f"{summary['distinct_colours']} colours, {kind}): "
                    f"{'cached' if summary['cached'] else f'{time.monotonic() - start:.1f} s'}")
    return textures


def load_textures(journal, plan, max_bounces):
    """The prepared images as Blender images (raw data: no colour transform), removed again on restore; a
    black image stands in for reflectance textures when only emitters are shown (`max_bounces` 0)."""
    for key, summary in plan.textures.items():
        images = []
        for group in summary["groups"]:
            image = bpy.data.images.load(group["file"], check_existing=False)
            image.colorspace_settings.name = "Non-Color"
            journal.call_on_restore(lambda image=image: bpy.data.images.remove(image))
            images.append(image)
        plan.texture_images[key] = images
    if plan.textures and max_bounces == 0:
        black = bpy.data.images.new("chromatrace black", 1, 1, alpha=False, float_buffer=True)
        black.pixels[:] = (0.0, 0.0, 0.0, 1.0)
        journal.call_on_restore(lambda: bpy.data.images.remove(black))
        plan.texture_images[None] = [black]


def texture_noise(tool, source, role):
    """The capture noise an image texture's file has, as the render will zero it ({"zeroed", "largest",
    "threshold"}); None for an image packed into the .blend (judged when the render writes it out)."""
    path = source["texture"]
    if path.startswith("packed:"):
        return None
    kind = "reflectance" if role == "reflectance" else "radiance"
    space = {"sRGB": "sRGB", "linear": "linear"}.get(source.get("colour_space"), "auto")
    return tool.check_texture(path, kind, space)["negative_texels"]
