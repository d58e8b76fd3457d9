// SPDX-License-Identifier: Apache-2.0
#pragma once
// The principal curve of a bent cluster: a cubic in the position along the principal axis. Its bend
// (sagitta over chord) measures how much a "banana" or a gamma-bent line departs from a straight line.

#include <array>
#include <vector>

#include "analyzer/moments.h"

namespace ct::analyzer {

struct PrincipalCurve {
  // x(t) ≈ mean + t·axes.col(0) + Σ_k u_k s^k · axes.col(1) + Σ_k v_k s^k · axes.col(2), k = 0…3,
  // s = (t − t_mid) / half_length, t ∈ [t_min, t_max].
  Vec3 mean = Vec3::Zero();
  Mat3 axes = Mat3::Identity();
  std::array<double, 4> u{}, v{};
  double t_min = 0, t_max = 0;
  double straight_rms = 0;  // rms distance from the best straight line
  double curve_rms = 0;     // rms distance from the curve
  double bend = 0;          // largest distance of the curve from its chord, over the chord's length
  double curvature = 0;     // at the middle of the curve, 1 / colour units
  double explained = 0;     // 1 − curve_rms² / straight_rms²: the share of the off-line spread the bend explains

  Vec3 at(double t) const;
};

// Fits the curve to points about the principal axes of their moments.
PrincipalCurve fit_principal_curve(const std::vector<Vec3>& points, const Moments& moments);

}  // namespace ct::analyzer
