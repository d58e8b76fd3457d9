# SPDX-License-Identifier: GPL-3.0-or-later
"""The open scene planned for a colour-error target with this Blender (planning.py's steps): the scene as a scene
file — the batch's --scene, or the open scene written as Export writes it — and the pilots rendered by this Cycles.
batch.py --plan and the Render panel's Plan button both come here."""

import os
import shutil

from . import cache, planning, scene_export, spectral_render
from .errors import BadInput


def plan_open_scene(scene, tool, target, work, scene_file=None, edge_step=None, reference_spp=None, **request):
    """Planned (planning.py) for `scene`. `request`: the render's Request settings the pilots keep (resolution,
    device, on_mixing_nodes, on_world). BadInput when the scene cannot be planned."""
    approximations = []
    if not scene_file:
        scene_file = os.path.join(work, "scene.json")
        try:
            scene_export.export_scene(scene, scene_file, tool, log=lambda message: None, approximations=approximations)
        except BadInput as e:
            raise BadInput(f"the scene could not be written as a scene file to plan: {e}") from None
    base = spectral_render.Request.from_scene(scene, **{k: v for k, v in request.items() if v is not None})

    def render_pilot(bands_file, seed, output):
        pilot = spectral_render.Request(**vars(base))
        pilot.bands, pilot.bands_file, pilot.samples, pilot.seed = None, bands_file, planning.PILOT_SAMPLES, seed
        pilot.families, pilot.object_ids = set(), True
        pilot.resolution = pilot_resolution(scene, base)
        pilot.output, pilot.cache_root, pilot.keep_cache = output, os.path.join(work, "cache"), False
        pilot.log = lambda message: None
        spectral_render.SpectralRender(scene, pilot, tool).run()

    planned = planning.plan_render(scene_file, target, work, render_pilot, tool, edge_step,
                                   light_tree=uses_light_tree(scene), reference_spp=reference_spp)
    planned.approximations = approximations  # what the plan's scene file holds only approximately: said as notes
    return planned


def uses_light_tree(scene):
    """The scene's Cycles samples lights with its light tree (Blender 3.5 on): the plan then tries it off too."""
    return bool(getattr(scene.cycles, "use_light_tree", False))


def pilot_resolution(scene, request):
    return planning.pilot_resolution(*request.resolution_of(scene))


def keep(planned, cache_root, name):
    """The plan (band file and report) kept in the render cache's plans/ folder under the scene's name, where the
    scene's band plan then points; returns the band file's path."""
    folder = os.path.join(cache_root or cache.default_root(), "plans")
    os.makedirs(folder, exist_ok=True)
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "scene"
    bands_file = os.path.join(folder, f"{safe}.json")
    for source, target in ((planned.bands_file, bands_file),
                           (planned.report_file, os.path.join(folder, f"{safe}.report.json"))):
        shutil.copyfile(source, target + ".partial")
        os.replace(target + ".partial", target)
    return bands_file
