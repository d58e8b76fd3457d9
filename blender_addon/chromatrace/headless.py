# SPDX-License-Identifier: GPL-3.0-or-later
"""The headless spectral render: batch.py's arguments (batch_args.py) to a spectral EXR, or to the pre-flight
summary with --explain (batch.py's docstring says what each does). The add-on's one entry for scripts: batch.py
runs it from the source tree or an install, and an add-on installed as an extension runs it as
`bl_ext.<repository>.chromatrace.headless`.

Exit status 0 on success, 1 on a runtime failure, 2 on bad input, with one line on stderr naming the file,
field or option at fault (as the `chromatrace` command). Progress lines go to stderr (--quiet: none).

For tests: CHROMATRACE_TEST_FAIL_AT_RENDER=N raises an exception just before the N-th new Cycles render
(counting from 0), CHROMATRACE_TEST_KILL_AT_RENDER=N kills the process there (SIGKILL);
CHROMATRACE_TEST_CYCLES_SETTINGS="blur_glossy=1,sample_clamp_indirect=10" puts Cycles settings back to other
values before every render (tests/blender/cross_validate.py shows that compare catches the bias of Cycles'
defaults).
"""

import contextlib
import json
import os
import resource
import shutil
import signal
import sys
import time
import traceback

from .batch_args import parse_batch_args
from .errors import BadInput


def script_arguments(argv):
    """The batch's own arguments: those after `--` (Blender's convention), or, in a Python that imported Blender
    as a module, everything after the script's name."""
    if "--" in argv:
        return argv[argv.index("--") + 1:]
    import bpy
    return argv[1:] if getattr(bpy.app, "module", False) else []


def _log(message):
    print(f"chromatrace: {message}", file=sys.stderr, flush=True)


def _test_hook():
    fail_at = os.environ.get("CHROMATRACE_TEST_FAIL_AT_RENDER")
    kill_at = os.environ.get("CHROMATRACE_TEST_KILL_AT_RENDER")
    biased = os.environ.get("CHROMATRACE_TEST_CYCLES_SETTINGS")
    if fail_at is None and kill_at is None and biased is None:
        return None

    def hook(event, rendered, **info):
        if biased:
            import bpy
            for item in biased.split(","):
                key, value = item.split("=")
                setattr(bpy.context.scene.cycles, key, float(value))
        if kill_at is not None and rendered == int(kill_at):
            sys.stderr.flush()
            os.kill(os.getpid(), signal.SIGKILL)
        if fail_at is not None and rendered == int(fail_at):
            raise RuntimeError(f"test hook: failing before render {rendered} (group {info['group']})")
    return hook


def _empty_startup_scene(bpy):
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras,
                       bpy.data.worlds):
        for item in list(collection):
            collection.remove(item)


def _ensure_registered(bpy):
    """Registers the add-on unless Blender already has (an enabled extension or add-on)."""
    if not hasattr(bpy.types.Scene, "chromatrace"):
        from . import register
        register()


def run(argv):
    args = parse_batch_args(argv)
    import bpy
    from . import cache, planning, scene_import, tool

    _ensure_registered(bpy)
    log = (lambda message: None) if args.quiet else _log
    chromatrace_tool = tool.Tool(tool.find_executable())
    if args.scene:
        _empty_startup_scene(bpy)
        scene_import.import_scene(args.scene, bpy.context.scene, chromatrace_tool, log, ggx_masking=args.ggx_masking,
                                  warn=_log)  # also with --quiet
    else:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(args.blend))
    scene = bpy.context.scene
    work, planned = None, None
    try:
        if args.plan is not None:
            work = planning.planning_folder()
            planned = _plan(args, scene, chromatrace_tool, work, log)
            args.bands_file, args.max_bounces = planned.bands_file, planned.max_bounces
            if args.plan_out:
                with open(planned.bands_file) as f:
                    cache.write_json(os.path.abspath(args.plan_out), json.load(f))
                log(f"plan written to {args.plan_out} (max {planned.max_bounces} bounces)")
        _render(args, bpy, scene, chromatrace_tool, log, planned)
    finally:
        if work:
            planning.remove_folder(work)


def _plan(args, scene, chromatrace_tool, work, log):
    """batch.py --plan: the plan (plan_scene.py) of the scene file, or of the open scene written as one, with pilots
    rendered by this Cycles."""
    from . import plan_scene, planning, spectral_render
    request = dict(resolution=args.resolution, device=args.device, on_mixing_nodes=args.on_mixing_nodes,
                   on_world=args.on_world)
    pilot_size = plan_scene.pilot_resolution(scene, spectral_render.Request.from_scene(
        scene, **{k: v for k, v in request.items() if v is not None}))
    both = plan_scene.uses_light_tree(scene)  # pilots with Cycles' light tree and without it
    log(f"planning for a mean ΔE00 of {args.plan:g}: chromatrace plan, then two pilot renders of "
        f"{'x'.join(map(str, pilot_size))} at {planning.PILOT_SAMPLES} "
        f"samples for Cycles' noise{', with its light tree and again without it' if both else ''}")
    start, start_cpu = time.monotonic(), _cpu_seconds()
    with _stdout_silenced(args.quiet):
        try:
            planned = plan_scene.plan_open_scene(scene, chromatrace_tool, args.plan, work, scene_file=args.scene,
                                                 edge_step=args.plan_edge_step,
                                                 reference_spp=args.plan_reference_spp, **request)
        except BadInput as e:
            message = str(e)
            if not message.startswith("--plan"):
                message = f"--plan: {args.blend or args.scene}: {message}"
            raise BadInput(message) from None
    log(planned.summary())
    for note in planned.notes:
        _log(f"warning: the plan: {note}")  # also with --quiet: the prediction is less certain for it
    # The planning's cost beside the renders' (their progress lines): this process's CPU (the pilots' Cycles
    # renders) and its finished children's (chromatrace plan, twice).
    log(f"planning: {time.monotonic() - start:.2f} s, {_cpu_seconds() - start_cpu:.2f} s CPU")
    return planned


def _cpu_seconds():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _render(args, bpy, scene, chromatrace_tool, log, planned):
    from . import bands, spectral_render
    request = spectral_render.Request.from_scene(
        scene, output=os.path.abspath(args.out) if args.out else None, samples=args.samples,
        max_bounces=args.max_bounces, seed=args.seed, bands=args.bands, bands_file=args.bands_file,
        families=args.components, resolution=args.resolution, cache_root=args.cache_dir,
        keep_cache=args.keep_cache or None, log=log, on_mixing_nodes=args.on_mixing_nodes,
        bands_per_render=args.bands_per_render, on_world=args.on_world, only_group=args.band_group,
        only_variant=args.bounce_limit, device=args.device)
    if planned:
        request.plan_header = planned.header()
    if args.bands_file:
        request.bands = None
        if args.samples is not None and bands.planned_samples(args.bands_file):
            raise BadInput(f"--samples: the band plan {args.bands_file} gives each band group its samples "
                           "(cycles_samples); leave out --samples, or use a plan without them")
    elif args.bands:
        request.bands_file = None
    if args.explain is not None:
        summary = spectral_render.SpectralRender(scene, request, chromatrace_tool).preflight()
        text = json.dumps(summary, indent=1)
        if args.explain == "-":
            print(text, flush=True)
        else:
            with open(args.explain, "w") as f:
                f.write(text + "\n")
        return
    if args.scene and args.band_group is None:
        # What these settings leave out, said before rendering as `chromatrace render` says it (also with
        # --quiet); a band-group task of a farm leaves it to the run that assembles.
        for warning in chromatrace_tool.render_warnings(
                args.scene, bands=args.bands, bands_file=args.bands_file, samples=args.samples,
                max_bounces=args.max_bounces, resolution=args.resolution):
            _log(f"warning: {warning}")
    spectral_render.TEST_HOOK = _test_hook()
    with _stdout_silenced(args.quiet):
        spectral_render.SpectralRender(scene, request, chromatrace_tool).run()


@contextlib.contextmanager
def _stdout_silenced(quiet):
    """With --quiet, what Blender and Cycles print to standard output while rendering ("Fra:1 Mem:…", "Saved: …")
    goes nowhere: their printing is in C, so the file descriptor itself is pointed at /dev/null for the while.
    chromatrace's own messages are on standard error."""
    if not quiet:
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def main(argv=None, prog="chromatrace.headless"):
    """Runs the batch with `argv` (by default this process's script arguments) and exits with its status."""
    if argv is None:
        argv = script_arguments(sys.argv)
    try:
        run(argv)
    except BadInput as e:
        print(f"{prog}: error: {e}", file=sys.stderr, flush=True)
        _exit(2)
    except Exception as e:  # a runtime failure: the reason on one line, the traceback for a bug report
        if os.environ.get("CHROMATRACE_TRACEBACK"):
            traceback.print_exc()
        print(f"{prog}: failed: {str(e).strip().splitlines()[-1] if str(e).strip() else type(e).__name__}",
              file=sys.stderr, flush=True)
        _exit(1)
    _exit(0)


def _remove_session_folder(folder):
    """Removes Blender's session folder (TMPDIR/blender_XXXXXX/), which its teardown would have removed."""
    folder = os.path.normpath(folder or "")
    if os.path.basename(folder).startswith("blender_") and os.path.isdir(folder):
        shutil.rmtree(folder, ignore_errors=True)


def _exit(status):
    """Ends the process with `status`. Blender itself leaves without the interpreter's teardown; a Python that
    imported Blender as a module (PyPI's bpy) must too, as its teardown can stall on the render threads."""
    import bpy
    if getattr(bpy.app, "module", False):
        sys.stdout.flush()
        sys.stderr.flush()
        _remove_session_folder(bpy.app.tempdir)
        os._exit(status)
    sys.exit(status)
