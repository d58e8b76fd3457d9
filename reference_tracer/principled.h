// SPDX-License-Identifier: Apache-2.0
#pragma once
// Blender's Principled BSDF as Cycles evaluates it for an opaque dielectric (scene format "principled",
// core/scene.h PrincipledMaterial; docs/scene-format.md). Directions as in bsdf.h: `wo` towards the viewer,
// `wi` towards the light, local frame with z the normal; eval() and diffuse() return f·cos θi.
//
// Version 2 (Blender 4.0 on): f = F(wo·h, η)·D·G2 / (4 cos θo cos θi) · k(μo) + W(μo)·base/π, with the exact
// unpolarised dielectric Fresnel at the microfacet normal, height-correlated masking, Multiscatter GGX's energy
// compensation k = 1 + Fms·(1 − E)/E (Turquin 2019 with Kulla and Conty's average Fresnel; 1 for plain GGX) and
// the base attenuated by W = 1 − [E + Fms·(1 − E)]·(F0 + (1 − F0)·S), both at the view angle μo, as Cycles sets
// them up once per shading point. E, E_avg and S are Cycles' lookup tables (GgxTables), recomputed here as
// they are defined and read back with the same grids and interpolation.
// Version 1 (Blender 3.x): Burley's diffuse with retro-reflection, added to single-scatter GGX with separable
// masking and the dielectric Fresnel of F0 = 0.08 · specular; no layering.

#include <array>
#include <mutex>
#include <optional>
#include <vector>

#include "reference_tracer/bsdf.h"

namespace ct::rt {

// The unpolarised reflectance of a dielectric interface of relative index eta at cos θ (total internal
// reflection gives 1).
double fresnel_dielectric(double cos_theta, double eta);

// Kulla and Conty's fit of the cosine-weighted hemispherical average of fresnel_dielectric.
double average_fresnel_dielectric(double eta);

// Cycles' GGX tables (cycles_precompute): each entry an average over the visible normals of the GGX
// distribution (height-correlated masking) seen from μ, a reflection below the horizon counting 0.
// - E(r, μ): the directional albedo without Fresnel (32 × 32, r and μ at i/31);
// - E_avg(r) = ∫ 2μ E(r, μ) dμ (32);
// - S(r, μ, z): the mean of (F(wo·h, η) − F0) / (1 − F0) for F0 = z⁴ (16 × 16 × 16, at i/15; z ≤ 0.99).
// Computed by a fixed midpoint quadrature of the visible-normal sampling (the same values whatever the thread
// count) when first needed: E and E_avg when a scene first has a principled material, each plane of S in z when a
// material first reads it (a scene's few IORs need two planes each).
class GgxTables {
 public:
  static const GgxTables& get();
  double E(double roughness, double mu) const;
  double E_avg(double roughness) const;
  double S(double roughness, double mu, double z) const;
  void prepare_z(double z) const;  // computes the planes S(·, ·, z) reads, if not yet done

  // The entries themselves, by quadrature with n × n points over the visible normals (for tests).
  static double albedo(double roughness, double mu, int n);
  static double fresnel_rise(double roughness, double mu, double z, int n);

 private:
  GgxTables();
  void prepare_plane(int z) const;
  std::vector<double> e_, e_avg_;
  mutable std::vector<double> s_;
  mutable std::array<std::once_flag, 16> plane_ready_;
};

struct PrincipledLobe {
  int version = 2;
  double roughness = 0.5;
  double eta = 1.5;          // 1: no interface lobe
  bool multiscatter = true;  // version 2
  GgxLobe ggx{0.25, true};

  PrincipledLobe(int version, double roughness, double eta, bool multiscatter);

  // f·cos θi of the base (without its colour): W(μo)·cos θi/π (v2) or Burley's (v1).
  double diffuse(const Vec3& wo, const Vec3& wi) const;
  // f·cos θi of the interface lobe.
  double eval(const Vec3& wo, const Vec3& wi) const;
  double pdf(const Vec3& wo, const Vec3& wi) const;
  std::optional<LobeSample> sample(const Vec3& wo, const Vec2& u) const;

  // The view-angle factors Cycles fixes at the shading point: the interface's energy compensation k(μo) and the
  // base's weight W(μo) (both 1 where they do not apply).
  double specular_factor(double mu) const;
  double diffuse_weight(double mu) const;

 private:
  double f0_ = 0.04;   // ((η − 1)/(η + 1))²
  double fms_ = 0.0;   // Fss·E_avg / (1 − Fss·(1 − E_avg)), version 2 multiscatter
  double z_ = 0.0;     // F0^(1/4), S's third coordinate
};

}  // namespace ct::rt
