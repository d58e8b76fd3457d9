# SPDX-License-Identifier: GPL-3.0-or-later
"""Command line of blender_addon/batch.py (pure Python, no bpy).

    blender --background --factory-startup --python blender_addon/batch.py -- \
        (--scene SCENE.json | --blend FILE.blend) --out OUT.exr [options]
        (--scene SCENE.json | --blend FILE.blend) --explain [FILE] [options]   (the pre-flight summary only)
        (--scene SCENE.json | --blend FILE.blend) --out OUT.exr --band-group G [options]   (one group into the cache)

Every mistake is a BadInput with one line naming the option, as the `chromatrace` command reports.
"""

import argparse
import os
import re

from .components import ComponentError, parse_components
from .errors import BadInput


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse prints usage and exits; we want one line and exit code 2
        raise BadInput(message)


def _parser():
    p = _Parser(prog="batch.py", add_help=True,
                description="Render a chromatrace scene or a .blend spectrally with Cycles (bands multiplexed 3 per render).")
    source = p.add_mutually_exclusive_group()
    source.add_argument("--scene", help="scene file (chromatrace-scene/1)")
    source.add_argument("--blend", help=".blend file with chromatrace settings (never written)")
    p.add_argument("--out", help="output spectral EXR (written atomically)")
    p.add_argument("--samples", type=int, help="samples per pixel (default: the scene's)")
    p.add_argument("--bands", help="band plan lo:hi:width in nm (default: the scene's)")
    p.add_argument("--bands-file", help="band plan file (chromatrace-bands/1)")
    p.add_argument("--plan", type=float, metavar="DE00",
                   help="plan bands, bounce limit and each band group's samples for this mean ΔE00 (chromatrace plan, "
                        "with Cycles' noise measured on two small pilot renders) and render with them")
    p.add_argument("--plan-edge-step", type=float, metavar="NM",
                   help="with --plan: band edges on multiples of NM nm (chromatrace plan --edge-step; 5 lets compare "
                        "hold the render against a reference of 5 nm bands)")
    p.add_argument("--plan-reference-spp", type=int, metavar="N",
                   help="with --plan: the target is the mean ΔE00 compare will measure against a tracer reference of N "
                        "paths per pixel, its noise counted (for a render to be validated against one)")
    p.add_argument("--plan-out", metavar="FILE",
                   help="with --plan: also write the plan's band file (bands, reconstruction, each group's samples) to "
                        "FILE, to render the same plan again with --bands-file and --max-bounces")
    p.add_argument("--max-bounces", type=int, help="scattering events per path: 0 emitters, 1 direct, >= 2 global")
    p.add_argument("--components", help="component families: paths, lights, bounces, all, none (default: the scene's)")
    p.add_argument("--resolution", help="image size WxH, overriding the camera's")
    p.add_argument("--seed", type=int, help="Cycles seed (default: the scene's)")
    p.add_argument("--on-mixing-nodes", choices=["refuse", "one-band"],
                   help="node trees that mix colour channels: refuse to render, or render one band per render")
    p.add_argument("--on-world", choices=["refuse", "omit"],
                   help="a lit world whose colours cannot be spectra (an HDRI): refuse to render (default), or render "
                        "without the world's light, with a warning and a note in the file")
    p.add_argument("--explain", "--preflight", nargs="?", const="-", metavar="FILE",
                   help="print (or write to FILE) the pre-flight summary as JSON: every material, light and the world "
                        "exact, upsampled or refused, and the renders needed; render nothing")
    p.add_argument("--ggx-masking", choices=["scene", "cycles"], default="scene",
                   help="GGX masking-shadowing: the scene's (a material asking for the masking this Cycles does not "
                        "have is refused; the default), or this Cycles' own (separable up to Blender 3.x, "
                        "height-correlated from 4.0), each material changed named in a warning and the output's "
                        "header recording the scene as rendered")
    p.add_argument("--device", choices=["CPU", "CUDA", "OPTIX", "HIP", "ONEAPI", "METAL"], default="CPU",
                   help="Cycles' render device: the CPU (default), or the GPUs of one backend Blender finds; recorded "
                        "in the cache key and the output's header")
    p.add_argument("--bands-per-render", type=int, choices=[1, 2, 3],
                   help="bands multiplexed into one render (default 3; fewer for comparisons)")
    p.add_argument("--cache-dir", help="where finished band groups are kept for resuming "
                                       "(default: $XDG_CACHE_HOME/chromatrace/blender)")
    p.add_argument("--keep-cache", action="store_true", help="keep the band-group renders after success")
    p.add_argument("--band-group", type=int, metavar="G",
                   help="render only band group G (0-based, with all its bounce limits) into the cache and stop: one "
                        "task of a render split over a cluster (chromatrace farm cycles); a later run without it "
                        "finds the group there")
    p.add_argument("--bounce-limit", metavar="NAME",
                   help="with --band-group: only this one of the group's renders (a bounce limit of the bounces "
                        "components, as the pre-flight summary's render_variants names them: k1, k2, ..., main)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress lines on stderr")
    return p


def parse_batch_args(argv):
    """Parses the arguments after Blender's `--`; returns an argparse.Namespace with `components` a set or None
    and `resolution` a (width, height) pair or None."""
    args = _parser().parse_args(argv)
    if not args.scene and not args.blend:
        raise BadInput("--scene: give a scene file (--scene SCENE.json) or a .blend (--blend FILE.blend)")
    source_option = "--scene" if args.scene else "--blend"
    source = args.scene or args.blend
    if not os.path.isfile(source):
        raise BadInput(f"{source_option}: {source}: no such file")
    if not args.out and args.explain is None:
        raise BadInput("--out: no output file given")
    for option, path in (("--out", args.out), ("--explain", args.explain)):
        if path and path != "-" and not os.path.isdir(os.path.dirname(os.path.abspath(path))):
            raise BadInput(f"{option}: {path}: directory {os.path.dirname(os.path.abspath(path))} does not exist")
    if args.samples is not None and args.samples < 1:
        raise BadInput(f"--samples: must be at least 1, got {args.samples}")
    if args.max_bounces is not None and args.max_bounces < 0:
        raise BadInput(f"--max-bounces: must be >= 0, got {args.max_bounces}")
    if args.seed is not None and args.seed < 0:
        raise BadInput(f"--seed: must be >= 0, got {args.seed}")
    if args.band_group is not None and args.band_group < 0:
        raise BadInput(f"--band-group: must be >= 0, got {args.band_group}")
    if args.band_group is not None and args.explain is not None:
        raise BadInput("--band-group: renders a band group, --explain renders nothing; give one of them")
    if args.bounce_limit is not None and args.band_group is None:
        raise BadInput("--bounce-limit: needs --band-group (the group whose render it is)")
    if args.plan is not None:
        if not args.plan > 0:
            raise BadInput(f"--plan: the mean ΔE00 to plan for must be > 0, got {args.plan:g}")
        for option, value in (("--bands", args.bands), ("--bands-file", args.bands_file), ("--samples", args.samples),
                              ("--max-bounces", args.max_bounces), ("--band-group", args.band_group),
                              ("--explain", args.explain)):
            if value is not None:
                raise BadInput(f"{option}: --plan chooses the bands, bounce limit and samples; give one of them")
    if args.plan_edge_step is not None and args.plan is None:
        raise BadInput("--plan-edge-step: needs --plan (the plan whose band edges it places)")
    if args.plan_reference_spp is not None and args.plan is None:
        raise BadInput("--plan-reference-spp: needs --plan (the plan whose target it is)")
    if args.plan_reference_spp is not None and args.plan_reference_spp < 1:
        raise BadInput(f"--plan-reference-spp: must be >= 1, got {args.plan_reference_spp}")
    if args.plan_out is not None and args.plan is None:
        raise BadInput("--plan-out: needs --plan (the plan it writes)")
    if args.bands and args.bands_file:
        raise BadInput("--bands-file: give either --bands or --bands-file, not both")
    if args.bands_file and not os.path.isfile(args.bands_file):
        raise BadInput(f"--bands-file: {args.bands_file}: no such file")
    if args.components is not None:
        try:
            args.components = parse_components(args.components)
        except ComponentError as e:
            raise BadInput(str(e)) from None
    if args.resolution is not None:
        match = re.fullmatch(r"([1-9][0-9]*)x([1-9][0-9]*)", args.resolution)
        if not match:
            raise BadInput(f"--resolution: expected WxH with positive integers, got \"{args.resolution}\"")
        args.resolution = (int(match.group(1)), int(match.group(2)))
    return args
