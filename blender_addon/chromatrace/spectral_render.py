# SPDX-License-Identifier: GPL-3.0-or-later
"""The spectral render: Cycles renders three bands at a time, chromatrace assembles the spectral EXR.

    render = SpectralRender(scene, Request.from_scene(scene, output="out.exr"), Tool(executable))
    for done, total, message in render.steps():   # one step per Cycles render; render.run() does them all
        ...

What it guarantees:
- Everything it changes (colours, Cycles and colour-management settings, passes, light groups, object
  indices, the world's strength) goes through a Journal and is put back in a `finally`, whether the render
  succeeds, fails or is cancelled (closing the generator). It never saves the .blend.
- Each finished Cycles render is read back (to the end of its pixel data, at the render's size, with the channels
  assemble takes from it: with Blender's own OpenImageIO in this process where it imports, else `chromatrace info`) and only then moved into a cache directory keyed by a hash of
  everything that decides its pixels (cache.py); one that does not read (a full disk) fails the run and is
  removed. A run that was killed resumes with the renders still missing; a cached render that does not read
  back is rendered again, with a warning. The final EXR is written atomically by `chromatrace assemble`.
"""

import json
import os
import shutil
import tempfile
import time

import bpy

from . import blender_compat, cache, components, cycles_setup, manifest, materials, node_resolution, node_rules
from . import readback, render_setup, scene_parts
from .bands import band_groups, describe_band_range, group_samples, guided_adaptive, guided_bands
from .cache_description import cache_description
from .camera_math import camera_description
from .errors import BadInput
from .journal import Journal
from .preflight import preflight
from .render_request import RenderPlan, Request  # noqa: F401 (Request: the add-on's callers take it from here)
from .textures import prepare_textures

# Tests set this to a callable f(event, **info); an exception it raises aborts the render at that point.
TEST_HOOK = None


class SpectralRender:
    def __init__(self, scene, request, tool):
        self.scene = scene
        self.request = request
        self.tool = tool
        self.rendered = 0  # Cycles renders made by this run (not found in the cache)
        self.cached = 0
        self.cache_dir = None
        self.preview = None  # the picture a person would see, written beside the output when the render ends

    def run(self):
        for _ in self.steps():
            pass

    def preflight(self):
        """What a render would do, without rendering or changing anything (batch.py --explain; preflight.py)."""
        return preflight(self.scene, self.request, self.tool)

    def _resolution(self):
        return self.request.resolution_of(self.scene)

    def _prepare(self, work_dir):
        """The plan of the renders: what is rendered, with which band values, into which components."""
        scene, request = self.scene, self.request
        view_layer, objects, used, lights = scene_parts.scene_parts(scene)
        walks = node_resolution.walks(scene, used, lights)
        world = node_resolution.world_state(scene, walks, request.on_world)
        mixing = node_resolution.check_nodes(request, used, walks, world)
        replicate = bool(mixing)
        keys, inputs, emitters, texture_sources = node_resolution.spectral_inputs(scene, used, lights, walks, world)
        bands = node_resolution.band_averages(self.tool, request, work_dir, keys, inputs, texture_sources)
        edges = bands["bands"]["edges_nm"]
        per_render = 1 if replicate else request.bands_per_render
        if replicate:
            count = len(edges) - 1
            request.log(f"warning: one band per render, {count} Cycles renders of the bands instead of "
                        f"{len(band_groups(count, request.bands_per_render))}, because nodes mix colour channels: "
                        f"{node_rules.summarise(mixing)}; each band is rendered alone as a grey (in R, G and B), so "
                        "these nodes act on its value only (a change of hue or saturation does nothing to a grey); "
                        "nodes that act on each channel alike (Mix, Gamma, Invert, Bright/Contrast) keep three bands "
                        "per render")
        textures = prepare_textures(self.tool, request, work_dir, inputs, texture_sources, edges, per_render, replicate)
        transmission = any(materials.has_transmission(walks[("material", m.name)]) for m in used)
        light_groups, assignments, world_group = scene_parts.light_groups(scene, request.families, view_layer,
                                                                          objects, emitters, world)
        total, planned = components.component_plan(request.families, light_groups, request.max_bounces, transmission,
                                                    environment=world["status"] == "lit")
        groups = band_groups(len(edges) - 1, per_render)
        plan = RenderPlan(view_layer=view_layer, objects=objects, materials=used, inputs=inputs, bands=bands, edges=edges,
                          groups=groups, replicate=replicate, per_render=per_render,
                          samples=group_samples(groups, bands["bands"].get("cycles_samples"), request.samples),
                          planned_samples=bool(bands["bands"].get("cycles_samples")),
                          adaptive=guided_adaptive(groups, bands["bands"].get("cycles_samples"),
                                                   bands["bands"].get("cycles_guided_groups"),
                                                   bands["bands"].get("cycles_guided_threshold")),
                          light_tree=bands["bands"].get("cycles_light_tree"),
                          light_groups=light_groups, assignments=assignments, total=total, components=planned,
                          variants=components.render_variants(request.max_bounces, "bounces" in request.families),
                          passes=components.passes_needed(planned),
                          ids=scene_parts.object_ids(objects, request.object_ids),
                          world=world, world_group=world_group, lights=lights, replaced={}, textures=textures,
                          texture_images={})
        plan.key = cache.cache_key(cache_description(scene, request, plan, self._resolution()))
        return plan

    def steps(self):
        """Generator: yields (renders done, renders in all, message) after each Cycles render."""
        request = self.request
        if not request.output:
            raise BadInput("output: no file name")
        out_dir = os.path.dirname(os.path.abspath(request.output))
        if not os.path.isdir(out_dir):
            raise BadInput(f"output: {request.output}: directory {out_dir} does not exist")
        journal = Journal()
        work_dir = tempfile.mkdtemp(prefix="chromatrace-")
        try:
            plan = self._prepare(work_dir)
            self.cache_dir = cache.cache_directory(request.cache_root, plan.key)
            groups, variants = plan.groups, plan.variants
            total = len(groups) * len(variants) + (1 if request.object_ids else 0)
            request.log(f"{len(plan.edges) - 1} bands in {len(groups)} renders of {plan.per_render} band(s)"
                        f"{' x ' + str(len(variants)) + ' bounce limits' if len(variants) > 1 else ''}; "
                        f"cache {self.cache_dir}")
            wanted = manifest.channels_by_file(self._manifest(plan))
            todo = set(manifest.missing_renders(self.cache_dir, groups, list(variants)))
            only = request.only_group
            if only is not None:
                if only >= len(groups):
                    raise BadInput(f"--band-group: must be in [0, {len(groups) - 1}] for {len(groups)} band groups, "
                                   f"got {only}")
                total = len(variants)
                if request.only_variant is not None:
                    if request.only_variant not in variants:
                        raise BadInput(f"--bounce-limit: must be one of {', '.join(variants)}, got "
                                       f"\"{request.only_variant}\"")
                    total = 1
            self._drop_unreadable(plan, wanted, todo)
            applied = False
            done = 0
            for g, group in enumerate(groups):
                if only is not None and g != only:
                    continue
                colours_set = False
                for variant, cycles_bounces in variants.items():
                    if request.only_variant is not None and variant != request.only_variant:
                        continue
                    final = os.path.join(self.cache_dir, manifest.render_file_name(g, variant))
                    if (g, variant) not in todo:
                        self.cached += 1
                        done += 1
                        request.log(f"render {done}/{total} ({describe_band_range(plan.edges, group)}, {variant}): "
                                    "already in the cache")
                        yield done, total, "cached"
                        continue
                    if not applied:
                        render_setup.apply_settings(journal, self.scene, request, plan, self._resolution())
                        applied = True
                    if not colours_set:
                        render_setup.set_colours(journal, plan, group, request.max_bounces)
                        colours_set = True
                    cycles_setup.set_bounces(journal, self.scene, cycles_bounces)
                    cycles_setup.set_samples(journal, self.scene, plan.samples[g], plan.adaptive[g])
                    if TEST_HOOK is not None:
                        TEST_HOOK("before_render", group=g, variant=variant, rendered=self.rendered)
                    took = self._render_into_cache(journal, final, wanted.get(os.path.basename(final), set()),
                                                   f"render {done + 1}")
                    done += 1
                    message = (f"render {done}/{total} ({describe_band_range(plan.edges, group)}, {variant}"
                               f"{f', {plan.samples[g]} samples' if plan.planned_samples else ''}): {took}")
                    request.log(message)
                    yield done, total, message
            if only is not None:
                request.log(f"band group {only} of {len(groups)}"
                            f"{'' if request.only_variant is None else ' (' + request.only_variant + ')'} is in the cache "
                            f"{self.cache_dir}")
                return
            if request.object_ids:
                ids_file = os.path.join(self.cache_dir, manifest.IDS_FILE)
                if os.path.isfile(ids_file):
                    self.cached += 1
                    done += 1
                    request.log(f"render {done}/{total} (object ids): already in the cache")
                    yield done, total, "cached"
                else:
                    if not applied:
                        render_setup.apply_settings(journal, self.scene, request, plan, self._resolution())
                        applied = True
                    message = self._render_ids(journal, plan, ids_file, wanted.get(manifest.IDS_FILE, set()))
                    done += 1
                    request.log(f"render {done}/{total} (object ids): {message}")
                    yield done, total, message
            journal.restore()
            self._assemble(plan)
            self._write_preview()
            if not request.keep_cache:
                cache.remove(self.cache_dir)
        finally:
            journal.restore()
            shutil.rmtree(work_dir, ignore_errors=True)

    def _render_ids(self, journal, plan, final, channels):
        """The object-id render: one sample per pixel, at the pixel's centre."""
        cycles_setup.set_id_render(journal, self.scene, plan.view_layer)
        return self._render_into_cache(journal, final, channels, "the object-id render")

    def _render_into_cache(self, journal, final, channels, what):
        """One Cycles render as it is set up, into `final` in the cache once it reads back with `channels`;
        returns the time it took, in words."""
        temporary = final + ".partial"
        journal.set(self.scene.render, "filepath", temporary)
        start, start_cpu = time.monotonic(), time.process_time()
        bpy.ops.render.render(write_still=True, scene=self.scene.name)
        if not os.path.isfile(temporary):
            raise RuntimeError(f"Cycles wrote no file for {what} ({temporary})")
        cache.commit(temporary, final, lambda path: self._unreadable(path, channels))
        self.rendered += 1
        return f"{time.monotonic() - start:.2f} s, {time.process_time() - start_cpu:.2f} s CPU"

    def _unreadable(self, path, channels):
        """Why a Cycles render file cannot be assembled, or None: it must read to the end of its pixel data, be of
        the render's size and hold `channels`."""
        info = readback.read_back(path)  # in this process, with Blender's own OpenImageIO, where it imports
        if isinstance(info, str):
            return info
        if info is None:
            try:
                info = self.tool.image_info(path)
            except (BadInput, RuntimeError) as e:
                return str(e)
        size = [info["width"], info["height"]]
        if size != self._resolution():
            return f"{path}: {size[0]}x{size[1]} pixels, not the render's {'x'.join(map(str, self._resolution()))}"
        missing = sorted(set(channels) - {c["name"] for c in info["channels"]})
        if missing:
            return f"{path}: no channel {', '.join(missing)}"
        return None

    def _drop_unreadable(self, plan, wanted, todo):
        """Adds to `todo` (and removes from the cache) every cached render that does not read back."""
        cached = [(g, v) for g in range(len(plan.groups)) for v in plan.variants if (g, v) not in todo]
        files = [(manifest.render_file_name(g, v), (g, v)) for g, v in cached]
        if self.request.object_ids:
            files.append((manifest.IDS_FILE, None))
        for name, entry in files:
            path = os.path.join(self.cache_dir, name)
            if not os.path.isfile(path):
                continue
            problem = self._unreadable(path, wanted.get(name, set()))
            if problem is None:
                continue
            self.request.log(f"warning: {name} in the cache does not read back, so it is rendered again: {problem}")
            cache.discard(path)
            if entry is not None:
                todo.add(entry)

    def _manifest(self, plan, attributes=None):
        """The `chromatrace-assemble/1` document of the plan's renders."""
        names = None
        if self.request.object_ids:
            names = {}
            for ob in plan.objects:
                if ob.name in plan.ids:
                    names[plan.ids[ob.name]] = ob.chromatrace.scene_name or ob.name
        return manifest.build_manifest(
            plan.edges, plan.groups, list(plan.variants), plan.view_layer.name, plan.total,
            plan.components, object_names=names, attributes=attributes, replicate=plan.replicate,
            reconstruction=plan.bands["bands"].get("reconstruction"), pass_names=blender_compat.pass_names(),
            guided_bands=guided_bands(len(plan.edges) - 1, plan.bands["bands"].get("cycles_guided_groups")),
            guided_adaptive=next((a for a in plan.adaptive if a), None))

    def _assemble(self, plan):
        request = self.request
        manifest_file = os.path.join(self.cache_dir, "manifest.json")
        cache.write_json(manifest_file, self._manifest(plan, self._attributes(plan)))
        self.tool.assemble(manifest_file, os.path.abspath(request.output))
        request.log(f"wrote {request.output} ({self.rendered} renders made, {self.cached} from the cache)")

    def _write_preview(self):
        """OUT.preview.png beside OUT.exr: the display rendering of a camera (tool.preview), so that a person sees
        the scene as photographed, not the raw integral of radiance with the CIE observer. A failure is said, and
        leaves the spectral file as it is."""
        output = os.path.abspath(self.request.output)
        preview = os.path.splitext(output)[0] + ".preview.png"
        try:
            self.tool.preview(output, preview)
        except (BadInput, RuntimeError) as e:
            self.request.log(f"warning: no preview: {e}")
            return
        self.preview = preview
        self.request.log(f"preview {preview}")

    def _attributes(self, plan):
        scene, request = self.scene, self.request
        s = scene.chromatrace
        source = s.source_json or json.dumps({"blend": bpy.data.filepath, "scene": scene.name})
        attributes = {}
        if plan.world["status"] == "omitted":
            attributes["chromatrace.warning"] = node_resolution.world_warning(plan.world)
        if request.plan_header:
            attributes["chromatrace.plan"] = request.plan_header
        if s.source_json and s.source_file:  # where the scene's relative paths resolve (compare's white reads them)
            attributes["chromatrace.scene_directory"] = os.path.dirname(os.path.abspath(bpy.path.abspath(s.source_file)))
        return attributes | {
            "chromatrace.renderer": (f"Cycles (Blender {bpy.app.version_string}) via the chromatrace add-on: "
                                     f"{plan.per_render} band(s) per render, max {request.max_bounces} bounces, "
                                     + ("" if plan.light_tree is None else
                                        f"light tree {'on' if plan.light_tree else 'off'} (the band plan's), ")
                                     + f"on {request.device}"),
            "chromatrace.device": getattr(plan, "device", request.device),
            # One number, or one per band group where the band plan gives each group its own (docs/spectral-exr.md).
            "chromatrace.samples": ",".join(map(str, plan.samples)) if len(set(plan.samples)) > 1 else str(plan.samples[0]),
            "chromatrace.seed": str(request.seed),
            "chromatrace.scene": source,
            # Blender's colours (RGB lights, worlds, HDRIs, Blackbody nodes) are relative to D65: the preview's white.
            "chromatrace.white": "D65",
            "chromatrace.camera": json.dumps(camera_description(scene, self._resolution())),
        }
