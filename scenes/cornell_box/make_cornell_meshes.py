#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes meshes/*.ply: the Cornell Box geometry in chromatrace's frame (metres, Z up, right-handed).

Source: the Cornell University Program of Computer Graphics "Cornell Box Data" as reproduced by
mitsuba-renderer/mitsuba-data (commit 01100fa9b0b154492061a92404f26dcd7b784dbb, scenes/cbox/meshes/*.obj),
in mm, +y up, camera looking along +z. Each quad is kept as one PLY face with its corners in the source
order, so the fan split (c1,c2,c3),(c1,c3,c4) is the source's own pair of triangles and the faces keep the
source's facing (walls into the box, blocks outward).

Frame change (a rotation plus a shift, so handedness is kept; determinant +1):
  X = (278 - x) / 1000,  Y = z / 1000,  Z = y / 1000
The camera (x = 278) ends up on X = 0 looking along +Y, the floor on Z = 0, and the red wall (x ~ 550) at
X ~ -0.275, on the viewer's left as in the source. Left out: the ceiling's second face, a copy of the
light-sized patch lying in the ceiling plane (it is hidden behind the luminaire and would only overlap the
ceiling's first face). Run from this folder: python3 make_cornell_meshes.py
"""

QUADS = {
    "floor": [[(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)]],
    "ceiling": [[(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)]],
    "back_wall": [[(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)]],
    "red_wall": [[(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)]],
    "green_wall": [[(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)]],
    "short_block": [
        [(130, 165, 65), (82, 165, 225), (240, 165, 272), (290, 165, 114)],
        [(290, 0, 114), (290, 165, 114), (240, 165, 272), (240, 0, 272)],
        [(130, 0, 65), (130, 165, 65), (290, 165, 114), (290, 0, 114)],
        [(82, 0, 225), (82, 165, 225), (130, 165, 65), (130, 0, 65)],
        [(240, 0, 272), (240, 165, 272), (82, 165, 225), (82, 0, 225)],
        [(290, 0, 114), (240, 0, 272), (82, 0, 225), (130, 0, 65)],
    ],
    "tall_block": [
        [(423, 330, 247), (265, 330, 296), (314, 330, 456), (472, 330, 406)],
        [(423, 0, 247), (423, 330, 247), (472, 330, 406), (472, 0, 406)],
        [(472, 0, 406), (472, 330, 406), (314, 330, 456), (314, 0, 456)],
        [(314, 0, 456), (314, 330, 456), (265, 330, 296), (265, 0, 296)],
        [(265, 0, 296), (265, 330, 296), (423, 330, 247), (423, 0, 247)],
        [(472, 0, 406), (314, 0, 456), (265, 0, 296), (423, 0, 247)],
    ],
}


def to_chromatrace(p):
    x, y, z = p
    return ((278 - x) / 1000, z / 1000, y / 1000)


def number(v):
    text = f"{v:.4f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


for name, quads in QUADS.items():
    vertices = [to_chromatrace(p) for quad in quads for p in quad]
    lines = ["ply", "format ascii 1.0",
             "comment Cornell Box " + name + ", from the Cornell Program of Computer Graphics data via mitsuba-data;",
             "comment metres, Z up: (X, Y, Z) = ((278 - x) / 1000, z / 1000, y / 1000). See ../README.md.",
             f"element vertex {len(vertices)}", "property float x", "property float y", "property float z",
             f"element face {len(quads)}", "property list uchar int vertex_indices", "end_header"]
    lines += [" ".join(number(c) for c in v) for v in vertices]
    lines += [f"4 {4 * i} {4 * i + 1} {4 * i + 2} {4 * i + 3}" for i in range(len(quads))]
    with open(f"meshes/{name}.ply", "w", encoding="utf-8", newline="\n") as out:
        out.write("\n".join(lines) + "\n")
