// SPDX-License-Identifier: Apache-2.0
#include "reference_tracer/bsdf.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace ct::rt {
namespace {

constexpr double kInvPi = 1.0 / std::numbers::pi;

bool same_hemisphere_above(const Vec3& wo, const Vec3& wi) { return wo.z() > 0.0 && wi.z() > 0.0; }

}  // namespace

Frame::Frame(const Vec3& normal) : n(normal) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  s = Vec3(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  t = Vec3(b, sign + n.y() * n.y() * a, -n.y());
}

Vec2 sample_concentric_disk(const Vec2& u) {
  const Vec2 p = 2.0 * u - Vec2(1.0, 1.0);
  if (p.x() == 0.0 && p.y() == 0.0) return Vec2::Zero();
  double r, phi;
  if (std::abs(p.x()) > std::abs(p.y())) {
    r = p.x();
    phi = std::numbers::pi / 4.0 * (p.y() / p.x());
  } else {
    r = p.y();
    phi = std::numbers::pi / 2.0 - std::numbers::pi / 4.0 * (p.x() / p.y());
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

Vec3 sample_cosine_hemisphere(const Vec2& u) {
  const Vec2 d = sample_concentric_disk(u);
  return {d.x(), d.y(), std::sqrt(std::max(0.0, 1.0 - d.squaredNorm()))};
}

// ---- Lambert ----

double LambertLobe::eval(const Vec3& wo, const Vec3& wi) const {
  return same_hemisphere_above(wo, wi) ? wi.z() * kInvPi : 0.0;
}

double LambertLobe::pdf(const Vec3& wo, const Vec3& wi) const { return eval(wo, wi); }

std::optional<LobeSample> LambertLobe::sample(const Vec3& wo, const Vec2& u) const {
  if (wo.z() <= 0.0) return std::nullopt;
  const Vec3 wi = sample_cosine_hemisphere(u);
  if (wi.z() <= 0.0) return std::nullopt;
  return LobeSample{wi, 1.0, wi.z() * kInvPi};
}

// ---- GGX ----

double GgxLobe::D(const Vec3& h) const {
  if (h.z() <= 0.0) return 0.0;
  const double a2 = alpha * alpha;
  const double c2 = h.z() * h.z();
  const double denom = c2 * (a2 - 1.0) + 1.0;
  return a2 / (std::numbers::pi * denom * denom);
}

double GgxLobe::Lambda(const Vec3& w) const {
  const double c2 = w.z() * w.z();
  if (w.z() <= 0.0) return std::numeric_limits<double>::infinity();
  const double tan2 = std::max(0.0, 1.0 - c2) / c2;
  return 0.5 * (std::sqrt(1.0 + alpha * alpha * tan2) - 1.0);
}

double GgxLobe::G1(const Vec3& w) const { return 1.0 / (1.0 + Lambda(w)); }

double GgxLobe::G2(const Vec3& wo, const Vec3& wi) const {
  return height_correlated ? 1.0 / (1.0 + Lambda(wo) + Lambda(wi)) : G1(wo) * G1(wi);
}

double GgxLobe::eval(const Vec3& wo, const Vec3& wi) const {
  if (!same_hemisphere_above(wo, wi)) return 0.0;
  const Vec3 h = (wo + wi).normalized();
  return D(h) * G2(wo, wi) / (4.0 * wo.z());
}

double GgxLobe::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!same_hemisphere_above(wo, wi)) return 0.0;
  const Vec3 h = (wo + wi).normalized();
  return G1(wo) * D(h) / (4.0 * wo.z());
}

std::optional<LobeSample> GgxLobe::sample(const Vec3& wo, const Vec2& u) const {
  if (wo.z() <= 0.0) return std::nullopt;
  // Visible-normal sampling: stretch to the unit-roughness configuration, sample the projected
  // hemisphere, unstretch (E. Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018).
  const Vec3 vh = Vec3(alpha * wo.x(), alpha * wo.y(), wo.z()).normalized();
  const double len2 = vh.x() * vh.x() + vh.y() * vh.y();
  const Vec3 t1 = len2 > 0.0 ? Vec3(-vh.y(), vh.x(), 0.0) / std::sqrt(len2) : Vec3(1.0, 0.0, 0.0);
  const Vec3 t2 = vh.cross(t1);
  const double r = std::sqrt(u.x());
  const double phi = 2.0 * std::numbers::pi * u.y();
  const double p1 = r * std::cos(phi);
  const double s = 0.5 * (1.0 + vh.z());
  const double p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * r * std::sin(phi);
  const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  const Vec3 h = Vec3(alpha * nh.x(), alpha * nh.y(), std::max(1e-12, nh.z())).normalized();
  const Vec3 wi = 2.0 * wo.dot(h) * h - wo;
  if (wi.z() <= 0.0) return std::nullopt;
  const double g1 = G1(wo);
  const double p = g1 * D(h) / (4.0 * wo.z());
  // eval / pdf reduces to G2(wo, wi) / G1(wo): G1(wi) for separable masking.
  return LobeSample{wi, G2(wo, wi) / g1, p};
}

// ---- Phong ----

double PhongLobe::eval(const Vec3& wo, const Vec3& wi) const {
  if (!same_hemisphere_above(wo, wi)) return 0.0;
  const double c = reflect_about_normal(wo).dot(wi);
  if (c <= 0.0) return 0.0;
  return (exponent + 2.0) / (2.0 * std::numbers::pi) * std::pow(c, exponent) * wi.z();
}

double PhongLobe::pdf(const Vec3& wo, const Vec3& wi) const {
  if (!same_hemisphere_above(wo, wi)) return 0.0;
  const double c = reflect_about_normal(wo).dot(wi);
  if (c <= 0.0) return 0.0;
  return (exponent + 1.0) / (2.0 * std::numbers::pi) * std::pow(c, exponent);
}

std::optional<LobeSample> PhongLobe::sample(const Vec3& wo, const Vec2& u) const {
  if (wo.z() <= 0.0) return std::nullopt;
  const double cos_a = std::pow(u.x(), 1.0 / (exponent + 1.0));
  const double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
  const double phi = 2.0 * std::numbers::pi * u.y();
  const Frame lobe(reflect_about_normal(wo));
  const Vec3 wi = lobe.to_world(Vec3(sin_a * std::cos(phi), sin_a * std::sin(phi), cos_a));
  if (wi.z() <= 0.0) return std::nullopt;
  const double p = (exponent + 1.0) / (2.0 * std::numbers::pi) * std::pow(cos_a, exponent);
  return LobeSample{wi, (exponent + 2.0) / (exponent + 1.0) * wi.z(), p};
}

// ---- Mirror ----

std::optional<LobeSample> MirrorLobe::sample(const Vec3& wo, const Vec2&) const {
  if (wo.z() <= 0.0) return std::nullopt;
  return LobeSample{reflect_about_normal(wo), 1.0, std::numeric_limits<double>::infinity()};
}

}  // namespace ct::rt
