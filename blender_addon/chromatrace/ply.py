# SPDX-License-Identifier: GPL-3.0-or-later
"""PLY triangle meshes, the subset chromatrace uses (pure Python, no bpy; docs/scene-format.md, "PLY meshes").

Reads `format ascii 1.0` and `binary_little_endian 1.0` with vertex x, y, z (and nx, ny, nz; and texture
coordinates u, v or s, t, texture_u, texture_v, texture_s, texture_t) and a face list `vertex_indices` (or
`vertex_index`), splitting polygons into fans from their first vertex, as core/ply.cpp does. Writes what core's
write_ply writes: binary little-endian, x y z [nx ny nz] [u v] as doubles and faces as
`property list uchar int vertex_indices`, so `chromatrace` reads the add-on's meshes unchanged.
"""

import struct

_TYPES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h", "ushort": "H", "uint16": "H",
    "int": "i", "int32": "i", "uint": "I", "uint32": "I", "float": "f", "float32": "f", "double": "d", "float64": "d",
}


_UV_NAMES = (("u", "v"), ("s", "t"), ("texture_u", "texture_v"), ("texture_s", "texture_t"))


class PlyError(ValueError):
    pass


class Mesh:
    """positions: [(x, y, z)]; normals: [] or one unit (nx, ny, nz) per position; triangles: [(a, b, c)];
    uvs: [] or one (u, v) per position."""

    def __init__(self, positions=None, normals=None, triangles=None, uvs=None):
        self.positions = positions or []
        self.normals = normals or []
        self.triangles = triangles or []
        self.uvs = uvs or []


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    return parse_ply(data, str(path))


def parse_ply(data, source="mesh"):
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise PlyError(f"{source}: not a PLY file")
    body_start = data.index(b"\n", end) + 1
    elements, fmt = [], None
    for line in data[:end].decode("ascii", "replace").splitlines()[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            if words[1] == "list":
                elements[-1][2].append((words[4], _TYPES[words[2]], _TYPES[words[3]]))
            else:
                elements[-1][2].append((words[2], _TYPES[words[1]], None))
    if fmt not in ("ascii", "binary_little_endian"):
        raise PlyError(f"{source}: format {fmt} not supported (ascii or binary_little_endian)")
    rows = _read_ascii(data[body_start:], elements) if fmt == "ascii" else _read_binary(data, body_start, elements)

    mesh = Mesh()
    vertices = rows.get("vertex", ([], []))
    names = vertices[0]
    index = {n: i for i, n in enumerate(names)}
    if not all(k in index for k in ("x", "y", "z")):
        raise PlyError(f"{source}: vertex element needs x, y, z")
    has_normals = all(k in index for k in ("nx", "ny", "nz"))
    uv = next(((u, v) for u, v in _UV_NAMES if u in index or v in index), None)
    if uv is not None and not (uv[0] in index and uv[1] in index):
        raise PlyError(f"{source}: vertex element has only one of {uv[0]}, {uv[1]}")
    for row in vertices[1]:
        if uv is not None:
            mesh.uvs.append((row[index[uv[0]]], row[index[uv[1]]]))
        mesh.positions.append((row[index["x"]], row[index["y"]], row[index["z"]]))
        if has_normals:
            n = (row[index["nx"]], row[index["ny"]], row[index["nz"]])
            length = (n[0] ** 2 + n[1] ** 2 + n[2] ** 2) ** 0.5 or 1.0
            mesh.normals.append((n[0] / length, n[1] / length, n[2] / length))
    faces = rows.get("face", ([], []))
    face_index = next((i for i, n in enumerate(faces[0]) if n in ("vertex_indices", "vertex_index")), None)
    if face_index is None:
        raise PlyError(f"{source}: face element needs a vertex_indices list")
    for row in faces[1]:
        polygon = row[face_index]
        for i in range(1, len(polygon) - 1):
            mesh.triangles.append((polygon[0], polygon[i], polygon[i + 1]))
    return mesh


def _read_ascii(body, elements):
    tokens = iter(body.decode("ascii").split())
    rows = {}
    for name, count, props in elements:
        out = []
        for _ in range(count):
            row = []
            for _prop, vtype, itype in props:
                if itype is None:
                    row.append(_number(next(tokens), vtype))
                else:
                    n = int(next(tokens))
                    row.append([_number(next(tokens), itype) for _ in range(n)])
            out.append(row)
        rows[name] = ([p[0] for p in props], out)
    return rows


def _number(text, code):
    return float(text) if code in "fd" else int(text)


def _read_binary(data, offset, elements):
    rows = {}
    for name, count, props in elements:
        out = []
        simple = all(p[2] is None for p in props)
        if simple:
            layout = struct.Struct("<" + "".join(p[1] for p in props))
            for _ in range(count):
                out.append(list(layout.unpack_from(data, offset)))
                offset += layout.size
        else:
            for _ in range(count):
                row = []
                for _prop, vtype, itype in props:
                    if itype is None:
                        (v,) = struct.unpack_from("<" + vtype, data, offset)
                        offset += struct.calcsize(vtype)
                        row.append(v)
                    else:
                        (n,) = struct.unpack_from("<" + vtype, data, offset)
                        offset += struct.calcsize(vtype)
                        row.append(list(struct.unpack_from(f"<{n}{itype}", data, offset)))
                        offset += n * struct.calcsize(itype)
                out.append(row)
        rows[name] = ([p[0] for p in props], out)
    return rows


def format_ply(mesh):
    """The bytes of a binary little-endian PLY of `mesh`, laid out as core/ply.cpp writes it."""
    smooth = bool(mesh.normals)
    header = ["ply", "format binary_little_endian 1.0", "comment written by chromatrace", f"element vertex {len(mesh.positions)}",
              "property double x", "property double y", "property double z"]
    if smooth:
        header += ["property double nx", "property double ny", "property double nz"]
    if mesh.uvs:
        header += ["property double u", "property double v"]
    header += [f"element face {len(mesh.triangles)}", "property list uchar int vertex_indices", "end_header"]
    parts = [("\n".join(header) + "\n").encode("ascii")]
    vertex = struct.Struct(f"<{3 + (3 if smooth else 0) + (2 if mesh.uvs else 0)}d")
    for i, p in enumerate(mesh.positions):
        parts.append(vertex.pack(*p, *(mesh.normals[i] if smooth else ()), *(mesh.uvs[i] if mesh.uvs else ())))
    face = struct.Struct("<B3i")
    parts.extend(face.pack(3, *t) for t in mesh.triangles)
    return b"".join(parts)


def write_ply(path, mesh):
    with open(path, "wb") as f:
        f.write(format_ply(mesh))
