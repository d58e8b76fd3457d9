# SPDX-License-Identifier: Apache-2.0
# chromatrace.analyze against `chromatrace analyze`: the same analysis.json content and the same segment labels, on every
# test photograph, from its path and from its pixels as a NumPy array.
import json

import numpy as np
import OpenImageIO as oiio
import pytest

from conftest import DATA, command_error, photographs, run


def command_analysis(image, out, *options):
    run("analyze", image, "-o", out, "--no-plots", "--no-report", "--quiet", *options)
    labels = None
    if (out / "labels.png").exists():
        labels = read_pixels(out / "labels.png")[:, :, 0]
    return json.loads((out / "analysis.json").read_text()), labels


def read_pixels(path):
    """A file's pixels as a Python user loads them with OpenImageIO's Python module: integer files in their stored
    integers (uint8, uint16), float files as float32."""
    image = oiio.ImageInput.open(str(path))
    assert image, oiio.geterror()
    spec = image.spec()
    kind = {oiio.UINT8: "uint8", oiio.UINT16: "uint16"}.get(spec.format.basetype, "float")
    pixels = image.read_image(0, 0, 0, spec.nchannels, kind)
    image.close()
    return pixels


def without_curve_source(analysis: dict) -> dict:
    """The analysis without the words for where the curve came from: a file's metadata (its colour space, or that it
    names none) where an array has none."""
    out = json.loads(json.dumps(analysis))
    source = out["input"]["curve"]["source"]
    out["input"]["curve"]["source"] = "*"
    out["notes"] = [n.replace(source, "*") for n in out["notes"]]
    return out


@pytest.mark.parametrize("photo", photographs(), ids=lambda p: p.name)
def test_the_module_analyses_as_the_command(chromatrace, photo, tmp_path):
    expected, expected_labels = command_analysis(photo, tmp_path / "command", "--segment")
    from_path = chromatrace.analyze(photo, segment=True)
    assert from_path.data == expected
    assert from_path.labels.dtype == np.uint16 and from_path.labels.tobytes() == expected_labels.astype(np.uint16).tobytes()
    if photo.suffix.lower() == ".cr2":
        return  # a camera raw is no array of pixels: its values are what LibRaw's development makes of the mosaic
    pixels = read_pixels(photo)
    from_array = chromatrace.analyze(pixels, segment=True, name=str(photo))
    assert without_curve_source(from_array.data) == without_curve_source(expected)
    assert from_array.labels.tobytes() == from_path.labels.tobytes()
    # What the array's curve is said to come from.
    assert from_array.data["input"]["curve"]["source"] == (
        "an 8-bit array: sRGB, as cameras and phones store pictures" if pixels.dtype == np.uint8 else "a float array: linear")


def test_an_array_of_any_layout_or_type_is_read_as_its_values(chromatrace):
    """Strided, Fortran-ordered and float64 arrays give the analysis of the same values as a C-ordered float32 one."""
    rng = np.random.default_rng(5)
    base = rng.uniform(0.05, 1.0, size=(40, 60, 3)).astype(np.float32)
    reference = chromatrace.analyze(base).data
    assert chromatrace.analyze(np.asfortranarray(base)).data == reference
    assert chromatrace.analyze(base.astype(np.float64)).data == reference
    wide = np.zeros((40, 120, 3), np.float32)
    wide[:, ::2] = base
    assert chromatrace.analyze(wide[:, ::2]).data == reference
    flipped = chromatrace.analyze(np.ascontiguousarray(base[::-1, :, ::-1])).data
    assert chromatrace.analyze(base[::-1, :, ::-1]).data == flipped  # negative strides


def test_an_alpha_channel_sets_pixels_aside_as_a_files_does(chromatrace, tmp_path):
    pixels = read_pixels(DATA / "photos" / "smarties.png")
    alpha = np.full(pixels.shape[:2] + (1,), 255, np.uint8)
    alpha[:100, :150] = 0
    rgba = np.ascontiguousarray(np.concatenate([pixels, alpha], axis=2))
    path = tmp_path / "rgba.png"
    out = oiio.ImageOutput.create(str(path))
    spec = oiio.ImageSpec(rgba.shape[1], rgba.shape[0], 4, oiio.UINT8)
    spec.alpha_channel = 3
    out.open(str(path), spec)
    out.write_image(rgba)
    out.close()
    expected, _ = command_analysis(path, tmp_path / "command")
    got = chromatrace.analyze(rgba, name=str(path))
    assert without_curve_source(got.data) == without_curve_source(expected)
    assert got.region(0)["valid_pixels"] == rgba.shape[0] * rgba.shape[1] - 100 * 150
    assert "alpha channel A: 15000 fully transparent pixels left out of every region" in got.data["notes"]


def test_labels_and_masks_as_arrays_are_the_files_regions(chromatrace, tmp_path):
    photo = DATA / "photos" / "smarties.png"
    pixels = read_pixels(photo)
    height, width = pixels.shape[:2]
    labels = np.zeros((height, width), np.uint16)
    labels[50:150, 60:200] = 3
    labels[200:300, 100:300] = 7
    mask = np.zeros((height, width), np.uint8)
    mask[10:90, 250:400] = 255
    for name, array in (("labels.png", labels), ("cup.png", mask)):
        out = oiio.ImageOutput.create(str(tmp_path / name))
        out.open(str(tmp_path / name), oiio.ImageSpec(width, height, 1, oiio.UINT16 if array.dtype == np.uint16 else oiio.UINT8))
        out.write_image(np.ascontiguousarray(array[:, :, None]))
        out.close()
    expected, _ = command_analysis(photo, tmp_path / "command", "--labels", tmp_path / "labels.png", "--mask", tmp_path / "cup.png",
                                   "--rect", "5,5,40,30")
    got = chromatrace.analyze(photo, labels=labels, mask={"cup.png": mask}, rects=[(5, 5, 40, 30)])
    assert got.data == expected
    assert [r["name"] for r in got.regions] == ["image", "label 3", "label 7", "mask cup.png", "rect 5,5 40x30"]
    assert got.region("mask cup.png")["pixels"] == int((mask != 0).sum())


def test_refusals_raise_the_commands_message(chromatrace, tmp_path):
    photo = DATA / "photos" / "smarties.png"
    missing = tmp_path / "missing.png"
    cases = [
        (dict(image=missing), ["analyze", missing, "-o", tmp_path / "a"]),
        (dict(image=photo, encoding="gamma=-1"), ["analyze", photo, "-o", tmp_path / "b", "--input-transfer", "gamma=-1"]),
        (dict(image=photo, layer="diffuse"), ["analyze", photo, "-o", tmp_path / "c", "--layer", "diffuse"]),
        (dict(image=photo, mask=tmp_path / "nothing.png"), ["analyze", photo, "-o", tmp_path / "d", "--mask", tmp_path / "nothing.png"]),
        (dict(image=photo, rects=["1,2,3"]), ["analyze", photo, "-o", tmp_path / "e", "--rect", "1,2,3"]),
        # Options are checked before the image is read, as the command checks them.
        (dict(image=missing, bins=1), ["analyze", missing, "-o", tmp_path / "f", "--bins", "1"]),
        (dict(image=np.zeros((2, 2)), segment=True, segment_min_area=2.0),
         ["analyze", missing, "-o", tmp_path / "g", "--segment", "--segment-min-area", "2"]),
    ]
    for kwargs, command in cases:
        with pytest.raises(chromatrace.InputError) as raised:
            chromatrace.analyze(kwargs.pop("image"), **kwargs)
        assert isinstance(raised.value, ValueError)
        if command is not None:
            assert str(raised.value) == command_error(*command)
    with pytest.raises(chromatrace.InputError,
                       match=r"^array: an image array is height × width × 3 \(R, G, B\) or × 4 \(R, G, B, A\), got shape \(4, 4\)$"):
        chromatrace.analyze(np.zeros((4, 4), np.uint8))
    with pytest.raises(chromatrace.InputError, match="^array: samples of type int16; uint8, uint16, uint32, float32 or float64$"):
        chromatrace.analyze(np.zeros((4, 4, 3), np.int16))
    # A broadcast view is any size for free; the file readers' limits hold before any memory is taken.
    with pytest.raises(chromatrace.InputError, match=r"^array: image of 70000x60000 pixels, more than the limit of 2\^30"):
        chromatrace.analyze(np.broadcast_to(np.uint8(7), (60000, 70000, 3)))
    with pytest.raises(chromatrace.InputError, match=r"^array: image of 20000x15000 pixels, 3 channels: needs 3.6 GB as floats"):
        chromatrace.analyze(np.broadcast_to(np.uint8(7), (15000, 20000, 3)))
    with pytest.raises(chromatrace.InputError, match="^array: no valid pixel: 0 transparent, 16 negative, 0 NaN or infinite$"):
        chromatrace.analyze(-np.ones((4, 4, 3), np.float32))


def test_the_analysis_writes_what_the_command_writes(chromatrace, tmp_path):
    photo = DATA / "photos" / "smarties.png"
    run("analyze", photo, "-o", tmp_path / "command", "--segment", "--quiet")
    chromatrace.analyze(photo, segment=True).write(tmp_path / "module")
    written = sorted(p.relative_to(tmp_path / "command") for p in (tmp_path / "command").rglob("*"))
    assert written == sorted(p.relative_to(tmp_path / "module") for p in (tmp_path / "module").rglob("*"))
    for p in written:
        if (tmp_path / "command" / p).is_file():
            assert (tmp_path / "command" / p).read_bytes() == (tmp_path / "module" / p).read_bytes(), p
