# SPDX-License-Identifier: Apache-2.0
# chromatrace.sensor, read_spectral_exr and write_spectral_exr against the command and the files' known contents.
import json
import subprocess
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from conftest import DATA, SOURCE, command_error, run

SAMPLES = DATA / "spectral_exr_samples"


def exr_layers(path):
    """Every channel of an EXR by name (OpenImageIO's Python module), and its attributes."""
    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    spec = image.spec()
    pixels = image.read_image(0, 0, 0, spec.nchannels, "float")
    image.close()
    return {name: pixels[:, :, i] for i, name in enumerate(spec.channelnames)}, {a.name: a.value for a in spec.extra_attribs}


def test_a_spectral_file_is_read_as_its_bands(chromatrace):
    d65 = chromatrace.read_spectral_exr(SAMPLES / "spectral-exr_D65_emissive.exr")
    assert d65["kind"] == "spectral emissive"
    assert d65["S0"].shape == (1, 1, 90) and d65["S0"].dtype == np.float32
    assert d65["wavelengths_nm"][0] == 380 and d65["wavelengths_nm"][-1] == 825
    # The file holds CIE D65 (ISO 11664-2, the table in core/data) at its band centres.
    table = dict(tuple(map(float, line.split(","))) for line in (SOURCE / "core/data/illuminants/D65.csv").read_text().splitlines()
                 if line[:1].isdigit())
    assert list(d65["S0"][0, 0]) == pytest.approx([table[nm] for nm in d65["wavelengths_nm"]], abs=1e-4)
    macbeth = chromatrace.read_spectral_exr(SAMPLES / "spectral-exr_Macbeth_reflective.exr")
    assert macbeth["kind"] == "spectral reflective" and macbeth["T"].shape == (400, 600, 36)
    assert macbeth["band_edges_nm"][0] == 375 and macbeth["band_edges_nm"][-1] == 735
    assert 0 <= macbeth["T"].min() and macbeth["T"].max() <= 1


def test_written_arrays_read_back_as_they_were(chromatrace, tmp_path):
    rng = np.random.default_rng(3)
    total = rng.uniform(0, 2, size=(7, 5, 4)).astype(np.float32)
    diffuse = (total * 0.25).astype(np.float32)
    ids = rng.integers(0, 3, size=(7, 5))
    path = tmp_path / "cube.exr"
    chromatrace.write_spectral_exr(path, total, [450, 500, 550, 600], components={"diffuse_direct": diffuse}, object_ids=ids,
                                   object_names={1: "ball", 2: "floor"}, attributes={"chromatrace.renderer": "numpy"})
    back = chromatrace.read_spectral_exr(path)
    assert np.array_equal(back["S0"], total) and np.array_equal(back["components"]["diffuse_direct"]["S0"], diffuse)
    assert np.array_equal(back["object_ids"], ids) and back["object_names"] == {1: "ball", 2: "floor"}
    assert back["band_edges_nm"] == [425, 475, 525, 575, 625]
    assert back["metadata"]["chromatrace.renderer"] == "numpy"
    # The command reads it as the module wrote it.
    assert "4 bands, 425-625 nm" in run("info", path).stdout


def test_the_camera_on_an_array_is_the_command_on_its_file(chromatrace, tmp_path):
    macbeth = chromatrace.read_spectral_exr(SAMPLES / "spectral-exr_Macbeth_reflective.exr")
    reflectance = macbeth["T"][::4, ::4]  # 150 x 100 pixels
    written = tmp_path / "macbeth.exr"
    chromatrace.write_spectral_exr(written, reflectance, band_edges_nm=macbeth["band_edges_nm"], reflective=True)
    settings = {"noise": {"read_e": 4}, "adc": {"bits": 12}}
    (tmp_path / "camera.json").write_text(json.dumps(settings))
    run("sensor", written, "-o", tmp_path / "command.exr", "--illuminant", "D65", "--preset", "canon_eos_5d_mkiii",
        "--config", tmp_path / "camera.json", "--seed", "7", "--set", "noise.dsnu_e=2", "--exposure-s", "auto", "--cfa", "GRBG",
        "--quiet")
    expected, attributes = exr_layers(tmp_path / "command.exr")
    for source in (written, reflectance):
        capture = chromatrace.sensor(source, settings, preset="canon_eos_5d_mkiii", band_edges_nm=macbeth["band_edges_nm"],
                                     illuminant="D65", seed=7, set={"noise.dsnu_e": 2}, exposure_s="auto", cfa="GRBG")
        assert capture.signal == "DN" == attributes["chromatrace.signal"]
        assert capture.rgb.shape == (100, 150, 3)
        for k, c in enumerate("RGB"):
            assert np.array_equal(capture.rgb[:, :, k], expected[c]), c
            assert np.array_equal(capture.linear[:, :, k], expected["linear." + c])
            assert np.array_equal(capture.display[:, :, k], expected["display." + c])
        assert capture.metadata["chromatrace.black_level"] == attributes["chromatrace.black_level"]
        assert capture.settings["noise"]["read_e"] == 4 and capture.settings["noise"]["dsnu_e"] == 2
        assert capture.settings["adc"]["bits"] == 12 and capture.settings["noise"]["seed"] == 7
        assert capture.settings["cfa"]["pattern"] == "GRBG" and capture.exposure_s != 0.01  # the preset's time, replaced


def test_camera_refusals_raise_the_commands_message(chromatrace, tmp_path):
    d65 = SAMPLES / "spectral-exr_D65_emissive.exr"
    for kwargs, options in (({"preset": "pinhole"}, ["--preset", "pinhole"]),
                            ({"set": {"noise.read_e": -1}}, ["--set", "noise.read_e=-1"]),
                            ({"illuminant": "D66"}, ["--illuminant", "D66"])):
        with pytest.raises(chromatrace.InputError) as raised:
            chromatrace.sensor(d65, **kwargs)
        message = command_error("sensor", d65, "-o", tmp_path / "out.exr", *options)
        assert str(raised.value) == message
    with pytest.raises(chromatrace.InputError, match="^wavelengths_nm: 3 centres for 4 bands in the array$"):
        chromatrace.sensor(np.ones((2, 2, 4), np.float32), wavelengths_nm=[400, 500, 600])


def dcraw_mosaic(raw, tmp_path):
    """dcraw's own reading of a raw file's mosaic (-D: no scaling, no interpolation; -4: 16 bits), an independent
    reader."""
    out = tmp_path / (raw.stem + "-dcraw.tiff")
    with open(out, "wb") as f:
        subprocess.run(["dcraw", "-D", "-4", "-T", "-c", str(raw)], stdout=f, check=True)
    image = oiio.ImageInput.open(str(out))
    pixels = image.read_image(0, 0, 0, 1, "uint16")[:, :, 0]
    image.close()
    return pixels


def test_a_camera_raws_mosaic_is_read_as_dcraw_reads_it(chromatrace, tmp_path):
    raw = Path("/usr/share/doc/rawtran/IMG_5952.CR2")
    m = chromatrace.read_raw_mosaic(raw)
    assert m["pattern"] == "RGGB" and m["mosaic"].dtype == np.uint16 and m["mosaic"].shape == (2348, 3522)
    assert np.array_equal(m["mosaic"], dcraw_mosaic(raw, tmp_path))
    with pytest.raises(chromatrace.InputError) as raised:
        chromatrace.read_raw_mosaic(SAMPLES / "spectral-exr_D65_emissive.exr")
    assert "LibRaw" in str(raised.value)


def test_the_cameras_mosaic_is_the_commands_dng(chromatrace, tmp_path):
    source = SAMPLES / "spectral-exr_Macbeth_reflective.exr"
    run("sensor", source, "-o", tmp_path / "command.dng", "--illuminant", "D65", "--preset", "canon_eos_5d_mkiii",
        "--exposure-s", "auto", "--cfa", "BGGR", "--seed", "3", "--quiet")
    capture = chromatrace.sensor(source, preset="canon_eos_5d_mkiii", illuminant="D65", exposure_s="auto", cfa="BGGR", seed=3,
                                 mosaic=True)
    assert capture.cfa_pattern == "BGGR" and capture.mosaic.shape == capture.rgb.shape[:2]
    assert np.array_equal(capture.mosaic, dcraw_mosaic(tmp_path / "command.dng", tmp_path))
    with pytest.raises(chromatrace.InputError, match="^mosaic: the settings have no colour filter array"):
        chromatrace.sensor(source, illuminant="D65", preset="ideal", mosaic=True)
