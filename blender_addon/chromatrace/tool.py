# SPDX-License-Identifier: GPL-3.0-or-later
"""Running the `chromatrace` command, which owns every spectrum operation, the tessellation and the spectral
EXR writer (pure Python, no bpy).

The executable is, in order: the add-on preference, the CHROMATRACE_EXE environment variable, the one
installed beside the add-on by `cmake --install` (<prefix>/bin/chromatrace for the add-on in
<prefix>/share/chromatrace/blender_addon/chromatrace), then `chromatrace` on PATH.
"""

import json
import os
import re
import shutil
import subprocess

from .errors import BadInput

ENV_VAR = "CHROMATRACE_EXE"


def installed_executable():
    here = os.path.dirname(os.path.realpath(__file__))  # through a symlink in Blender's add-ons folder
    return os.path.normpath(os.path.join(here, "..", "..", "..", "..", "bin", "chromatrace"))


def find_executable(preference=""):
    """The chromatrace executable: the add-on preference when one is set — a preference naming no executable is
    an error that says so, never skipped for another chromatrace — else $CHROMATRACE_EXE, the installed one, or
    chromatrace on PATH."""
    if preference:
        if os.path.isfile(preference) and os.access(preference, os.X_OK):
            return preference
        raise BadInput(f"the add-on preference 'chromatrace executable' is {preference}, which is "
                       f"{'not executable' if os.path.isfile(preference) else 'not a file'}: correct it, or clear it "
                       f"to use $CHROMATRACE_EXE, the installed chromatrace or the one on PATH")
    candidates = [os.environ.get(ENV_VAR, ""), installed_executable()]
    for path in candidates:
        if path and os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    found = shutil.which("chromatrace")
    if found:
        return found
    raise BadInput("chromatrace executable not found: set the add-on preference, the CHROMATRACE_EXE environment "
                   "variable, or put chromatrace on PATH")


class Tool:
    def __init__(self, executable):
        self.executable = executable

    def run(self, *args, json_output=False):
        """Runs a subcommand. Exit 2 (bad input) raises BadInput with the command's one-line message;
        other failures raise RuntimeError."""
        result = subprocess.run([self.executable, *map(str, args)], capture_output=True, text=True)
        if result.returncode == 2:
            raise BadInput(_last_line(result.stderr) or f"chromatrace {args[0]}: bad input")
        if result.returncode != 0:
            raise RuntimeError(_last_line(result.stderr) or f"chromatrace {args[0]} failed ({result.returncode})")
        return json.loads(result.stdout) if json_output else result.stdout

    def band_averages(self, spectra_file, bands=None, bands_file=None):
        args = ["scene-bands", spectra_file, "--json"]
        if bands:
            args += ["--bands", bands]
        if bands_file:
            args += ["--bands-file", bands_file]
        return self.run(*args, json_output=True)

    def plan(self, scene_file, target, output, report, pilots=None, edge_step=None, reference_spp=None):
        """`chromatrace plan` for Cycles: the band-plan file and the report; with two pilot renders, Cycles' noise
        measured on them; with `reference_spp`, the target is as compare measures it against a tracer reference of
        that many paths, its noise counted."""
        args = ["plan", scene_file, "--target-de00", repr(float(target)), "-o", output, "--report", report, "--quiet"]
        if edge_step:
            args += ["--edge-step", repr(float(edge_step))]
        if reference_spp:
            args += ["--reference-spp", str(int(reference_spp)), "--target-against-reference"]
        if pilots:
            args += ["--cycles-pilot", *pilots]
        return self.run(*args)

    def check_scene(self, scene_file):
        return self.run("check-scene", scene_file, "--json", json_output=True)

    def render_warnings(self, scene_file, bands=None, bands_file=None, samples=None, max_bounces=None, resolution=None):
        """What a Cycles render of the scene file with these settings leaves out, said before rendering
        (`chromatrace check-scene --renderer cycles`): one line each, cause, size and fix, the settings named by
        the batch's options (--bands-file, --samples, --max-bounces)."""
        args = ["check-scene", scene_file, "--json", "--renderer", "cycles"]
        for option, value in (("--bands", bands), ("--bands-file", bands_file), ("--samples", samples),
                              ("--max-bounces", max_bounces)):
            if value is not None:
                args += [option, value]
        if resolution is not None:
            args += ["--resolution", f"{resolution[0]}x{resolution[1]}"]
        return self.run(*args, json_output=True)["scene"]["warnings"]

    def export_meshes(self, scene_file, directory):
        return self.run("export-meshes", scene_file, directory, "--uvs", "--json", json_output=True)

    def prepare_texture(self, image, kind, colour_space, bands_file, per_render, replicate, scale, directory):
        """Per-band-group textures of an image (`chromatrace prepare-texture`): its --json summary."""
        args = ["prepare-texture", image, "--kind", kind, "--colour-space", colour_space, "--bands-file", bands_file,
                "--bands-per-render", per_render, "--scale", repr(float(scale)), "-o", directory, "--json", "--quiet"]
        if replicate:
            args.append("--replicate")
        return self.run(*args, json_output=True)

    def check_texture(self, image, kind, colour_space):
        """An image read and judged as a render would (`chromatrace prepare-texture --check`): {"width", "height",
        "negative_texels": {"zeroed", "largest", "threshold"}}; negative light refused (BadInput naming the texel)."""
        return self.run("prepare-texture", image, "--kind", kind, "--colour-space", colour_space, "--check",
                        json_output=True)

    def analysis_commands(self, spectral_exr, analysis_dir, sensor_preset, camera_curves=None):
        """The command lines that take a spectral render to its histogram report: the camera (`chromatrace sensor`
        with a sensor preset, a camera's curves — the preset's own when None — and automatic exposure) and the
        analyzer (`chromatrace analyze`). Returns ([[argv], [argv]], report.html)."""
        camera = os.path.join(analysis_dir, "camera.exr")
        curves = ["--camera", camera_curves] if camera_curves else []
        return ([[self.executable, "sensor", spectral_exr, "-o", camera, "--preset", sensor_preset, *curves,
                  "--exposure-s", "auto", "--quiet"],
                 [self.executable, "analyze", camera, "-o", os.path.join(analysis_dir, "analysis"), "--quiet"]],
                os.path.join(analysis_dir, "analysis", "report.html"))

    def run_commands(self, commands):
        """Runs command lines made by this tool in order (each as run() does: BadInput on exit 2)."""
        for argv in commands:
            self.run(*argv[1:])

    def preview(self, spectral_exr, png):
        """The picture a person would see (`chromatrace sensor`'s display rendering: a Canon EOS 5D Mark III,
        exposure from the scene's surfaces, white balance, colour matrix and sRGB), noise-free, as an 8-bit PNG."""
        return self.run("sensor", spectral_exr, "-o", png, "--preset", "canon_eos_5d_mkiii", "--exposure-s", "auto",
                        "--no-noise", "-q")

    def image_info(self, image):
        """`chromatrace info --json`: size, channels, …; BadInput when the file does not read to its end."""
        return self.run("info", image, "--json", json_output=True)

    def assemble(self, manifest_file, output):
        return self.run("assemble", manifest_file, "-o", output, "--quiet")


def _last_line(text):
    """The command's one-line message, without its "chromatrace <command>: error: " prefix."""
    lines = [line for line in text.strip().splitlines() if line.strip()]
    if not lines:
        return ""
    return re.sub(r"^chromatrace [a-z-]+: (error|failed): ", "", lines[-1])
