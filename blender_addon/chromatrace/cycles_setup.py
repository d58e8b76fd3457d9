# SPDX-License-Identifier: GPL-3.0-or-later
"""Cycles settings that keep every colour channel linear and unbiased on its own, so that each channel of a
render is an independent estimate of its band (applied through the journal, so they are undone after).

Off: clamping (direct and indirect), Filter Glossy, denoising, adaptive sampling (but in guided band groups when the
band plan asks for it: set_samples), the light threshold,
path guiding, fast GI, simplify, motion blur, Freestyle, compositing and the sequencer. On: both kinds of
caustics. Box pixel filter of width 1 (for the scene format's "point", a Gaussian 0.01 wide), Standard view
transform with look None, exposure 0 and gamma 1, Cycles film exposure 1, 32-bit float multilayer OpenEXR.
The render device is select_device's: the CPU unless asked.
"""

from .errors import BadInput

VIEW_LAYER_PASSES = {
    "Emit": "use_pass_emit", "Env": "use_pass_environment",
    "DiffDir": "use_pass_diffuse_direct", "DiffInd": "use_pass_diffuse_indirect", "DiffCol": "use_pass_diffuse_color",
    "GlossDir": "use_pass_glossy_direct", "GlossInd": "use_pass_glossy_indirect", "GlossCol": "use_pass_glossy_color",
    "TransDir": "use_pass_transmission_direct", "TransInd": "use_pass_transmission_indirect",
    "TransCol": "use_pass_transmission_color",
    "IndexOB": "use_pass_object_index",
}


# Cycles (scene.cycles) and render (scene.render) settings apply() fixes, besides those the request chooses.
CYCLES_SETTINGS = (("use_animated_seed", False), ("use_adaptive_sampling", False), ("use_denoising", False),
                   ("sample_clamp_direct", 0.0), ("sample_clamp_indirect", 0.0), ("blur_glossy", 0.0),
                   ("light_sampling_threshold", 0.0), ("caustics_reflective", True), ("caustics_refractive", True),
                   ("use_layer_samples", "IGNORE"), ("time_limit", 0.0), ("use_guiding", False), ("use_fast_gi", False),
                   ("film_exposure", 1.0), ("sample_offset", 0), ("volume_bounces", 0))
RENDER_SETTINGS = (("film_transparent", False), ("use_motion_blur", False), ("use_compositing", False),
                   ("use_sequencer", False), ("use_freestyle", False), ("use_simplify", False), ("use_border", False),
                   ("use_file_extension", False), ("use_persistent_data", True), ("pixel_aspect_x", 1.0),
                   ("pixel_aspect_y", 1.0), ("resolution_percentage", 100), ("use_single_layer", False),
                   ("use_multiview", False))
BOUNCES = ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces")
# Every scene.cycles and scene.render setting a render sets, whatever the scene held: the cache key leaves them out.
FIXED = {"cycles": {a for a, _v in CYCLES_SETTINGS} | set(BOUNCES) | {"device", "samples", "seed", "pixel_filter_type",
                                                                       "filter_width", "adaptive_min_samples",
                                                                       "adaptive_threshold"},
         "render": {a for a, _v in RENDER_SETTINGS} | {"engine", "resolution_x", "resolution_y", "filepath"}}


def _set_if(journal, target, attribute, value):
    if target is not None and hasattr(target, attribute):
        journal.set(target, attribute, value)


def pixel_filter(point):
    """Cycles' pixel filter: a box over the pixel, or (point) a Gaussian 0.01 pixels wide, the narrowest Cycles
    allows: every sample at the pixel's centre. Cycles ignores the width of its Box filter (always one pixel),
    so a point cannot be a narrow box."""
    return (("pixel_filter_type", "GAUSSIAN"), ("filter_width", 0.01)) if point else (("pixel_filter_type", "BOX"),
                                                                                      ("filter_width", 1.0))


def select_device(journal, scene, cycles_preferences, device):
    """Cycles' render device: "CPU", or every device of one GPU backend ("CUDA", "OPTIX", "HIP", "ONEAPI",
    "METAL") that this Blender finds, set through the journal (the preferences too, so they are put back).
    Returns what renders, for the output's header ("CPU", "CUDA: NVIDIA ..."); a backend this Blender was not
    built with or finds no device of is refused by name."""
    if device == "CPU":
        journal.set(scene.cycles, "device", "CPU")
        return "CPU"
    try:  # the backends are a dynamic enum: only setting one says whether this build has it
        journal.set(cycles_preferences, "compute_device_type", device)
    except TypeError:
        raise BadInput(f"--device: {device}: this Blender's Cycles has no {device} backend") from None
    cycles_preferences.refresh_devices()
    gpus = [d for d in cycles_preferences.devices if d.type == device]
    if not gpus:
        raise BadInput(f"--device: {device}: Cycles finds no {device} device on this machine")
    for d in cycles_preferences.devices:
        journal.set(d, "use", d.type == device)
    journal.set(scene.cycles, "device", "GPU")
    return f"{device}: {', '.join(d.name for d in gpus)}"


def multilayer_exr(image_settings):
    """The settings that make a render write a multilayer OpenEXR with every pass in one part: a format among the
    others up to Blender 4.x; from 5.0 the one format of the multilayer media type (chosen first), which writes
    a part per pass unless interleaved (`chromatrace assemble` reads one part)."""
    media = [("media_type", "MULTI_LAYER_IMAGE")] if hasattr(image_settings, "media_type") else []
    interleave = [("use_exr_interleave", True)] if hasattr(image_settings, "use_exr_interleave") else []
    return media + [("file_format", "OPEN_EXR_MULTILAYER")] + interleave


def apply(journal, scene, view_layer, samples, seed, point_filter, resolution, passes):
    render = scene.render
    journal.set(render, "engine", "CYCLES")
    c = scene.cycles
    journal.set(c, "samples", samples)
    journal.set(c, "seed", seed)
    for attribute, value in (*CYCLES_SETTINGS, *pixel_filter(point_filter)):
        _set_if(journal, c, attribute, value)
    for attribute, value in RENDER_SETTINGS:
        _set_if(journal, render, attribute, value)
    if resolution is not None:
        journal.set(render, "resolution_x", resolution[0])
        journal.set(render, "resolution_y", resolution[1])

    image = render.image_settings
    # The valid bit depths depend on the format: set (and restore) the format first.
    journal.set_together(image, multilayer_exr(image) + [("color_depth", "32"), ("exr_codec", "ZIP")]
                         + [(a, v) for a, v in (("use_preview", False), ("color_management", "FOLLOW_SCENE"))
                            if hasattr(image, a)])

    view = scene.view_settings
    journal.set(scene.display_settings, "display_device", "sRGB")
    journal.set(view, "view_transform", "Standard")
    journal.set(view, "look", "None")
    journal.set(view, "exposure", 0.0)
    journal.set(view, "gamma", 1.0)
    journal.set(view, "use_curve_mapping", False)

    for layer in scene.view_layers:
        journal.set(layer, "use", layer == view_layer)
    journal.set(view_layer, "use_pass_combined", True)
    for name, attribute in VIEW_LAYER_PASSES.items():
        if name in passes:
            journal.set(view_layer, attribute, True)
    _set_if(journal, view_layer, "samples", 0)
    _set_if(journal, getattr(view_layer, "cycles", None), "denoising_store_passes", False)


def set_light_tree(journal, scene, on):
    """Cycles' light tree on or off, as the band plan asks (its cycles_light_tree: planning.py turns it off where the
    pilots found the scene less noisy without it). A Blender before 3.5 has none: off is what it does anyway."""
    if hasattr(scene.cycles, "use_light_tree"):
        journal.set(scene.cycles, "use_light_tree", bool(on))
    elif on:
        raise BadInput("cycles_light_tree: the band plan asks for Cycles' light tree, which this Blender "
                       "(before 3.5) does not have")


def set_samples(journal, scene, samples, adaptive=None):
    """One band group's samples per pixel. With `adaptive` (threshold, most samples: bands.guided_adaptive), Cycles'
    adaptive sampling: every pixel gets `samples`, and one whose noise stays above the threshold up to the most;
    without, adaptive sampling stays off and every pixel gets `samples`."""
    c = scene.cycles
    journal.set(c, "use_adaptive_sampling", adaptive is not None)
    if adaptive is None:
        journal.set(c, "samples", samples)
        return
    threshold, most = adaptive
    journal.set(c, "samples", max(most, samples))
    journal.set(c, "adaptive_min_samples", samples)
    journal.set(c, "adaptive_threshold", threshold)


# The world importance map's resolution (its width; the map is width × width / 2 cells) for a band group, where
# Cycles' automatic choice would build one of 4096 × 2048 for any world without a single sun: the environment
# image's width, no less than WORLD_MAP_MIN. Cycles shades every cell once per render, and each band group is a
# render with its own world image, so the map is built again for each (1.4 s of CPU at 4096 on the textured test
# scene, most of a band group at 96 × 96); at 1024 it is a sixteenth of that, and the render as noisy (docs/plan.md).
WORLD_MAP_MIN, WORLD_MAP_MAX = 1024, 4096


def world_map_resolution(sampling_method, image_widths):
    """The world's MANUAL map resolution for a band group, or None to leave the world's sampling as it is: when its
    sampling is AUTOMATIC and it is an environment image (or several) of these widths."""
    widths = [w for w in image_widths if w > 0]
    if sampling_method != "AUTOMATIC" or not widths:
        return None
    return min(WORLD_MAP_MAX, max(WORLD_MAP_MIN, max(widths)))


def set_id_render(journal, scene, view_layer):
    """Settings of the object-id render, after apply(): one sample per pixel through the point filter (at the
    pixel's centre, where the reference tracer takes a pixel's id), the Object Index pass on."""
    journal.set(scene.cycles, "use_adaptive_sampling", False)
    journal.set(scene.cycles, "samples", 1)
    for attribute, value in pixel_filter(point=True):
        journal.set(scene.cycles, attribute, value)
    journal.set(view_layer, VIEW_LAYER_PASSES["IndexOB"], True)
    set_bounces(journal, scene, 0)


def set_bounces(journal, scene, cycles_max_bounces):
    c = scene.cycles
    for attribute in BOUNCES:
        journal.set(c, attribute, cycles_max_bounces)
