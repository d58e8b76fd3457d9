// SPDX-License-Identifier: Apache-2.0
#include "reference_tracer/principled.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/parallel.h"

namespace ct::rt {
namespace {

constexpr int kSizeE = 32;  // E(r, μ) and E_avg(r): r and μ at i/31
constexpr int kSizeS = 16;  // S(r, μ, z): at i/15
// Quadrature points per side over the visible normals, and μ points for E_avg. The midpoint rule converges as 1/n
// here (a reflection below the horizon cuts the integrand), so an entry that moves by less than 10⁻³ when the
// points are doubled is within 2·10⁻³ of its limit (tests/reference_tracer/test_principled.cpp). That keeps the base's
// weight W within 0.5 % where it is smallest (0.4 at μ = 0.1), a quarter of compare's tolerance for glossy materials.
constexpr int kPointsE = 64, kPointsS = 96, kPointsAvgMu = 32, kPointsAvg = 48;

double saturate(double x) { return std::clamp(x, 0.0, 1.0); }

// Cycles' lookup: the coordinate saturated and scaled to the grid, linear between neighbours.
struct Coordinate {
  int i0, i1;
  double t;
};
Coordinate grid(double x, int size) {
  const double p = saturate(x) * (size - 1);
  const int i0 = std::min(static_cast<int>(p), size - 1);
  return {i0, std::min(i0 + 1, size - 1), p - i0};
}

Vec3 view(double mu) { return {std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu}; }

}  // namespace

double fresnel_dielectric(double cos_theta, double eta) {
  const double c = std::abs(cos_theta);
  const double g2 = eta * eta - 1.0 + c * c;
  if (g2 <= 0.0) return 1.0;  // total internal reflection
  const double g = std::sqrt(g2);
  const double a = (g - c) / (g + c);
  const double b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
  return 0.5 * a * a * (1.0 + b * b);
}

double average_fresnel_dielectric(double eta) {
  if (eta >= 1.0) return (eta - 1.0) / (4.08567 + 1.00071 * eta);
  return 0.997118 + eta * (0.1014 - eta * (0.965241 + eta * 0.130607));
}

double GgxTables::albedo(double roughness, double mu, int n) {
  const GgxLobe lobe{roughness * roughness, true};
  const Vec3 wo = view(mu);
  double sum = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (const auto s = lobe.sample(wo, Vec2((i + 0.5) / n, (j + 0.5) / n))) sum += s->weight;
  return saturate(sum / (static_cast<double>(n) * n));
}

double GgxTables::fresnel_rise(double roughness, double mu, double z, int n) {
  const GgxLobe lobe{roughness * roughness, true};
  const Vec3 wo = view(mu);
  const double f0 = z * z * z * z, eta = (1.0 + z * z) / (1.0 - z * z);
  double sum = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (const auto s = lobe.sample(wo, Vec2((i + 0.5) / n, (j + 0.5) / n))) {
        const Vec3 h = (wo + s->wi).normalized();
        sum += saturate((fresnel_dielectric(wo.dot(h), eta) - f0) / (1.0 - f0));
      }
  return saturate(sum / (static_cast<double>(n) * n));
}

GgxTables::GgxTables() : e_(kSizeE * kSizeE), e_avg_(kSizeE), s_(kSizeS * kSizeS * kSizeS) {
  auto at = [](int i, int size, double lo, double hi) { return std::clamp(static_cast<double>(i) / (size - 1), lo, hi); };
  parallel_for(e_.size(), 0, [&](std::size_t k) {
    const int x = static_cast<int>(k % kSizeE), y = static_cast<int>(k / kSizeE);
    e_[k] = albedo(at(x, kSizeE, 1e-4, 1.0), at(y, kSizeE, 1e-4, 1.0), kPointsE);
  });
  parallel_for(e_avg_.size(), 0, [&](std::size_t x) {
    const double r = at(static_cast<int>(x), kSizeE, 1e-4, 1.0);
    double sum = 0.0;
    for (int m = 0; m < kPointsAvgMu; ++m) {
      const double mu = (m + 0.5) / kPointsAvgMu;
      sum += 2.0 * mu * albedo(r, mu, kPointsAvg);
    }
    e_avg_[x] = sum / kPointsAvgMu;
  });
}

void GgxTables::prepare_plane(int z) const {
  std::call_once(plane_ready_[static_cast<std::size_t>(z)], [&] {
    auto at = [](int i, int size, double lo, double hi) {
      return std::clamp(static_cast<double>(i) / (size - 1), lo, hi);
    };
    const std::size_t base = static_cast<std::size_t>(z) * kSizeS * kSizeS;
    parallel_for(kSizeS * kSizeS, 0, [&](std::size_t k) {
      const int x = static_cast<int>(k % kSizeS), y = static_cast<int>(k / kSizeS);
      s_[base + k] = fresnel_rise(at(x, kSizeS, 1e-4, 1.0), at(y, kSizeS, 1e-4, 1.0), at(z, kSizeS, 1e-4, 0.99),
                                  kPointsS);
    });
  });
}

void GgxTables::prepare_z(double z) const {
  const Coordinate w = grid(z, kSizeS);
  prepare_plane(w.i0);
  prepare_plane(w.i1);
}

const GgxTables& GgxTables::get() {
  static const GgxTables tables;
  return tables;
}

double GgxTables::E(double roughness, double mu) const {
  const Coordinate x = grid(roughness, kSizeE), y = grid(mu, kSizeE);
  auto row = [&](int j) { return std::lerp(e_[j * kSizeE + x.i0], e_[j * kSizeE + x.i1], x.t); };
  return std::lerp(row(y.i0), row(y.i1), y.t);
}

double GgxTables::E_avg(double roughness) const {
  const Coordinate x = grid(roughness, kSizeE);
  return std::lerp(e_avg_[x.i0], e_avg_[x.i1], x.t);
}

double GgxTables::S(double roughness, double mu, double z) const {
  const Coordinate x = grid(roughness, kSizeS), y = grid(mu, kSizeS), w = grid(z, kSizeS);
  prepare_plane(w.i0);  // once each; PrincipledLobe prepares its planes when it is made
  prepare_plane(w.i1);
  auto row = [&](int j, int k) {
    const std::size_t base = (static_cast<std::size_t>(k) * kSizeS + j) * kSizeS;
    return std::lerp(s_[base + x.i0], s_[base + x.i1], x.t);
  };
  auto plane = [&](int k) { return std::lerp(row(y.i0, k), row(y.i1, k), y.t); };
  return std::lerp(plane(w.i0), plane(w.i1), w.t);
}

PrincipledLobe::PrincipledLobe(int version_, double roughness_, double eta_, bool multiscatter_)
    : version(version_), roughness(roughness_), eta(eta_), multiscatter(version_ == 2 && multiscatter_),
      ggx{roughness_ * roughness_, version_ == 2} {
  const double r = (eta - 1.0) / (eta + 1.0);
  f0_ = r * r;
  z_ = std::sqrt(std::abs(r));
  if (version == 2 && eta > 1.0) GgxTables::get().prepare_z(z_);
  if (multiscatter && eta > 1.0) {
    const double e_avg = GgxTables::get().E_avg(roughness);
    const double fss = average_fresnel_dielectric(eta);
    fms_ = fss * e_avg / (1.0 - fss * (1.0 - e_avg));
  }
}

double PrincipledLobe::specular_factor(double mu) const {
  if (!multiscatter || eta <= 1.0) return 1.0;
  const double e = GgxTables::get().E(roughness, mu);
  return 1.0 + fms_ * (1.0 - e) / e;
}

double PrincipledLobe::diffuse_weight(double mu) const {
  if (version == 1 || eta <= 1.0) return 1.0;
  const GgxTables& t = GgxTables::get();
  double albedo = f0_ + (1.0 - f0_) * t.S(roughness, mu, z_);
  if (multiscatter) {
    const double e = t.E(roughness, mu);
    albedo *= e + fms_ * (1.0 - e);
  }
  return saturate(1.0 - albedo);
}

double PrincipledLobe::diffuse(const Vec3& wo, const Vec3& wi) const {
  if (wo.z() <= 0.0 || wi.z() <= 0.0) return 0.0;
  if (version == 2) return diffuse_weight(wo.z()) * wi.z() / std::numbers::pi;
  // Burley (2012) with retro-reflection, as Cycles 3.x's Principled diffuse.
  const double fv = std::pow(1.0 - wo.z(), 5.0), fl = std::pow(1.0 - wi.z(), 5.0);
  const double rr = roughness * (1.0 + wo.dot(wi));
  const double f = (1.0 - 0.5 * fv) * (1.0 - 0.5 * fl) + rr * (fl + fv + fl * fv * (rr - 1.0));
  return f * wi.z() / std::numbers::pi;
}

double PrincipledLobe::eval(const Vec3& wo, const Vec3& wi) const {
  if (eta <= 1.0 || wo.z() <= 0.0 || wi.z() <= 0.0) return 0.0;
  const Vec3 h = (wo + wi).normalized();
  return fresnel_dielectric(wo.dot(h), eta) * ggx.eval(wo, wi) * specular_factor(wo.z());
}

double PrincipledLobe::pdf(const Vec3& wo, const Vec3& wi) const { return eta <= 1.0 ? 0.0 : ggx.pdf(wo, wi); }

std::optional<LobeSample> PrincipledLobe::sample(const Vec3& wo, const Vec2& u) const {
  if (eta <= 1.0) return std::nullopt;
  auto s = ggx.sample(wo, u);
  if (!s) return std::nullopt;
  const Vec3 h = (wo + s->wi).normalized();
  s->weight *= fresnel_dielectric(wo.dot(h), eta) * specular_factor(wo.z());
  return s;
}

}  // namespace ct::rt
