# SPDX-License-Identifier: GPL-3.0-or-later
"""What a spectral render is asked to do (Request: the scene's chromatrace settings, batch.py's options over
them) and what it decided to do (RenderPlan)."""

import sys

import bpy

from . import defaults


def _stderr_log(message):
    print(f"chromatrace: {message}", file=sys.stderr, flush=True)


class RenderPlan:
    """What SpectralRender._prepare decided: the objects and materials rendered, their spectral inputs and band
    averages, the band groups, light groups, components, render variants, passes and object ids, and the cache
    key."""

    def __init__(self, **fields):
        self.key = None
        self.__dict__.update(fields)


class Request:
    """What to render: the scene's chromatrace settings, optionally overridden (batch.py's options)."""

    def __init__(self, **values):
        self.samples = defaults.RENDER["samples"]
        self.max_bounces = defaults.RENDER["max_bounces"]
        self.seed = defaults.RENDER["seed"]
        self.bands = defaults.RENDER["bands"]
        self.bands_file = None
        self.families = {"paths", "lights"}
        self.object_ids = True
        self.resolution = None
        self.point_filter = False
        self.on_mixing_nodes = "refuse"  # or "one-band"
        self.on_world = "refuse"  # a lit world whose colours cannot be spectra (an HDRI): or "omit"
        self.bands_per_render = 3
        self.device = "CPU"  # Cycles' device: CPU, or a GPU backend (cycles_setup.select_device)
        self.output = None
        self.cache_root = None
        self.keep_cache = False
        self.only_group = None  # render only this band group into the cache, no ids, no assembly (batch --band-group)
        self.only_variant = None  # with only_group: only this render variant (bounce limit) of it (--bounce-limit)
        self.plan_header = None  # batch --plan: what the output's header keeps of the plan (chromatrace.plan)
        self.log = _stderr_log
        for key, value in values.items():
            if not hasattr(self, key):
                raise TypeError(f"unknown request setting {key}")
            setattr(self, key, value)

    @classmethod
    def from_scene(cls, scene, **overrides):
        s = scene.chromatrace
        values = dict(samples=s.samples, max_bounces=s.max_bounces, seed=s.seed, bands=s.bands_argument(),
                      bands_file=bpy.path.abspath(s.bands_file) if s.band_plan == "FILE" else None,
                      families=s.families(), object_ids=s.use_object_ids, point_filter=s.pixel_filter == "point",
                      on_mixing_nodes="one-band" if s.on_mixing_nodes == "ONE_BAND" else "refuse",
                      on_world="omit" if s.on_world == "OMIT" else "refuse",
                      output=s.output_file(),
                      cache_root=bpy.path.abspath(s.cache_dir) if s.cache_dir else None)
        values.update({k: v for k, v in overrides.items() if v is not None})
        return cls(**values)

    def resolution_of(self, scene):
        """The render's size in pixels: the request's, else the scene's at its percentage."""
        if self.resolution:
            return list(self.resolution)
        r = scene.render
        return [r.resolution_x * r.resolution_percentage // 100, r.resolution_y * r.resolution_percentage // 100]
