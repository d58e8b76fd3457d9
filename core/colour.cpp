// SPDX-License-Identifier: Apache-2.0
#include "core/colour.h"

#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "core/cie.h"

namespace ct {
namespace {

// The CMFs are tabulated over 360–830 nm and zero outside, so every XYZ integral runs over that range.
constexpr double kCmfLo = 360.0;
constexpr double kCmfHi = 830.0;

Eigen::Matrix3d srgb_to_xyz_matrix() {
  // IEC 61966-2-1 primaries and D65 white chromaticities; the matrix follows from them (the standard's
  // printed 4-decimal matrix is a rounding of this one).
  const double prim[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
  Eigen::Matrix3d p;
  for (int c = 0; c < 3; ++c) {
    const double x = prim[c][0], y = prim[c][1];
    p.col(c) << x / y, 1.0, (1.0 - x - y) / y;
  }
  const Vec3d w = d65_white();
  const Eigen::Vector3d scale = p.colPivHouseholderQr().solve(Eigen::Vector3d(w[0], w[1], w[2]));
  return p * scale.asDiagonal();
}

const Eigen::Matrix3d& to_xyz() {
  static const Eigen::Matrix3d m = srgb_to_xyz_matrix();
  return m;
}

const Eigen::Matrix3d& from_xyz() {
  static const Eigen::Matrix3d m = to_xyz().inverse();
  return m;
}

Vec3d apply(const Eigen::Matrix3d& m, const Vec3d& v) {
  const Eigen::Vector3d r = m * Eigen::Vector3d(v[0], v[1], v[2]);
  return {r[0], r[1], r[2]};
}

double deg(double rad) { return rad * 180.0 / std::numbers::pi; }
double rad(double deg) { return deg * std::numbers::pi / 180.0; }

}  // namespace

Vec3d spectrum_to_xyz(const PiecewiseLinearSpectrum& s) {
  return {integral_of_product(s, cie::x_bar(), kCmfLo, kCmfHi), integral_of_product(s, cie::y_bar(), kCmfLo, kCmfHi),
          integral_of_product(s, cie::z_bar(), kCmfLo, kCmfHi)};
}

std::array<std::vector<double>, 3> xyz_band_weights(const Bands& bands) {
  std::array<std::vector<double>, 3> w;
  const PiecewiseLinearSpectrum* cmf[3] = {&cie::x_bar(), &cie::y_bar(), &cie::z_bar()};
  for (int c = 0; c < 3; ++c) {
    w[c] = band_weights(bands, [&](double lo, double hi) { return cmf[c]->integral(lo, hi); });
  }
  return w;
}

Vec3d bands_to_xyz(const std::vector<double>& values, const Bands& bands) {
  const auto w = xyz_band_weights(bands);
  Vec3d xyz{};
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < bands.size(); ++i) xyz[c] += values[i] * w[c][i];
  return xyz;
}

Vec3d reflectance_to_xyz(const PiecewiseLinearSpectrum& reflectance, const PiecewiseLinearSpectrum& illuminant) {
  const double norm = integral_of_product(illuminant, cie::y_bar(), kCmfLo, kCmfHi);
  return {integral_of_product(reflectance, illuminant, cie::x_bar(), kCmfLo, kCmfHi) / norm,
          integral_of_product(reflectance, illuminant, cie::y_bar(), kCmfLo, kCmfHi) / norm,
          integral_of_product(reflectance, illuminant, cie::z_bar(), kCmfLo, kCmfHi) / norm};
}

Vec3d xyz_to_xyY(const Vec3d& xyz) {
  const double sum = xyz[0] + xyz[1] + xyz[2];
  if (sum == 0.0) return {0.0, 0.0, 0.0};
  return {xyz[0] / sum, xyz[1] / sum, xyz[1]};
}

Vec3d xyY_to_xyz(const Vec3d& xyY) {
  if (xyY[1] == 0.0) return {0.0, 0.0, 0.0};
  return {xyY[0] * xyY[2] / xyY[1], xyY[2], (1.0 - xyY[0] - xyY[1]) * xyY[2] / xyY[1]};
}

std::array<double, 2> chromaticity(const PiecewiseLinearSpectrum& emission) {
  const Vec3d xyY = xyz_to_xyY(spectrum_to_xyz(emission));
  return {xyY[0], xyY[1]};
}

Vec3d xyz_to_lab(const Vec3d& xyz, const Vec3d& white) {
  // CIE 15:2004 with the exact constants ε = (6/29)³, κ = (29/3)³ of the continuous definition.
  constexpr double eps = 216.0 / 24389.0;
  constexpr double kappa = 24389.0 / 27.0;
  auto f = [](double t) { return t > eps ? std::cbrt(t) : (kappa * t + 16.0) / 116.0; };
  const double fx = f(xyz[0] / white[0]), fy = f(xyz[1] / white[1]), fz = f(xyz[2] / white[2]);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Vec3d lab_to_xyz(const Vec3d& lab, const Vec3d& white) {
  constexpr double eps = 216.0 / 24389.0;
  constexpr double kappa = 24389.0 / 27.0;
  const double fy = (lab[0] + 16.0) / 116.0;
  const double fx = fy + lab[1] / 500.0;
  const double fz = fy - lab[2] / 200.0;
  auto finv = [](double f) { return f * f * f > eps ? f * f * f : (116.0 * f - 16.0) / kappa; };
  const double yr = lab[0] > kappa * eps ? fy * fy * fy : lab[0] / kappa;
  return {finv(fx) * white[0], yr * white[1], finv(fz) * white[2]};
}

double delta_e_2000(const Vec3d& lab1, const Vec3d& lab2, double kL, double kC, double kH) {
  // G. Sharma, W. Wu, E. N. Dalal, "The CIEDE2000 color-difference formula: implementation notes,
  // supplementary test data, and mathematical observations", Color Res. Appl. 30(1), 2005, eq. 1–22.
  const double L1 = lab1[0], a1 = lab1[1], b1 = lab1[2];
  const double L2 = lab2[0], a2 = lab2[1], b2 = lab2[2];
  const double C1 = std::hypot(a1, b1), C2 = std::hypot(a2, b2);
  const double Cbar7 = std::pow(0.5 * (C1 + C2), 7.0);
  const double G = 0.5 * (1.0 - std::sqrt(Cbar7 / (Cbar7 + std::pow(25.0, 7.0))));
  const double a1p = (1.0 + G) * a1, a2p = (1.0 + G) * a2;
  const double C1p = std::hypot(a1p, b1), C2p = std::hypot(a2p, b2);
  auto hue = [](double b, double ap) {
    if (b == 0.0 && ap == 0.0) return 0.0;
    const double h = deg(std::atan2(b, ap));
    return h < 0.0 ? h + 360.0 : h;
  };
  const double h1p = hue(b1, a1p), h2p = hue(b2, a2p);

  const double dLp = L2 - L1;
  const double dCp = C2p - C1p;
  double dhp = 0.0;
  if (C1p * C2p != 0.0) {
    dhp = h2p - h1p;
    if (dhp > 180.0) dhp -= 360.0;
    else if (dhp < -180.0) dhp += 360.0;
  }
  const double dHp = 2.0 * std::sqrt(C1p * C2p) * std::sin(rad(dhp) / 2.0);

  const double Lbarp = 0.5 * (L1 + L2);
  const double Cbarp = 0.5 * (C1p + C2p);
  double hbarp = h1p + h2p;
  if (C1p * C2p != 0.0) {
    if (std::abs(h1p - h2p) <= 180.0) hbarp *= 0.5;
    else hbarp = (h1p + h2p < 360.0) ? 0.5 * (h1p + h2p + 360.0) : 0.5 * (h1p + h2p - 360.0);
  }
  const double T = 1.0 - 0.17 * std::cos(rad(hbarp - 30.0)) + 0.24 * std::cos(rad(2.0 * hbarp)) +
                   0.32 * std::cos(rad(3.0 * hbarp + 6.0)) - 0.20 * std::cos(rad(4.0 * hbarp - 63.0));
  const double dTheta = 30.0 * std::exp(-std::pow((hbarp - 275.0) / 25.0, 2.0));
  const double Cbarp7 = std::pow(Cbarp, 7.0);
  const double RC = 2.0 * std::sqrt(Cbarp7 / (Cbarp7 + std::pow(25.0, 7.0)));
  const double Lm50sq = (Lbarp - 50.0) * (Lbarp - 50.0);
  const double SL = 1.0 + 0.015 * Lm50sq / std::sqrt(20.0 + Lm50sq);
  const double SC = 1.0 + 0.045 * Cbarp;
  const double SH = 1.0 + 0.015 * Cbarp * T;
  const double RT = -std::sin(rad(2.0 * dTheta)) * RC;

  const double l = dLp / (kL * SL), c = dCp / (kC * SC), h = dHp / (kH * SH);
  return std::sqrt(l * l + c * c + h * h + RT * c * h);
}

Vec3d d65_white() { return xyY_to_xyz({0.3127, 0.3290, 1.0}); }

Vec3d xyz_to_linear_srgb(const Vec3d& xyz) { return apply(from_xyz(), xyz); }
Vec3d linear_srgb_to_xyz(const Vec3d& rgb) { return apply(to_xyz(), rgb); }

double srgb_encode(double v) {
  // Odd extension for negative values (as scRGB), so out-of-gamut colours survive a round trip.
  const double a = std::abs(v);
  const double e = a <= 0.0031308 ? 12.92 * a : 1.055 * std::pow(a, 1.0 / 2.4) - 0.055;
  return std::copysign(e, v);
}

double srgb_decode(double v) {
  const double a = std::abs(v);
  const double d = a <= 0.04045 ? a / 12.92 : std::pow((a + 0.055) / 1.055, 2.4);
  return std::copysign(d, v);
}

}  // namespace ct
