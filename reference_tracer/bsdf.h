// SPDX-License-Identifier: Apache-2.0
#pragma once
// The BRDFs of the scene format, each written once. Both renderers implement exactly these (docs/materials.md).
//
// All directions are unit vectors in the local shading frame, z = surface normal, pointing away from the
// surface: `wo` towards the viewer, `wi` towards the light. A lobe's eval() returns f(wo, wi)·cos θi (the
// BRDF times the cosine, as Cycles' closures do) and its pdf() is per unit solid angle, so a sampled
// direction's weight is eval / pdf. The lobes are spectrally flat; materials scale them by spectra.

#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace ct::rt {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

inline double cos_theta(const Vec3& w) { return w.z(); }

struct LobeSample {
  Vec3 wi;
  double weight = 0;  // eval(wo, wi) / pdf(wo, wi)
  double pdf = 0;     // per solid angle; +∞ for a delta lobe
};

// Lambertian: f = 1/π; cosine-weighted sampling.
struct LambertLobe {
  double eval(const Vec3& wo, const Vec3& wi) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
  std::optional<LobeSample> sample(const Vec3& wo, const Vec2& u) const;
};

// GGX (Trowbridge–Reitz) microfacet reflection as Cycles' Glossy BSDF evaluates it: alpha = roughness²,
// f = D(h)·G2(wo, wi) / (4 cos θo cos θi), no Fresnel, with the Smith masking-shadowing G2 of the Cycles
// version held to: separable G1(wo)·G1(wi) (Blender 3.x) or height-correlated 1 / (1 + Λ(wo) + Λ(wi))
// (Blender 4.0 on; Heitz 2014, "Understanding the Masking-Shadowing Function"), G1 = 1 / (1 + Λ). Sampled
// from the distribution of visible normals (Heitz 2018), pdf = G1(wo)·D(h) / (4 cos θo).
struct GgxLobe {
  double alpha;
  bool height_correlated = false;
  double D(const Vec3& h) const;
  double Lambda(const Vec3& w) const;  // Smith's Λ; +∞ at or below the horizon
  double G1(const Vec3& w) const;
  double G2(const Vec3& wo, const Vec3& wi) const;
  double eval(const Vec3& wo, const Vec3& wi) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
  std::optional<LobeSample> sample(const Vec3& wo, const Vec2& u) const;
};

// Energy-normalised (modified) Phong lobe of Lafortune and Willems (1994): f = (n+2)/(2π)·cos^n α, α the
// angle between wi and the mirror direction of wo; sampled ∝ cos^n α around the mirror direction.
struct PhongLobe {
  double exponent;
  double eval(const Vec3& wo, const Vec3& wi) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
  std::optional<LobeSample> sample(const Vec3& wo, const Vec2& u) const;
};

// Perfect mirror: a delta lobe (eval and pdf are 0 for any given pair; sampling returns the mirror
// direction with weight 1).
struct MirrorLobe {
  double eval(const Vec3&, const Vec3&) const { return 0.0; }
  double pdf(const Vec3&, const Vec3&) const { return 0.0; }
  std::optional<LobeSample> sample(const Vec3& wo, const Vec2& u) const;
};

inline Vec3 reflect_about_normal(const Vec3& w) { return {-w.x(), -w.y(), w.z()}; }

// An orthonormal frame with the given unit normal as z (Duff et al. 2017, branchless).
struct Frame {
  Vec3 s, t, n;
  explicit Frame(const Vec3& normal);
  Vec3 to_local(const Vec3& v) const { return {v.dot(s), v.dot(t), v.dot(n)}; }
  Vec3 to_world(const Vec3& v) const { return s * v.x() + t * v.y() + n * v.z(); }
};

// Cosine-weighted hemisphere sample (Malley's method over a concentric disk).
Vec3 sample_cosine_hemisphere(const Vec2& u);
Vec2 sample_concentric_disk(const Vec2& u);

}  // namespace ct::rt
