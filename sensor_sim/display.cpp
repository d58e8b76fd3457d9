// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/display.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>
#include <fmt/core.h>

#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/rgb_to_spectrum.h"

namespace ct::sensor {
namespace {

Eigen::Matrix3d xyz_to_srgb_matrix() {
  Eigen::Matrix3d m;
  for (int c = 0; c < 3; ++c) {
    Vec3d unit{0, 0, 0};
    unit[static_cast<std::size_t>(c)] = 1;
    const Vec3d rgb = xyz_to_linear_srgb(unit);
    for (int r = 0; r < 3; ++r) m(r, c) = rgb[static_cast<std::size_t>(r)];
  }
  return m;
}

// The XYZ of the training reflectances lit by D65, perfect white at Y = 1.
const std::vector<Eigen::Vector3d>& training_targets() {
  static const std::vector<Eigen::Vector3d> targets = [] {
    std::vector<Eigen::Vector3d> t;
    for (const PiecewiseLinearSpectrum& r : display_training_reflectances()) {
      const Vec3d xyz = reflectance_to_xyz(r, cie::illuminant("D65"));
      t.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
    return t;
  }();
  return targets;
}

}  // namespace

const std::vector<PiecewiseLinearSpectrum>& display_training_reflectances() {
  static const std::vector<PiecewiseLinearSpectrum> reflectances = [] {
    constexpr double kLevels[] = {0.03, 0.2, 0.5, 0.85};
    std::vector<PiecewiseLinearSpectrum> r;
    for (const double red : kLevels)
      for (const double green : kLevels)
        for (const double blue : kLevels) r.push_back(rgb_to_spectrum({red, green, blue}));
    return r;
  }();
  return reflectances;
}

Eigen::Vector3d white_response(const std::array<std::vector<double>, 3>& weights, const std::vector<double>& illuminant) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::size_t ch = 0; ch < 3; ++ch)
    for (std::size_t b = 0; b < illuminant.size(); ++b) c[static_cast<int>(ch)] += weights[ch][b] * illuminant[b];
  return c;
}

namespace {

// M: white-balanced camera signals of the training reflectances lit by `illuminant` (band values) → `targets`, the
// white-preserving least-squares fit (M·(1, 1, 1) = target_white).
Eigen::Matrix3d fit_white_preserving(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                                     const std::vector<double>& illuminant, const std::vector<Eigen::Vector3d>& targets,
                                     const Vec3d& target_white) {
  if (illuminant.size() != bands.size() || weights[0].size() != bands.size())
    throw std::invalid_argument("camera_to_xyz: band counts differ");
  const Eigen::Vector3d white = white_response(weights, illuminant);
  if (!(white.minCoeff() > 0))
    throw InputError(fmt::format(
        "display: the illuminant gives no signal in some camera channel over the image's bands ({:g}-{:g} nm)",
        bands.min_wavelength(), bands.max_wavelength()));
  const auto& reflectances = display_training_reflectances();
  const Eigen::Index n = static_cast<Eigen::Index>(reflectances.size());
  Eigen::MatrixXd x(n, 3), y(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::vector<double> r = band_averages(reflectances[static_cast<std::size_t>(i)], bands);
    std::vector<double> lit(r.size());
    for (std::size_t b = 0; b < r.size(); ++b) lit[b] = r[b] * illuminant[b];
    x.row(i) = white_response(weights, lit).cwiseQuotient(white).transpose();
    y.row(i) = targets[static_cast<std::size_t>(i)].transpose();
  }
  // Each row m of M: min ‖x·m − y_r‖² subject to (1, 1, 1)·m = W_r (white stays white). The KKT system
  // [2xᵀx 1; 1ᵀ 0]·[m; ν] = [2xᵀy_r; W_r].
  Eigen::Matrix4d kkt = Eigen::Matrix4d::Zero();
  kkt.topLeftCorner<3, 3>() = 2 * x.transpose() * x;
  kkt.block<3, 1>(0, 3).setOnes();
  kkt.block<1, 3>(3, 0).setOnes();
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(kkt);
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    Eigen::Vector4d rhs;
    rhs.head<3>() = 2 * x.transpose() * y.col(r);
    rhs[3] = target_white[static_cast<std::size_t>(r)];
    m.row(r) = lu.solve(rhs).head<3>().transpose();
  }
  return m;
}

}  // namespace

Eigen::Matrix3d camera_to_xyz(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                              const std::vector<double>& illuminant) {
  // Targets: the reflectances lit by D65; white: the XYZ of sRGB white.
  return fit_white_preserving(weights, bands, illuminant, training_targets(), linear_srgb_to_xyz({1, 1, 1}));
}

Eigen::Matrix3d camera_to_xyz_unadapted(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                                        const PiecewiseLinearSpectrum& illuminant) {
  std::vector<Eigen::Vector3d> targets;
  for (const PiecewiseLinearSpectrum& r : display_training_reflectances()) {
    const Vec3d xyz = reflectance_to_xyz(r, illuminant);
    targets.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  const Vec3d white = reflectance_to_xyz(PiecewiseLinearSpectrum::constant(1.0), illuminant);
  return fit_white_preserving(weights, bands, band_averages(illuminant, bands), targets, white);
}

Eigen::Matrix3d display_matrix(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                               const std::vector<double>& illuminant) {
  static const Eigen::Matrix3d srgb = xyz_to_srgb_matrix();
  const Eigen::Vector3d white = white_response(weights, illuminant);
  return srgb * camera_to_xyz(weights, bands, illuminant) * white.cwiseInverse().asDiagonal();
}

Eigen::Vector3d display_value(const DisplayRendering& d, const Eigen::Vector3d& camera) {
  const Eigen::Vector3d v = display_linear(d, camera);
  Eigen::Vector3d out;
  for (int c = 0; c < 3; ++c) out[c] = std::isfinite(v[c]) ? srgb_encode(std::clamp(v[c], 0.0, 1.0)) : 0.0;
  return out;
}

}  // namespace ct::sensor
