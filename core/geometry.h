// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one geometry representation that the reference tracer and the exporters share: world-space triangle
// meshes, and the analytic shapes of the scene format with the exact rule that turns each into triangles.
//
// Conventions (docs/scene-format.md, "Geometry"): lengths in metres, Z-up, right-handed. A triangle
// (a, b, c) faces the side of its geometric normal (b - a) × (c - a); closed shapes are tessellated with
// these normals pointing outward, and a quad's normal is edge1 × edge2.

#include <array>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ct {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

inline constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;

struct TriangleMesh {
  std::vector<Vec3> positions;
  // Empty (flat shading: use the geometric normal) or one unit normal per position (smooth shading).
  std::vector<Vec3> normals;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  // Empty or one texture coordinate (u, v) per position (a PLY mesh's u, v or s, t properties).
  std::vector<Vec2> uvs;

  bool operator==(const TriangleMesh&) const = default;
};

// Unit geometric normal (b - a) × (c - a) of triangle `t`; zero for a degenerate triangle.
Vec3 face_normal(const TriangleMesh& mesh, std::size_t t);
double triangle_area(const TriangleMesh& mesh, std::size_t t);
double surface_area(const TriangleMesh& mesh);

struct Bounds {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  bool empty() const { return !(lo.array() <= hi.array()).all(); }
  void extend(const Vec3& p);
  void extend(const Bounds& b);
};
Bounds bounds(const TriangleMesh& mesh);

// ---- Analytic shapes --------------------------------------------------------------------------------

// The default tessellation (scene format "render.tessellation"): spheres and cylinders get 64 segments
// around, spheres half as many rings from pole to pole. The relative area error is then 0.2 % for a
// sphere, 0.04 % for a cylinder's side and 0.16 % for its caps.
inline constexpr int kDefaultSegments = 64;

// Parallelogram corner, corner + edge1, corner + edge1 + edge2, corner + edge2; faces edge1 × edge2.
struct QuadShape {
  Vec3 corner, edge1, edge2;
  Vec3 normal() const { return edge1.cross(edge2).normalized(); }
};

// UV sphere about the world Z axis: `rings` latitude bands (poles are single vertices) and `segments`
// longitude bands; all vertices lie on the sphere, with normals (p - center) / radius.
struct SphereShape {
  Vec3 center;
  double radius = 1.0;
  int segments = kDefaultSegments;
  int rings = kDefaultSegments / 2;
};

// Circular cylinder from `base` along the unit `axis` for `height`, approximated by a prism with
// `segments` sides (vertices on the circle, smooth normals) and optionally flat caps.
struct CylinderShape {
  Vec3 base, axis;
  double radius = 1.0, height = 1.0;
  bool caps = true;
  int segments = kDefaultSegments;
};

// Parallelepiped spanned by three edges from `corner` (a box when they are orthogonal). Either
// handedness of the edges is accepted; faces are wound so their normals point outward.
struct BoxShape {
  Vec3 corner, edge1, edge2, edge3;
};

// A triangle mesh from a PLY file, already in world space.
struct MeshShape {
  std::string file;  // as written in the scene (relative to it)
  TriangleMesh mesh;
};

using Shape = std::variant<QuadShape, SphereShape, CylinderShape, BoxShape, MeshShape>;

TriangleMesh tessellate(const QuadShape& quad);
TriangleMesh tessellate(const SphereShape& sphere);
TriangleMesh tessellate(const CylinderShape& cylinder);
TriangleMesh tessellate(const BoxShape& box);
TriangleMesh tessellate(const MeshShape& mesh);
TriangleMesh tessellate(const Shape& shape);

// Texture coordinates: for each triangle of tessellate(shape), the (u, v) of its three corners (docs/scene-format.md,
// "Texture coordinates"). Per corner, not per vertex, so that a seam (a sphere's longitude 0 = 1) needs no
// vertices of its own. quad: (0, 0) at the corner, u along edge1, v along edge2; box: each face as a quad;
// sphere: u = longitude / 2π from +X towards +Y, v = 1 at the north (+Z) pole and 0 at the south pole;
// cylinder side: u = angle / 2π in its frame, v = height fraction; its caps: the unit disc mapped to
// [0, 1]²; mesh: the file's per-vertex coordinates. Empty for a mesh without them.
std::vector<std::array<Vec2, 3>> corner_uvs(const Shape& shape);
// The mesh with one (u, v) per vertex, for formats that keep texture coordinates per vertex (PLY): each vertex
// whose corners carry different (u, v) — a seam, a pole — becomes one vertex per (u, v), with the same position and
// normal; the triangles keep their order and corners. `uvs`: corner_uvs of the shape `mesh` tessellates (one
// entry per triangle); empty leaves the mesh as it is.
TriangleMesh with_vertex_uvs(const TriangleMesh& mesh, const std::vector<std::array<Vec2, 3>>& uvs);

// Exact surface area of the analytic shape (the tessellation converges to it as O(1/segments²)); for a
// mesh, the area of its triangles.
double surface_area(const QuadShape& quad);
double surface_area(const SphereShape& sphere);
double surface_area(const CylinderShape& cylinder);
double surface_area(const BoxShape& box);
double surface_area(const MeshShape& mesh);
double surface_area(const Shape& shape);

// An axis-aligned box that holds the whole shape (exact for quads, boxes and meshes, conservative for the
// round shapes), without tessellating it.
Bounds bounds(const Shape& shape);

// Name of the shape type as the scene format spells it ("quad", "sphere", ...).
const char* shape_type_name(const Shape& shape);

// Two unit vectors u, v with (u, v, axis) a right-handed orthonormal frame, for a unit `axis`.
std::array<Vec3, 2> orthonormal_frame(const Vec3& axis);

}  // namespace ct
