#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes synthetic_reflectances.csv: smooth reflectance curves made up for chromatrace's scenes.

They are not measurements. Each is one of three shapes, lo and hi being the reflectance far from and at the
feature, over 380-780 nm every 5 nm, rounded to 4 decimals:
  long-pass  lo + (hi - lo) / (1 + exp(-(nm - centre) / width))   (reds, yellows: reflect long wavelengths)
  short-pass lo + (hi - lo) / (1 + exp((nm - centre) / width))    (blues)
  notch      hi - (hi - lo) * exp(-((nm - centre) / width)**2 / 2) (magenta: absorbs the middle)
Run it from this folder: python3 make_synthetic_reflectances.py
"""
import math

CURVES = [
    # name,        shape,        lo,   hi,   centre, width
    ("white_paint", "long-pass", 0.70, 0.82, 430.0, 15.0),
    ("beige",       "long-pass", 0.30, 0.58, 560.0, 40.0),
    ("pale_blue",   "short-pass", 0.25, 0.65, 540.0, 30.0),
    ("yellow",      "long-pass", 0.06, 0.75, 520.0, 18.0),
    ("magenta",     "notch",     0.08, 0.70, 545.0, 40.0),
]


def value(shape, lo, hi, centre, width, nm):
    if shape == "long-pass":
        return lo + (hi - lo) / (1.0 + math.exp(-(nm - centre) / width))
    if shape == "short-pass":
        return lo + (hi - lo) / (1.0 + math.exp((nm - centre) / width))
    return hi - (hi - lo) * math.exp(-0.5 * ((nm - centre) / width) ** 2)


with open("synthetic_reflectances.csv", "w", encoding="utf-8", newline="\n") as out:
    out.write("wavelength_nm," + ",".join(c[0] for c in CURVES) + "\n")
    for nm in range(380, 781, 5):
        out.write(f"{nm}," + ",".join(f"{value(*c[1:], nm):.4f}" for c in CURVES) + "\n")
