# SPDX-License-Identifier: GPL-3.0-or-later
"""Band multiplexing: which bands share a Cycles render, and what goes into each colour channel.

Pure Python (no bpy). Band edges and band averages come from the `chromatrace` command (core/spectrum.h);
this module only decides how the bands are packed into renders.
"""

import json

CHANNELS = ("R", "G", "B")


def band_groups(band_count, per_render=3):
    """The renders' groups of band indices, `per_render` (1 to 3) to a render, interleaved so that each render spans
    the spectrum: render g of G = ceil(band_count / per_render) holds bands g, g + G, g + 2G (7 bands -> [0,3,6],
    [1,4], [2,5]), as `chromatrace` groups them (core/band_plan.h, cycles_render_groups). Cycles picks a Principled
    BSDF's lobe with a probability that follows its colour averaged over the render's channels: renders of
    neighbouring bands would pick differently, their paths part and their noise adds up as chroma."""
    if not 1 <= per_render <= len(CHANNELS):
        raise ValueError(f"per_render must be 1 to {len(CHANNELS)}, got {per_render}")
    if band_count < 1:
        raise ValueError(f"band_count must be at least 1, got {band_count}")
    renders = -(-band_count // per_render)
    return [list(range(g, band_count, renders)) for g in range(renders)]


def plan_group_of(band_count, band):
    """The band plan's group (of three: band_groups(band_count)) that holds `band`, whose `cycles_samples` and
    `cycles_guided_groups` entry are its."""
    return band % -(-band_count // len(CHANNELS))


def planned_samples(bands_file):
    """The Cycles samples per band group a band-plan file gives (its "cycles_samples"), or None when it gives none or
    cannot be read; whether the rest of the file is sound, `chromatrace` says when it reads it."""
    try:
        with open(bands_file) as f:
            samples = json.load(f).get("cycles_samples")
    except (OSError, ValueError, AttributeError):
        return None
    return samples if isinstance(samples, list) and samples else None


def group_samples(groups, cycles_samples, samples):
    """Cycles' samples per pixel for each render of `groups`: the band plan's `cycles_samples` (one per band group
    of three, plan_group_of) where it gives them, the most any of a render's bands asks for; else `samples`."""
    if not cycles_samples:
        return [samples] * len(groups)
    count = sum(len(group) for group in groups)
    return [max(cycles_samples[plan_group_of(count, b)] for b in group) for group in groups]


def guided_bands(band_count, guided_groups):
    """The bands of the band plan's `cycles_guided_groups` (groups of three, plan_group_of): rendered with few
    samples and reconstructed from the others when assembled."""
    groups = set(guided_groups or [])
    return [b for b in range(band_count) if plan_group_of(band_count, b) in groups]


def guided_adaptive(groups, cycles_samples, guided_groups, threshold):
    """Cycles' adaptive sampling for each render of `groups`: None, or (threshold, most samples) for a render of
    guided bands when the band plan gives their `cycles_guided_threshold`. Such a render gives every pixel its own
    samples and, where a pixel's noise stays above the threshold (objects' edges and highlights, which the
    reconstruction leaves at their own samples), up to the most samples a guiding group has."""
    guided = set(guided_groups or [])
    if not threshold or not guided or not cycles_samples:
        return [None] * len(groups)
    most = max(s for g, s in enumerate(cycles_samples) if g not in guided)
    count = sum(len(group) for group in groups)
    return [(threshold, most) if all(plan_group_of(count, b) in guided for b in group) else None for group in groups]


def channel_of(group, band):
    """The colour channel ("R", "G" or "B") that carries `band` in the render of `group`."""
    return CHANNELS[group.index(band)]


def group_colour(band_values, group, replicate=False):
    """The RGB triple a colour input gets in the render of `group`, from its per-band values.

    Bands fill R, G, B in order; channels without a band get 0. With `replicate` (one band per render,
    the fallback for node trees that mix channels) the single band fills all three channels, so such
    nodes see a grey input and act on it as on a monochrome scene; only R is read back.
    """
    if replicate:
        if len(group) != 1:
            raise ValueError("replicating needs one band per render")
        v = band_values[group[0]]
        return (v, v, v)
    values = [band_values[b] for b in group]
    return tuple(values + [0.0] * (len(CHANNELS) - len(values)))


def describe_band_range(edges_nm, group):
    """'400-450, 500-550 nm' for the bands of a group (adjacent ones joined), for progress messages."""
    spans = []
    for b in group:
        if spans and spans[-1][1] == edges_nm[b]:
            spans[-1][1] = edges_nm[b + 1]
        else:
            spans.append([edges_nm[b], edges_nm[b + 1]])
    return ", ".join(f"{lo:g}-{hi:g}" for lo, hi in spans) + " nm"
