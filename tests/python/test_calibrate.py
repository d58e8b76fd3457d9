# SPDX-License-Identifier: Apache-2.0
# chromatrace.calibrate on frames as files and as arrays, against the command and the camera the frames were drawn from.
import json

import numpy as np
import OpenImageIO as oiio
import pytest

from conftest import command_error, run

# A monochrome camera of known parameters (EMVA 1288's linear model): photons → electrons (η, Poisson), a full well,
# read noise, the gain K, a black level, 12 bits.
ETA, K, READ_E, WELL_E, BLACK_DN, BITS = 0.6, 0.25, 3.0, 12000.0, 64, 12
PHOTONS_PER_S = 1.0e6
# Times of three significant digits: a file records them as a float (EXIF), which the calibration reads back as the
# shortest decimal that float is, so that files and arrays give the same times to the last bit.
TIMES = [float(f"{t:.3g}") for t in np.geomspace(1e-4, 0.03, 14)]


def frames(seed=11, size=(48, 64)):
    """Two flats and two darks per exposure time, as (array, time) pairs."""
    rng = np.random.default_rng(seed)
    flats, darks = [], []
    for t in TIMES:
        for _ in range(2):
            electrons = np.minimum(rng.poisson(ETA * PHOTONS_PER_S * t, size), WELL_E)
            flats.append((np.clip(np.round(BLACK_DN + K * (electrons + rng.normal(0, READ_E, size))), 0, 2**BITS - 1).astype(np.uint16), t))
            darks.append((np.clip(np.round(BLACK_DN + K * rng.normal(0, READ_E, size)), 0, 2**BITS - 1).astype(np.uint16), t))
    return flats, darks


def write_tiff(path, array, exposure_s):
    spec = oiio.ImageSpec(array.shape[1], array.shape[0], 1, "uint16")
    spec.attribute("ExposureTime", float(exposure_s))
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), oiio.geterror()
    out.write_image(np.ascontiguousarray(array[:, :, None]))
    out.close()


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    directory = tmp_path_factory.mktemp("series")
    flats, darks = frames()
    names = {}
    for kind, items in (("flat", flats), ("dark", darks)):
        names[kind] = []
        for i, (array, t) in enumerate(items):
            names[kind].append(directory / f"{kind}-{i:02d}.tif")
            write_tiff(names[kind][-1], array, t)
    return flats, darks, names, directory


def test_files_and_arrays_give_the_commands_calibration(chromatrace, series):
    flats, darks, names, directory = series
    run("calibrate", "--flat", *names["flat"], "--dark", *names["dark"], "--photons-per-s", PHOTONS_PER_S,
        "-o", directory / "camera.json", "--quiet")
    expected = json.loads((directory / "camera.json").read_text())
    settings, estimates = chromatrace.calibrate(names["flat"], names["dark"], photons_per_s=PHOTONS_PER_S)
    assert settings == expected
    from_arrays, array_estimates = chromatrace.calibrate(flats, darks, photons_per_s=PHOTONS_PER_S)
    assert from_arrays == expected
    assert array_estimates["channels"] == estimates["channels"]


def test_the_calibration_finds_the_camera_the_frames_came_from(chromatrace, series):
    flats, darks, _, _ = series
    settings, estimates = chromatrace.calibrate(flats, darks, photons_per_s=PHOTONS_PER_S)
    channel = estimates["channels"][0]
    for key, truth in (("gain_dn_per_e", K), ("dark_noise_e", READ_E), ("quantum_efficiency", ETA)):
        e = channel[key]
        assert abs(e["value"] - truth) <= 3 * e["standard_error"], (key, e, truth)
    assert settings["adc"]["gain_dn_per_e"] == pytest.approx(channel["gain_dn_per_e"]["value"])


def test_calibration_refusals_raise_the_commands_message(chromatrace, series, tmp_path):
    flats, darks, names, _ = series
    with pytest.raises(chromatrace.InputError) as raised:
        chromatrace.calibrate(names["flat"][:1], names["dark"])
    assert str(raised.value) == command_error("calibrate", "--flat", names["flat"][0], "--dark", *names["dark"], "-o", tmp_path / "c.json")
    with pytest.raises(chromatrace.InputError, match=r"^flats\[0\]: channel 0 holds 0.5 at pixel \(0, 0\), not a whole number"):
        chromatrace.calibrate([(np.full((8, 8), 0.5), 0.01)] + flats[1:], darks)
    with pytest.raises(chromatrace.InputError, match=r"^flats\[0\]: the exposure time must be a positive number of seconds, got -1"):
        chromatrace.calibrate([(flats[0][0], -1)] + flats[1:], darks)
