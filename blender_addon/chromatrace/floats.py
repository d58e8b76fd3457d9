# SPDX-License-Identifier: GPL-3.0-or-later
"""Numbers through Blender's single-precision properties (pure Python).

Blender keeps float properties in 32 bits: 0.1 comes back as 0.10000000149011612. Writing the shortest
decimal that gives the same 32-bit float restores what was typed or imported (0.1) for every number of up
to 7 significant digits, so import followed by export gives the scene file's numbers back.
"""

import struct


def _as_float32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def short_float(value):
    value = float(value)
    try:
        target = _as_float32(value)
    except OverflowError:  # beyond float32: it did not come from a Blender property
        return value
    for digits in range(1, 10):
        candidate = float(f"{value:.{digits}g}")
        if _as_float32(candidate) == target:
            return int(candidate) if candidate.is_integer() and abs(candidate) < 2 ** 53 else candidate
    return value
