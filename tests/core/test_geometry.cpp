// SPDX-License-Identifier: Apache-2.0
// Tessellation of the scene format's shapes (exact areas, convergence rates, outward normals) and PLY I/O.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/geometry.h"
#include "core/ply.h"

namespace ct {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 centroid(const TriangleMesh& mesh, std::size_t t) {
  const auto& [a, b, c] = mesh.triangles[t];
  return (mesh.positions[a] + mesh.positions[b] + mesh.positions[c]) / 3.0;
}

// Signed volume by the divergence theorem: positive, and equal to the solid's volume, exactly when the
// closed mesh's triangles all face outward.
double signed_volume(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const auto& [a, b, c] : mesh.triangles)
    six_v += mesh.positions[a].dot(mesh.positions[b].cross(mesh.positions[c]));
  return six_v / 6.0;
}

double relative_area_error(const Shape& shape) {
  return std::abs(surface_area(tessellate(shape)) - surface_area(shape)) / surface_area(shape);
}

TEST(Geometry, QuadIsExactAndFacesEdge1CrossEdge2) {
  const QuadShape quad{{1, 2, 3}, {0.5, 0, 0.1}, {0, 2, 0}};
  const TriangleMesh mesh = tessellate(quad);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_TRUE(mesh.normals.empty());  // flat
  EXPECT_NEAR(surface_area(mesh), quad.edge1.cross(quad.edge2).norm(), 1e-15);
  for (std::size_t t = 0; t < 2; ++t) EXPECT_NEAR((face_normal(mesh, t) - quad.normal()).norm(), 0.0, 1e-15);
}

TEST(Geometry, BoxIsExactClosedAndOutwardForEitherHandedness) {
  // A sheared, rotated parallelepiped: area 2(|a×b| + |b×c| + |c×a|), volume |a·(b×c)|.
  const Vec3 a(0.3, 0.1, 0.0), b(-0.1, 0.4, 0.05), c(0.02, 0.03, 0.5);
  for (const bool swap : {false, true}) {
    const BoxShape box{{1, -2, 0.5}, swap ? b : a, swap ? a : b, c};
    const TriangleMesh mesh = tessellate(box);
    EXPECT_EQ(mesh.triangles.size(), 12u);
    EXPECT_NEAR(surface_area(mesh), 2.0 * (a.cross(b).norm() + b.cross(c).norm() + c.cross(a).norm()), 1e-14);
    EXPECT_NEAR(surface_area(mesh), surface_area(Shape(box)), 1e-14);
    EXPECT_NEAR(signed_volume(mesh), std::abs(a.dot(b.cross(c))), 1e-14);
    const Vec3 centre = box.corner + 0.5 * (a + b + c);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      EXPECT_GT(face_normal(mesh, t).dot(centroid(mesh, t) - centre), 0.0) << "triangle " << t;
  }
}

TEST(Geometry, SphereAreaConvergesAsOneOverNSquared) {
  // UV sphere with n segments and n/2 rings, vertices on the sphere: the inscribed area falls short of
  // 4πr² by O(1/n²), so doubling n divides the error by 4 (once n is past the coarsest meshes).
  double previous = 0.0;
  for (int n = 16; n <= 256; n *= 2) {
    const double error = relative_area_error(SphereShape{{0.1, 0.2, 0.3}, 0.7, n, n / 2});
    if (previous > 0.0) {
      EXPECT_NEAR(previous / error, 4.0, 0.1) << "n = " << n;
    }
    previous = error;
  }
  // The documented default (64 x 32) is within 0.2 %.
  EXPECT_LT(relative_area_error(SphereShape{{0, 0, 0}, 1.0}), 0.0021);
}

TEST(Geometry, SphereNormalsPointOutward) {
  const SphereShape sphere{{0.4, 0.3, 0.35}, 0.35, 24, 11};
  const TriangleMesh mesh = tessellate(sphere);
  EXPECT_EQ(mesh.triangles.size(), static_cast<std::size_t>(2 * 24 * (11 - 1)));
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_NEAR((mesh.positions[i] - sphere.center).norm(), sphere.radius, 1e-15);
    EXPECT_NEAR((mesh.normals[i] - (mesh.positions[i] - sphere.center) / sphere.radius).norm(), 0.0, 1e-15);
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    EXPECT_GT(face_normal(mesh, t).dot(centroid(mesh, t) - sphere.center), 0.0) << "triangle " << t;
  EXPECT_GT(signed_volume(mesh), 0.0);
}

TEST(Geometry, CylinderAreaConvergesAsOneOverNSquared) {
  for (const bool caps : {true, false}) {
    double previous = 0.0;
    for (int n = 8; n <= 256; n *= 2) {
      const double error =
          relative_area_error(CylinderShape{{0, 0, 0}, Vec3(1, 1, 1).normalized(), 0.25, 0.9, caps, n});
      if (previous > 0.0) {
        EXPECT_NEAR(previous / error, 4.0, 0.1) << "n = " << n << ", caps " << caps;
      }
      previous = error;
    }
  }
  EXPECT_NEAR(surface_area(CylinderShape{{0, 0, 0}, Vec3::UnitZ(), 0.25, 0.9, true}),
              2 * kPi * 0.25 * 0.9 + 2 * kPi * 0.25 * 0.25, 1e-15);
}

TEST(Geometry, CylinderNormalsPointOutwardAndCapsAreFlat) {
  const CylinderShape cylinder{{-0.4, 0.2, 0}, Vec3(0.2, -0.3, 1).normalized(), 0.25, 0.9, true, 32};
  const TriangleMesh mesh = tessellate(cylinder);
  EXPECT_EQ(mesh.triangles.size(), 4u * 32u);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 c = centroid(mesh, t);
    const double along = (c - cylinder.base).dot(cylinder.axis);
    const Vec3 radial = c - cylinder.base - along * cylinder.axis;
    const Vec3 n = face_normal(mesh, t);
    if (std::abs(along) < 1e-12) {
      EXPECT_NEAR((n + cylinder.axis).norm(), 0.0, 1e-12);  // bottom cap
    } else if (std::abs(along - cylinder.height) < 1e-12) {
      EXPECT_NEAR((n - cylinder.axis).norm(), 0.0, 1e-12);  // top cap
    } else {
      EXPECT_GT(n.dot(radial), 0.0) << "side triangle " << t;
    }
  }
  // A closed prism: volume = (n/2) r² sin(2π/n) h, positive when every face points outward.
  EXPECT_NEAR(signed_volume(mesh), 16 * 0.25 * 0.25 * std::sin(2 * kPi / 32) * 0.9, 1e-12);
}

TEST(Geometry, OrthonormalFrameIsRightHanded) {
  for (const Vec3& axis : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0.3, -0.4, 0.2).normalized()}) {
    const auto [u, v] = orthonormal_frame(axis);
    EXPECT_NEAR(u.norm(), 1.0, 1e-15);
    EXPECT_NEAR(v.norm(), 1.0, 1e-15);
    EXPECT_NEAR(u.dot(axis), 0.0, 1e-15);
    EXPECT_NEAR((u.cross(v) - axis).norm(), 0.0, 1e-15);
  }
}

TEST(Geometry, BoundsAndMeshArea) {
  const TriangleMesh mesh = tessellate(BoxShape{{-1, 0, 2}, {2, 0, 0}, {0, 3, 0}, {0, 0, 0.5}});
  const Bounds b = bounds(mesh);
  EXPECT_EQ(b.lo, Vec3(-1, 0, 2));
  EXPECT_EQ(b.hi, Vec3(1, 3, 2.5));
  EXPECT_TRUE(Bounds().empty());
  EXPECT_EQ(surface_area(Shape(MeshShape{"box.ply", mesh})), surface_area(mesh));
}

// ---- PLY ------------------------------------------------------------------------------------------------

class Ply : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("chromatrace-ply-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(Ply, RoundTripGivesTheSameMesh) {
  // Positions with full double precision and unit normals: a smooth cylinder, and a flat box.
  const TriangleMesh smooth =
      tessellate(CylinderShape{{0.1, 0.2, 0.3}, Vec3(1, 2, 3).normalized(), 0.123456789, 1.1, true, 7});
  const TriangleMesh flat = tessellate(BoxShape{{0, 0, 0}, {1.0 / 3, 0, 0}, {0, 2.0 / 7, 0}, {0, 0, 0.1}});
  for (const PlyFormat format : {PlyFormat::Ascii, PlyFormat::BinaryLittleEndian}) {
    for (const TriangleMesh* mesh : {&smooth, &flat}) {
      const std::filesystem::path file = dir_ / "mesh.ply";
      write_ply(file, *mesh, format);
      EXPECT_FALSE(std::filesystem::exists(dir_ / "mesh.ply.partial"));
      const TriangleMesh back = read_ply(file);
      EXPECT_EQ(back.positions, mesh->positions);
      EXPECT_EQ(back.triangles, mesh->triangles);
      ASSERT_EQ(back.normals.size(), mesh->normals.size());
      // Normals are renormalised on reading, which may move the last bit.
      for (std::size_t i = 0; i < back.normals.size(); ++i)
        EXPECT_NEAR((back.normals[i] - mesh->normals[i]).norm(), 0.0, 1e-15);
    }
  }
}

TEST_F(Ply, AsciiPolygonsAreFanTriangulatedAndOtherDataSkipped) {
  const std::string text =
      "ply\r\nformat ascii 1.0\ncomment made by hand\nobj_info test\n"
      "element vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      "element face 2\nproperty uchar flags\nproperty list uchar int vertex_index\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
      "end_header\n"
      "0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 1 2 3\n0.5 1.5 0 4 5 6\n2 2 2 7 8 9\n"
      "7 4 0 1 2 3\n"    // a quad -> 2 triangles
      "0 5 0 1 2 4 3\n"  // a pentagon -> 3 triangles
      "0 1\n";
  const TriangleMesh mesh = parse_ply(text, "hand.ply");
  EXPECT_EQ(mesh.positions.size(), 6u);
  EXPECT_TRUE(mesh.normals.empty());
  const std::vector<std::array<std::uint32_t, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 2}, {0, 2, 4}, {0, 4, 3}};
  EXPECT_EQ(mesh.triangles, expected);
  EXPECT_EQ(mesh.positions[4], Vec3(0.5, 1.5, 0));
}

TEST_F(Ply, BinaryWithMixedTypes) {
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty double nx\nproperty double ny\nproperty double nz\n"
      "element face 1\nproperty list uchar uint vertex_indices\nproperty short material\nend_header\n";
  auto put = [&](auto value) { bytes.append(reinterpret_cast<const char*>(&value), sizeof value); };
  const float p[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}};
  for (const auto& v : p) {
    for (float x : v) put(x);
    for (double n : {0.0, 0.0, 2.0}) put(n);  // not unit: normalised on reading
  }
  put(std::uint8_t{3});
  for (std::uint32_t i : {0u, 1u, 2u}) put(i);
  put(std::int16_t{-7});
  const TriangleMesh mesh = parse_ply(bytes, "binary.ply");
  ASSERT_EQ(mesh.positions.size(), 3u);
  EXPECT_EQ(mesh.positions[2], Vec3(0, 1, 0.5));
  ASSERT_EQ(mesh.normals.size(), 3u);
  EXPECT_EQ(mesh.normals[0], Vec3(0, 0, 1));
  EXPECT_EQ(mesh.triangles, (std::vector<std::array<std::uint32_t, 3>>{{0, 1, 2}}));
}

TEST_F(Ply, BadFilesNameTheFileAndThePlace) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  auto message = [](const std::string& text) {
    try {
      parse_ply(text, "m.ply");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(header + "3 0 1 3\n"), "m.ply: face 0: vertex index 3 out of range (3 vertices)");
  EXPECT_EQ(message(header + "2 0 1\n"), "m.ply: face 0: has 2 vertices, needs at least 3");
  EXPECT_EQ(message(header + "3 0 1\n"), "m.ply: face 0: unexpected end of file");
  EXPECT_EQ(message("ply\nformat binary_big_endian 1.0\nend_header\n"),
            "m.ply: header line 2: format \"binary_big_endian\" is not supported (use ascii or binary_little_endian)");
  EXPECT_EQ(message("solid cube\n"), "m.ply: not a PLY file (first line is not \"ply\")");
  EXPECT_EQ(message("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n"),
            "m.ply: vertex element has no property y");
  EXPECT_THROW(read_ply(dir_ / "absent.ply"), InputError);
}

TEST_F(Ply, CountsTheFileCannotHoldAreRefusedBeforeAllocating) {
  auto message = [](const std::string& text) {
    try {
      parse_ply(text, "m.ply");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // 4e9 vertices declared in a small file: a vertex of 3 ASCII values takes at least 6 bytes (the last one 5),
  // so the 18 bytes after the header hold 3.
  EXPECT_EQ(message("ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n"),
            "m.ply: element vertex declares 4000000000 entries, more than the 3 that the rest of the file can hold");
  const std::string vertices =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uint int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  // A face list of 10^9 or 10^300 indices: refused before a vector of that length is made.
  EXPECT_EQ(message(vertices + "1000000000 0 1 2\n"),
            "m.ply: face 0: list length 1000000000 is more than the rest of the file holds");
  EXPECT_EQ(message(vertices + "1e300 0 1 2\n"), "m.ply: face 0: list length 1e+300 is more than the rest of the file holds");
  // Binary: a uint32 count of 4294967295 items of 4 bytes in a 12-byte rest.
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  auto put = [&](auto value) { binary.append(reinterpret_cast<const char*>(&value), sizeof value); };
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(x);
  put(std::uint32_t{4294967295u});
  for (std::int32_t i : {0, 1, 2}) put(i);
  EXPECT_EQ(message(binary), "m.ply: face 0: list length 4294967295 is more than the rest of the file holds");
  // An element without properties holds nothing, however many it declares: skipped, not counted through.
  const TriangleMesh mesh = parse_ply(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element nothing 4000000000000\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      "m.ply");
  EXPECT_EQ(mesh.triangles.size(), 1u);
}

}  // namespace
}  // namespace ct
