# SPDX-License-Identifier: GPL-3.0-or-later
"""The cameras Analyze Histogram can see a render through, by name: the sensor (`chromatrace sensor --preset`:
pixel, noise, ADC) and the spectral response (`--camera`: the 17 camera curves chromatrace ships, or the CIE 1931
observer). Lists, not free text, so that a name cannot be mistyped (tests/blender/unit checks them against
sensor_sim/cameras/ and docs/sensor.md)."""

# (id, name) of every shipped camera curve (sensor_sim/cameras/README.md), then the ideal XYZ observer.
CURVES = [
    ("canon_eos_100d", "Canon EOS 100D"),
    ("canon_eos_1dx_mkii", "Canon EOS-1D X Mark II"),
    ("canon_eos_200d", "Canon EOS 200D"),
    ("canon_eos_200d_mkii", "Canon EOS 200D Mark II"),
    ("canon_eos_5d", "Canon EOS 5D"),
    ("canon_eos_5d_mkii", "Canon EOS 5D Mark II"),
    ("canon_eos_5d_mkiii", "Canon EOS 5D Mark III"),
    ("canon_eos_5d_mkiv", "Canon EOS 5D Mark IV"),
    ("canon_eos_5ds", "Canon EOS 5DS"),
    ("canon_eos_m", "Canon EOS M"),
    ("hasselblad_l1d_20c", "Hasselblad L1D-20c (DJI Mavic 2 Pro)"),
    ("nikon_d810", "Nikon D810"),
    ("nikon_d850", "Nikon D850"),
    ("sony_ilce_6400", "Sony α6400 (ILCE-6400)"),
    ("sony_ilce_7m3", "Sony α7 III (ILCE-7M3)"),
    ("sony_ilce_7rm3", "Sony α7R III (ILCE-7RM3)"),
    ("sony_ilce_9", "Sony α9 (ILCE-9)"),
    ("cie1931", "CIE 1931 observer (an ideal XYZ camera)"),
]

# (id, name, what) of the sensor presets (docs/sensor.md, "Presets").
SENSORS = [
    ("canon_eos_5d_mkiii", "Canon EOS 5D Mark III sensor", "6.25 µm pixels, 14 bits, read noise 33 e⁻ (ISO 100)"),
    ("machine_vision_ccd", "Machine-vision CCD", "6.45 µm pixels, 12 bits, read noise 8 e⁻"),
    ("smartphone", "Smartphone sensor", "1.4 µm pixels behind f/1.8, 10 bits, read noise 2 e⁻"),
    ("ideal", "Ideal sensor", "no noise, no clipping, no mosaic"),
]


def curve_items():
    """EnumProperty items of the camera curves."""
    return [(key, name, f"The spectral response of the {name} (chromatrace sensor --camera {key})")
            for key, name in CURVES]


def sensor_items():
    """EnumProperty items of the sensor presets."""
    return [(key, name, f"{what} (chromatrace sensor --preset {key})") for key, name, what in SENSORS]
