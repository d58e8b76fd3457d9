// SPDX-License-Identifier: Apache-2.0
#include "core/geometry.h"

#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

#include <fmt/core.h>
#include <numbers>

namespace ct {
namespace {

using Index = std::uint32_t;

Index add_vertex(TriangleMesh& mesh, const Vec3& position) {
  mesh.positions.push_back(position);
  return static_cast<Index>(mesh.positions.size() - 1);
}

Index add_vertex(TriangleMesh& mesh, const Vec3& position, const Vec3& normal) {
  mesh.normals.push_back(normal);
  return add_vertex(mesh, position);
}

// Appends the parallelogram as two triangles; both have the geometric normal edge1 × edge2.
void add_quad(TriangleMesh& mesh, const Vec3& corner, const Vec3& edge1, const Vec3& edge2) {
  const Index a = add_vertex(mesh, corner);
  const Index b = add_vertex(mesh, corner + edge1);
  const Index c = add_vertex(mesh, corner + edge1 + edge2);
  const Index d = add_vertex(mesh, corner + edge2);
  mesh.triangles.push_back({a, b, c});
  mesh.triangles.push_back({a, c, d});
}

Vec3 unit_circle(const std::array<Vec3, 2>& frame, int segment, int segments) {
  const double phi = 2.0 * std::numbers::pi * segment / segments;
  return std::cos(phi) * frame[0] + std::sin(phi) * frame[1];
}

}  // namespace

Vec3 face_normal(const TriangleMesh& mesh, std::size_t t) {
  const auto& [a, b, c] = mesh.triangles[t];
  const Vec3 n = (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3::Zero();
}

double triangle_area(const TriangleMesh& mesh, std::size_t t) {
  const auto& [a, b, c] = mesh.triangles[t];
  return 0.5 * (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]).norm();
}

double surface_area(const TriangleMesh& mesh) {
  double area = 0.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) area += triangle_area(mesh, t);
  return area;
}

void Bounds::extend(const Vec3& p) {
  lo = lo.cwiseMin(p);
  hi = hi.cwiseMax(p);
}

void Bounds::extend(const Bounds& b) {
  lo = lo.cwiseMin(b.lo);
  hi = hi.cwiseMax(b.hi);
}

Bounds bounds(const TriangleMesh& mesh) {
  Bounds b;
  for (const Vec3& p : mesh.positions) b.extend(p);
  return b;
}

Bounds bounds(const Shape& shape) {
  Bounds b;
  if (const auto* quad = std::get_if<QuadShape>(&shape)) {
    for (int i = 0; i < 4; ++i)
      b.extend(quad->corner + double(i & 1) * quad->edge1 + double((i >> 1) & 1) * quad->edge2);
  } else if (const auto* box = std::get_if<BoxShape>(&shape)) {
    for (int i = 0; i < 8; ++i)
      b.extend(box->corner + double(i & 1) * box->edge1 + double((i >> 1) & 1) * box->edge2 +
               double((i >> 2) & 1) * box->edge3);
  } else if (const auto* sphere = std::get_if<SphereShape>(&shape)) {
    b.extend(sphere->center - Vec3::Constant(sphere->radius));
    b.extend(sphere->center + Vec3::Constant(sphere->radius));
  } else if (const auto* cylinder = std::get_if<CylinderShape>(&shape)) {
    const Vec3 r = Vec3::Constant(cylinder->radius);
    for (const Vec3& end : {cylinder->base, Vec3(cylinder->base + cylinder->height * cylinder->axis)}) {
      b.extend(end - r);
      b.extend(end + r);
    }
  } else {
    b = bounds(std::get<MeshShape>(shape).mesh);
  }
  return b;
}

std::array<Vec3, 2> orthonormal_frame(const Vec3& axis) {
  // Cross with the world axis least aligned with `axis`, so the result is never near zero.
  const Vec3 a = axis.cwiseAbs();
  const Vec3 helper = a.x() <= a.y() && a.x() <= a.z() ? Vec3::UnitX() : a.y() <= a.z() ? Vec3::UnitY() : Vec3::UnitZ();
  const Vec3 u = helper.cross(axis).normalized();
  return {u, axis.cross(u)};
}

TriangleMesh tessellate(const QuadShape& quad) {
  TriangleMesh mesh;
  add_quad(mesh, quad.corner, quad.edge1, quad.edge2);
  return mesh;
}

TriangleMesh tessellate(const SphereShape& sphere) {
  const int segments = sphere.segments, rings = sphere.rings;
  const std::array<Vec3, 2> frame = {Vec3::UnitX(), Vec3::UnitY()};
  TriangleMesh mesh;
  auto vertex = [&](const Vec3& direction) {
    return add_vertex(mesh, sphere.center + sphere.radius * direction, direction);
  };
  // Ring i (1 .. rings-1) at polar angle pi*i/rings holds vertices first_of_ring(i) + j.
  const Index north = vertex(Vec3::UnitZ());
  for (int i = 1; i < rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j)
      vertex(std::sin(theta) * unit_circle(frame, j, segments) + std::cos(theta) * Vec3::UnitZ());
  }
  const Index south = vertex(-Vec3::UnitZ());
  auto at = [&](int i, int j) { return static_cast<Index>(1 + (i - 1) * segments + j % segments); };

  // Longitude increases counter-clockwise seen from +Z, so these windings face outward.
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({north, at(1, j), at(1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
    mesh.triangles.push_back({south, at(rings - 1, j + 1), at(rings - 1, j)});
  }
  return mesh;
}

TriangleMesh tessellate(const CylinderShape& cylinder) {
  const int n = cylinder.segments;
  const std::array<Vec3, 2> frame = orthonormal_frame(cylinder.axis);
  const Vec3 top = cylinder.base + cylinder.height * cylinder.axis;
  TriangleMesh mesh;

  // Side: bottom vertex 2j, top vertex 2j+1, both with the smooth radial normal.
  for (int j = 0; j < n; ++j) {
    const Vec3 radial = unit_circle(frame, j, n);
    add_vertex(mesh, cylinder.base + cylinder.radius * radial, radial);
    add_vertex(mesh, top + cylinder.radius * radial, radial);
  }
  for (int j = 0; j < n; ++j) {
    const Index b0 = 2 * j, t0 = 2 * j + 1, b1 = 2 * ((j + 1) % n), t1 = b1 + 1;
    mesh.triangles.push_back({b0, b1, t1});
    mesh.triangles.push_back({b0, t1, t0});
  }

  // Caps get their own vertices: the rim needs the flat cap normal there, not the side's radial one.
  if (cylinder.caps) {
    for (const bool is_top : {false, true}) {
      const Vec3 normal = is_top ? Vec3(cylinder.axis) : Vec3(-cylinder.axis);
      const Vec3 centre = is_top ? top : cylinder.base;
      const Index middle = add_vertex(mesh, centre, normal);
      const Index first = middle + 1;
      for (int j = 0; j < n; ++j) add_vertex(mesh, centre + cylinder.radius * unit_circle(frame, j, n), normal);
      for (int j = 0; j < n; ++j) {
        const Index a = first + j, b = first + (j + 1) % n;
        mesh.triangles.push_back(is_top ? std::array<Index, 3>{middle, a, b} : std::array<Index, 3>{middle, b, a});
      }
    }
  }
  return mesh;
}

TriangleMesh tessellate(const BoxShape& box) {
  // With a right-handed (a, b, c) every face below is wound outward; a left-handed triple is made
  // right-handed by swapping a and b, which spans the same solid.
  const bool right_handed = box.edge1.cross(box.edge2).dot(box.edge3) > 0.0;
  const Vec3& a = right_handed ? box.edge1 : box.edge2;
  const Vec3& b = right_handed ? box.edge2 : box.edge1;
  const Vec3& c = box.edge3;
  const Vec3& o = box.corner;
  TriangleMesh mesh;
  add_quad(mesh, o, b, a);      // faces -c
  add_quad(mesh, o + c, a, b);  // faces +c
  add_quad(mesh, o, c, b);      // faces -a
  add_quad(mesh, o + a, b, c);  // faces +a
  add_quad(mesh, o, a, c);      // faces -b
  add_quad(mesh, o + b, c, a);  // faces +b
  return mesh;
}

TriangleMesh tessellate(const MeshShape& mesh) { return mesh.mesh; }

TriangleMesh tessellate(const Shape& shape) {
  return std::visit([](const auto& s) { return tessellate(s); }, shape);
}

namespace {

void add_quad_uvs(std::vector<std::array<Vec2, 3>>& uvs) {
  uvs.push_back({Vec2(0, 0), Vec2(1, 0), Vec2(1, 1)});
  uvs.push_back({Vec2(0, 0), Vec2(1, 1), Vec2(0, 1)});
}

// Mirrors tessellate(): the triangles in the same order, each corner's (u, v).
std::vector<std::array<Vec2, 3>> shape_uvs(const QuadShape&) {
  std::vector<std::array<Vec2, 3>> uvs;
  add_quad_uvs(uvs);
  return uvs;
}

std::vector<std::array<Vec2, 3>> shape_uvs(const BoxShape&) {
  std::vector<std::array<Vec2, 3>> uvs;
  for (int face = 0; face < 6; ++face) add_quad_uvs(uvs);
  return uvs;
}

std::vector<std::array<Vec2, 3>> shape_uvs(const SphereShape& sphere) {
  const int segments = sphere.segments, rings = sphere.rings;
  // Vertex (i, j) at u = j / segments (the seam's second side at u = 1), v = 1 − i / rings; a pole takes the
  // u of the middle of its triangle's segment.
  const auto at = [&](int i, int j) { return Vec2(static_cast<double>(j) / segments, 1.0 - static_cast<double>(i) / rings); };
  std::vector<std::array<Vec2, 3>> uvs;
  for (int j = 0; j < segments; ++j) {
    const double mid = (j + 0.5) / segments;
    uvs.push_back({Vec2(mid, 1.0), at(1, j), at(1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
      uvs.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      uvs.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
    uvs.push_back({Vec2(mid, 0.0), at(rings - 1, j + 1), at(rings - 1, j)});
  }
  return uvs;
}

std::vector<std::array<Vec2, 3>> shape_uvs(const CylinderShape& cylinder) {
  const int n = cylinder.segments;
  std::vector<std::array<Vec2, 3>> uvs;
  for (int j = 0; j < n; ++j) {
    const double u0 = static_cast<double>(j) / n, u1 = static_cast<double>(j + 1) / n;
    uvs.push_back({Vec2(u0, 0), Vec2(u1, 0), Vec2(u1, 1)});
    uvs.push_back({Vec2(u0, 0), Vec2(u1, 1), Vec2(u0, 1)});
  }
  if (cylinder.caps) {
    const auto rim = [&](int j) {
      const double phi = 2.0 * std::numbers::pi * j / n;
      return Vec2(0.5 + 0.5 * std::cos(phi), 0.5 + 0.5 * std::sin(phi));
    };
    const Vec2 middle(0.5, 0.5);
    for (const bool is_top : {false, true})
      for (int j = 0; j < n; ++j)
        uvs.push_back(is_top ? std::array<Vec2, 3>{middle, rim(j), rim(j + 1)}
                             : std::array<Vec2, 3>{middle, rim(j + 1), rim(j)});
  }
  return uvs;
}

std::vector<std::array<Vec2, 3>> shape_uvs(const MeshShape& shape) {
  const TriangleMesh& mesh = shape.mesh;
  std::vector<std::array<Vec2, 3>> uvs;
  if (mesh.uvs.empty()) return uvs;
  for (const auto& [a, b, c] : mesh.triangles) uvs.push_back({mesh.uvs[a], mesh.uvs[b], mesh.uvs[c]});
  return uvs;
}

}  // namespace

std::vector<std::array<Vec2, 3>> corner_uvs(const Shape& shape) {
  return std::visit([](const auto& s) { return shape_uvs(s); }, shape);
}

TriangleMesh with_vertex_uvs(const TriangleMesh& mesh, const std::vector<std::array<Vec2, 3>>& uvs) {
  if (uvs.empty()) return mesh;
  if (uvs.size() != mesh.triangles.size())
    throw std::invalid_argument(fmt::format("with_vertex_uvs: {} corner (u, v) triples for {} triangles", uvs.size(),
                                            mesh.triangles.size()));
  TriangleMesh out;
  std::map<std::tuple<std::uint32_t, double, double>, std::uint32_t> index;  // (vertex, u, v) -> new vertex
  out.triangles.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    std::array<std::uint32_t, 3> triangle{};
    for (std::size_t c = 0; c < 3; ++c) {
      const std::uint32_t v = mesh.triangles[t][c];
      const Vec2& uv = uvs[t][c];
      const auto [it, added] = index.try_emplace({v, uv.x(), uv.y()}, static_cast<std::uint32_t>(out.positions.size()));
      if (added) {
        out.positions.push_back(mesh.positions[v]);
        if (!mesh.normals.empty()) out.normals.push_back(mesh.normals[v]);
        out.uvs.push_back(uv);
      }
      triangle[c] = it->second;
    }
    out.triangles.push_back(triangle);
  }
  return out;
}

double surface_area(const QuadShape& quad) { return quad.edge1.cross(quad.edge2).norm(); }

double surface_area(const SphereShape& sphere) { return 4.0 * std::numbers::pi * sphere.radius * sphere.radius; }

double surface_area(const CylinderShape& cylinder) {
  const double side = 2.0 * std::numbers::pi * cylinder.radius * cylinder.height;
  const double caps = cylinder.caps ? 2.0 * std::numbers::pi * cylinder.radius * cylinder.radius : 0.0;
  return side + caps;
}

double surface_area(const BoxShape& box) {
  return 2.0 *
         (box.edge1.cross(box.edge2).norm() + box.edge2.cross(box.edge3).norm() + box.edge3.cross(box.edge1).norm());
}

double surface_area(const MeshShape& mesh) { return surface_area(mesh.mesh); }

double surface_area(const Shape& shape) {
  return std::visit([](const auto& s) { return surface_area(s); }, shape);
}

const char* shape_type_name(const Shape& shape) {
  static constexpr const char* names[] = {"quad", "sphere", "cylinder", "box", "mesh"};
  static_assert(std::size(names) == std::variant_size_v<Shape>);
  return names[shape.index()];
}

}  // namespace ct
