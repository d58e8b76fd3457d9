// SPDX-License-Identifier: Apache-2.0
#pragma once
// PLY triangle meshes (Greg Turk's polygon file format), the mesh format of chromatrace scenes.
//
// Reading: `format ascii 1.0` and `format binary_little_endian 1.0`. The `vertex` element must have
// properties x, y, z and may have nx, ny, nz (all three; normalised on reading) and texture coordinates u, v
// (or s, t, texture_u, texture_v, texture_s, texture_t; both of a pair); the `face` element needs a
// list property `vertex_indices` (or `vertex_index`). Polygons are split into triangles as a fan from their
// first vertex, which keeps the winding and so the facing. Every other element and property is skipped.
// Writing: x y z (and nx ny nz when the mesh has normals, u v when it has texture coordinates) as doubles, so that reading back gives the
// same numbers, and faces as `property list uchar int vertex_indices`.

#include <filesystem>
#include <string>
#include <string_view>

#include "core/geometry.h"

namespace ct {

enum class PlyFormat { Ascii, BinaryLittleEndian };

// Parses PLY bytes; errors are InputErrors naming `source` and the place ("bunny.ply: face 12: ...").
TriangleMesh parse_ply(std::string_view bytes, const std::string& source);
TriangleMesh read_ply(const std::filesystem::path& file);

std::string format_ply(const TriangleMesh& mesh, PlyFormat format);
// Writes through a temporary file renamed into place, so a failed write never leaves a partial file.
void write_ply(const std::filesystem::path& file, const TriangleMesh& mesh, PlyFormat format);

}  // namespace ct
