# SPDX-License-Identifier: Apache-2.0
"""chromatrace from Python: the analyzer and the camera simulator on NumPy arrays (docs/python.md).

Each function does what its command does, with the same library code and the same messages:

- analyze(image, ...)              chromatrace analyze: an Analysis (analysis.json's content, the segment labels)
- sensor(spectral, ...)            chromatrace sensor: a Capture (the camera's R, G, B, its layers and numbers)
- read_spectral_exr(path)          a spectral EXR (the JCGT layout) as arrays
- write_spectral_exr(path, ...)    arrays as a spectral EXR, as the renderers write it
- read_raw_mosaic(path)            a camera raw's Bayer mosaic as stored
- calibrate(flats, darks, ...)     chromatrace calibrate: EMVA 1288 sensor settings from frames

Bad input raises InputError (a ValueError) whose message is the line the command prints after "error: ": it names
options as the command does (--preset for preset=, --input-transfer for encoding=).
"""

from __future__ import annotations

import html
import json
import os
import tempfile
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from . import _chromatrace
from ._chromatrace import InputError

__all__ = ["InputError", "Analysis", "Capture", "analyze", "sensor", "read_spectral_exr", "write_spectral_exr", "read_raw_mosaic",
           "calibrate"]


def _path(value: Any) -> str | None:
    """A path given as str or os.PathLike, else None."""
    if isinstance(value, (str, os.PathLike)):
        return os.fspath(value)
    return None


# ----------------------------------------------------------------------------------------------------------------
# The analyzer


class Analysis:
    """An analysis of an image's colour histograms, as `chromatrace analyze` writes it.

    `data` is analysis.json's content as Python objects (docs/analyze.md lists every field); `labels` the
    segmentation's label map (height x width uint16: k for segment k, 0 unassigned) with segment=True, else None.
    In a notebook it shows itself as the analyze report (the image, the segment map and the interactive 3D
    histogram), or as the whole image's histogram plot where scripts do not run.
    """

    def __init__(self, native: Any):
        self._native = native
        self.data: dict = json.loads(native.json())
        self.labels: np.ndarray | None = native.labels()

    @property
    def regions(self) -> list[dict]:
        """The regions, each with its class, shape, interpretation and explanation (analysis.json's regions)."""
        return self.data["regions"]

    @property
    def illuminant(self) -> dict:
        """The light's colour: "estimate" (the one the analysis trusts most, with its method and uncertainty),
        "choice" (why), and every method's own estimate."""
        return self.data["illuminant"]

    def region(self, key: int | str) -> dict:
        """A region by its index or its name ("image", "segment 2", "mask cup", "object 3" …)."""
        if isinstance(key, int):
            return self.regions[key]
        for r in self.regions:
            if r["name"] == key:
                return r
        raise KeyError(f"no region named {key!r}; the regions are {', '.join(r['name'] for r in self.regions)}")

    def histogram(self, key: int | str) -> dict:
        """A region's 3D histogram (sparse cells), its projections and its rg-chromaticity histogram."""
        return json.loads(self._native.histogram_json(self.region(key)["index"]))

    def plot_png(self, key: int | str = 0, colouring: str = "own") -> bytes:
        """A region's histogram plot as PNG bytes, as analyze's plots/region-NN.png ("own" or "density" colouring)."""
        return self._native.plot_png(self.region(key)["index"], colouring)

    def report_html(self, report_points: int = 20000) -> str:
        """analyze's report page (report.html) as one self-contained HTML document shown on its own: it links no
        analysis.json or plots (write() writes the page beside them)."""
        return self._native.report_html(report_points)

    def write(self, directory: str | os.PathLike, *, plots: bool = True, report: bool = True, report_points: int = 20000,
              plot_limit: int | None = 12) -> None:
        """Writes the analysis directory analyze -o DIR writes (analysis.json, histograms/, plots/, report.html,
        labels.png), atomically: a failure leaves nothing behind."""
        self._native.write(os.fspath(directory), plots, report, report_points, plot_limit)

    def __repr__(self) -> str:
        light = self.illuminant["estimate"]
        rgb = ", ".join(f"{v:.4f}" for v in light["rgb"])
        return (f"<chromatrace.Analysis of {self.data['image']['file']}: {len(self.regions)} regions; "
                f"light ({rgb}) by {light['method']}>")

    # Jupyter: the report in a sandboxed frame of its own (its styles and scripts stay in it; everything is inline, no
    # network), and the whole image's plot for front ends that show no HTML.
    def _repr_html_(self) -> str:
        page = self.report_html(5000)
        return ('<iframe style="width:100%;height:820px;border:1px solid #ccc" sandbox="allow-scripts" '
                f'srcdoc="{html.escape(page, quote=True)}"></iframe>')

    def _repr_png_(self) -> bytes:
        return self.plot_png(0)


def _analyze_args(encoding, layer, labels, mask, rects, segment, camera_config, illuminant, bins, seed, threads, raw_demosaic,
                  raw_half_size, segment_options) -> Any:
    args = _chromatrace.AnalyzeArgs()
    args.input_transfer = encoding
    args.layer = layer
    if labels is not None:
        if _path(labels) is not None:
            args.labels = _path(labels)
        else:
            args.set_label_array(labels)
    masks: list[tuple[str, Any]] = []
    if mask is not None:
        if isinstance(mask, Mapping):
            masks = list(mask.items())
        elif _path(mask) is not None or isinstance(mask, np.ndarray):
            masks = [("", mask)]
        else:
            masks = [("", m) for m in mask]
    for k, (name, m) in enumerate(masks, 1):
        if _path(m) is not None:
            args.masks = args.masks + [_path(m)]
        else:
            args.add_mask_array(name or str(k), np.asarray(m))
    args.rects = [r if isinstance(r, str) else ",".join(str(int(v)) for v in r) for r in rects]
    args.segment = segment
    for key, value in segment_options.items():
        setattr(args, key, value)
    if camera_config is not None:
        args.camera_config = os.fspath(camera_config)
    if illuminant is not None:
        args.illuminant = [float(v) for v in illuminant]
    args.bins = bins
    args.seed = seed
    args.threads = threads
    if raw_demosaic is not None:
        args.raw_demosaic = raw_demosaic
    args.raw_half_size = raw_half_size
    return args


def analyze(image: Any, *, encoding: str = "auto", layer: str = "final", labels: Any = None, mask: Any = None,
            rects: Sequence[Any] = (), segment: bool = False, camera_config: str | os.PathLike | None = None,
            illuminant: Sequence[float] | None = None, bins: int = 64, seed: int = 1, threads: int = 0,
            raw_demosaic: str | None = None, raw_half_size: bool = False, name: str | None = None,
            segment_size: float | None = None, segment_min_area: float | None = None,
            segment_tolerance: float | None = None, segment_angle: float | None = None,
            segment_dark: float | None = None) -> Analysis:
    """Analyses an image's colour histograms, as `chromatrace analyze IMAGE` does.

    image: a path (PNG, TIFF, EXR, JPEG, camera raw …) or a height x width x 3 array of R, G, B (x 4 with an alpha,
        whose 0 sets a pixel aside, as a file's does): uint8, uint16 or uint32 hold their stored integers (as an
        integer file's), float32/float64 the values themselves.
    encoding: what R, G, B hold (--input-transfer): "auto", "linear", "srgb" or "gamma=G". Under "auto" an
        integer array is sRGB and a float array linear, as files without metadata are taken.
    layer: the layer of a simulator's EXR (--layer); arrays have only "final".
    labels: "object_id", a label image file, or a height x width array of labels (0 is no region).
    mask: a mask file or array (non-zero is in), a list of them, or a dict of them by name.
    rects: rectangles, each "x,y,w,h" or (x, y, w, h).
    segment: automatic segmentation (--segment); the labels come back as Analysis.labels.
    camera_config: sensor settings (e.g. from calibrate) whose noise judges the clusters; an array must then hold the
        camera's digital numbers, with encoding="linear".
    illuminant: the known light's R, G, B, for angular errors.
    name: what messages and analysis.json call an array ("array" by default).
    The other arguments are analyze's options of the same names.
    """
    segment_options = {k: v for k, v in {"segment_size": segment_size, "segment_min_area": segment_min_area,
                                         "segment_tolerance": segment_tolerance, "segment_angle": segment_angle,
                                         "segment_dark": segment_dark}.items() if v is not None}
    args = _analyze_args(encoding, layer, labels, mask, rects, segment, camera_config, illuminant, bins, seed, threads,
                         raw_demosaic, raw_half_size, segment_options)
    path = _path(image)
    if path is not None:
        return Analysis(_chromatrace.analyze_file(path, args))
    return Analysis(_chromatrace.analyze_array(np.asarray(image), name or "array", args))


# ----------------------------------------------------------------------------------------------------------------
# Spectral EXR files


def read_spectral_exr(path: str | os.PathLike) -> dict:
    """A spectral EXR (any file in the JCGT layout; docs/spectral-exr.md) as arrays.

    Returns a dict: each quantity of the total ("S0" radiance, "T" reflectance …) as a height x width x bands float32
    array, "components" (name -> {quantity -> array}), "wavelengths_nm" (band centres), "band_edges_nm",
    "object_ids" (height x width int32, or None), "object_names", "emissive_units", "kind", "metadata" (every other
    attribute as text) and "notes".
    """
    return _chromatrace.read_spectral_exr(os.fspath(path))


def write_spectral_exr(path: str | os.PathLike, spectral: Any, wavelengths_nm: Sequence[float] | None = None, *,
                       band_edges_nm: Sequence[float] | None = None, reflective: bool = False,
                       components: Mapping[str, Any] | None = None, object_ids: Any = None,
                       object_names: Mapping[int, str] | None = None, attributes: Mapping[str, str] | None = None) -> None:
    """Writes a spectral EXR as chromatrace's renderers write it (docs/spectral-exr.md), atomically.

    spectral: height x width x bands, emitted radiance in W m^-2 sr^-1 nm^-1 (S0), or reflectance (T) with
        reflective=True. Bands by their centres (wavelengths_nm: each reaches halfway to its neighbours) or edges.
    components: light-path component layers by name (diffuse_direct, light.key, bounce.2 …), of the same shape.
    object_ids: height x width whole numbers; object_names: id -> name. attributes: more text attributes, each
        named chromatrace.<key> (chromatrace.renderer, chromatrace.scene …).
    """
    cube = np.asarray(spectral)
    if cube.ndim != 3:
        raise InputError(f"spectral: expected height x width x bands, got shape {cube.shape}")
    _chromatrace.write_spectral_exr(os.fspath(path), cube, [float(v) for v in band_edges_nm or []],
                                    [float(v) for v in wavelengths_nm or []], reflective, list((components or {}).items()),
                                    object_ids, dict(object_names or {}), dict(attributes or {}))


# ----------------------------------------------------------------------------------------------------------------
# Camera raw files


def read_raw_mosaic(path: str | os.PathLike) -> dict:
    """A camera raw's Bayer mosaic as stored (DNG, CR2, NEF … through LibRaw): "mosaic" (height x width uint16, one
    value per visible photosite, the black level not subtracted), "pattern" (the top-left 2 x 2 tile, "RGGB" …),
    "black_level" (a tile's mean) and "white_level"."""
    return _chromatrace.read_raw_mosaic(os.fspath(path))


# ----------------------------------------------------------------------------------------------------------------
# The camera


@dataclass
class Capture:
    """What the camera simulator made of a spectral image (docs/sensor.md, "Output").

    rgb: the final R, G, B (height x width x 3 float32) in the units `signal` names: "DN" with the ADC on, "e-" with
    it off, "normalised" with a rendering intent. linear: the noise-free linear camera signal (e-); display: the
    sRGB picture for people, in [0, 1]; components: each light-path component's linear camera RGB (e-); object_ids;
    with mosaic=True, mosaic: the colour filter array's photosites before demosaicing (height x width uint16 DN,
    black level included) and cfa_pattern (its top-left 2 x 2 tile, "RGGB" …).
    metadata: the camera's numbers as the EXR header gives them (chromatrace.black_level, white_level, signal,
    units, curve …); settings: the effective sensor settings; notes: decisions taken.
    """
    rgb: np.ndarray
    signal: str
    linear: np.ndarray | None = None
    display: np.ndarray | None = None
    components: dict[str, np.ndarray] = field(default_factory=dict)
    object_ids: np.ndarray | None = None
    mosaic: np.ndarray | None = None
    cfa_pattern: str | None = None
    exposure_s: float = 0.0
    metadata: dict[str, Any] = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _camera_metadata(attributes: Mapping[str, Any]) -> dict[str, Any]:
    """The simulator's chromatrace.* attributes, those that hold JSON (units, display, sensor …) parsed."""
    out = {}
    for key, value in attributes.items():
        if not key.startswith("chromatrace."):
            continue
        if isinstance(value, str) and value[:1] in "{[":
            try:
                value = json.loads(value)
            except ValueError:
                pass
        out[key] = value
    return out


def _capture_from_exr(path: str, report: dict) -> Capture:
    values, names, attributes = _chromatrace.read_image_channels(path)
    index = {n: i for i, n in enumerate(names)}

    def rgb(prefix: str) -> np.ndarray | None:
        keys = [f"{prefix}{c}" for c in "RGB"]
        if not all(k in index for k in keys):
            return None
        return np.ascontiguousarray(values[:, :, [index[k] for k in keys]])

    layers = sorted({n.rsplit(".", 1)[0] for n in names if "." in n and n.rsplit(".", 1)[1] in ("R", "G", "B")})
    components = {l: layer for l in layers if l not in ("linear", "display") and (layer := rgb(l + ".")) is not None}
    ids = values[:, :, index["object_id"]].astype(np.int32) if "object_id" in index else None
    return Capture(rgb=rgb(""), signal=str(attributes.get("chromatrace.signal", "")), linear=rgb("linear."),
                   display=rgb("display."), components=components, object_ids=ids,
                   exposure_s=report["exposure_s"], metadata=_camera_metadata(attributes),
                   settings=json.loads(report["settings"]), notes=list(report["notes"]))


def sensor(spectral: Any, config: Any = None, *, preset: str | None = None, wavelengths_nm: Sequence[float] | None = None,
           band_edges_nm: Sequence[float] | None = None, illuminant: str | None = None, camera: str | None = None,
           exposure_s: float | str | None = None, cfa: str | None = None, noise: bool = True,
           set: Mapping[str, Any] | None = None, seed: int | None = None, threads: int = 0,
           output: str | os.PathLike | None = None, mosaic: bool = False) -> Capture:
    """Simulates a camera on a spectral image, as `chromatrace sensor IN.exr -o OUT.exr` does.

    spectral: a spectral EXR path, or a height x width x bands array with its wavelengths_nm (band centres) or
        band_edges_nm: radiance (S0, W m^-2 sr^-1 nm^-1), or reflectance lit by `illuminant`. An array is written to
        a temporary spectral EXR first: the simulator streams its input in blocks of rows from a file, as it does for
        any size of image.
    config: sensor settings, a chromatrace-sensor/1 file path or a dict of settings over the preset.
    preset: ideal, canon_eos_5d_mkiii, machine_vision_ccd or smartphone.
    illuminant: lights a reflectance image (a CIE illuminant name or a CSV file).
    camera: the spectral response, a shipped camera, cie1931 or a CSV file (--camera).
    exposure_s: the exposure time in seconds, or "auto" (--exposure-s; the presets fix one).
    cfa: a Bayer pattern (RGGB, BGGR, GRBG, GBRG) or "none" (--cfa). noise=False: every pixel at its expected value.
    set: settings by their dotted keys, {"noise.read_e": 3}, applied last, as --set.
    seed: the temporal noise's seed (noise.seed).
    output: where to keep the simulator's EXR (.exr) as the command writes it; a temporary file otherwise.
    mosaic: also the colour filter array's photosites as read out, before demosaicing (needs a CFA): the simulator
        runs a second time into a DNG, as `-o capture.dng` does (the noise is the same, keyed by pixel and seed), whose
        mosaic is then read back.
    """
    patches: list[tuple[str, str]] = []
    config_file = ""
    if preset is not None:
        patches.append((json.dumps({"preset": preset}), "--preset"))
    if config is not None:
        if _path(config) is not None:
            config_file = _path(config)
        elif isinstance(config, Mapping):
            patches.append((json.dumps(config), "--config"))
        else:
            raise InputError("--config: a settings file's path or a dict of settings")
    if camera is not None:
        patches.append((json.dumps({"spectral_response": {"camera": camera}}), "--camera"))
    if exposure_s is not None:
        if not (exposure_s == "auto" or (isinstance(exposure_s, (int, float)) and not isinstance(exposure_s, bool))):
            raise InputError(f'--exposure-s: must be a time in seconds or "auto", got "{exposure_s}"')
        patches.append((json.dumps({"exposure": {"time_s": exposure_s}}), "--exposure-s"))
    if cfa is not None:
        patches.append((json.dumps({"cfa": {"enabled": False} if cfa == "none" else {"enabled": True, "pattern": cfa}}), "--cfa"))
    if not noise:
        patches.append((json.dumps({"noise": {"enabled": False}}), "--no-noise"))
    if seed is not None:
        patches.append((json.dumps({"noise": {"seed": int(seed)}}), "--seed"))
    for key, value in (set or {}).items():
        patch: Any = value
        for part in reversed(key.split(".")):
            if not part:
                raise InputError(f"--set {key}={json.dumps(value)}: empty key in the path")
            patch = {part: patch}
        patches.append((json.dumps(patch), f"--set {key}={json.dumps(value)}"))
    with tempfile.TemporaryDirectory(prefix="chromatrace-") as scratch:
        path = _path(spectral)
        if path is None:
            path = os.path.join(scratch, "spectral.exr")
            write_spectral_exr(path, spectral, wavelengths_nm, band_edges_nm=band_edges_nm, reflective=illuminant is not None)
        out = os.fspath(output) if output is not None else os.path.join(scratch, "camera.exr")
        if not out.lower().endswith(".exr"):
            raise InputError(f"output: {out}: the Python module keeps the simulator's EXR (.exr), which holds every layer")
        report = _chromatrace.sensor_file(path, out, patches, config_file, illuminant or "", threads, 0)
        capture = _capture_from_exr(out, report)
        if mosaic:
            if not capture.settings["cfa"]["enabled"]:
                raise InputError('mosaic: the settings have no colour filter array (cfa.enabled is false): give cfa="RGGB" or another')
            dng = os.path.join(scratch, "mosaic.dng")
            _chromatrace.sensor_file(path, dng, patches, config_file, illuminant or "", threads, 0)
            raw = read_raw_mosaic(dng)
            capture.mosaic, capture.cfa_pattern = raw["mosaic"], raw["pattern"]
        return capture


# ----------------------------------------------------------------------------------------------------------------
# Calibration


def calibrate(flats: Sequence[Any], darks: Sequence[Any], *, photons_per_s: float | None = None,
              photons_per_pixel: Sequence[float] = (), encoding: str = "auto", wavelength_nm: float | None = None,
              camera: str = "", basis: str = "energy", pixel_um: float | None = None, temperature_c: float | None = None,
              report: str | os.PathLike | None = None) -> tuple[dict, dict]:
    """A camera's EMVA 1288 parameters from a photon-transfer series, as `chromatrace calibrate` measures them.

    flats, darks: frames, each a file (camera raw, or linear TIFF/PNG/EXR, with its EXIF exposure time) as --flat and
        --dark take them, or a pair (array, exposure time in seconds): a height x width array of one channel
        (monochrome) or height x width x 3 (R, G, B), of the camera's digital numbers, black level included. Arrays
        are named flats[i] and darks[i] in messages.
    encoding: what the files' values are (--input-transfer): "auto" or "linear".
    Returns (settings, estimates): the chromatrace-sensor/1 settings that sensor() and analyze(camera_config=…) take,
    and every estimate per channel with its standard error (the datasheet's calibration.json). report: also write
    the datasheet directory (index.html and its plots).
    """
    def split(frames: Sequence[Any], what: str) -> tuple[list[str], list[tuple[str, float, Any]]]:
        files, arrays = [], []
        for i, f in enumerate(frames):
            if _path(f) is not None:
                files.append(_path(f))
            elif isinstance(f, tuple) and len(f) == 2:
                arrays.append((f"{what}[{i}]", float(f[1]), np.asarray(f[0])))
            else:
                raise InputError(f"--{what[:-1]}: {what}[{i}] is neither a file nor a pair (array, exposure time in seconds)")
        return files, arrays

    flat_files, flat_arrays = split(flats, "flats")
    dark_files, dark_arrays = split(darks, "darks")
    settings, estimates = _chromatrace.calibrate_files(flat_files, dark_files, flat_arrays, dark_arrays, photons_per_s,
                                                       list(photons_per_pixel), encoding, wavelength_nm, camera, basis, pixel_um,
                                                       temperature_c, os.fspath(report) if report is not None else "")
    return json.loads(settings), json.loads(estimates)
