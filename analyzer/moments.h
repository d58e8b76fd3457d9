// SPDX-License-Identifier: Apache-2.0
#pragma once
// Mean, covariance and principal axes of a cluster of colours (the principal axes of any set of colours:
// core/principal_axes.h).

#include <cstddef>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products of colour directions

#include "core/principal_axes.h"

namespace ct::analyzer {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

struct Moments {
  std::size_t count = 0;
  Vec3 mean = Vec3::Zero();
  Mat3 covariance = Mat3::Zero();  // population covariance (divided by count)
  Vec3 eigenvalues = Vec3::Zero();  // of the covariance, largest first
  Mat3 axes = Mat3::Identity();     // column k: the unit eigenvector of eigenvalues[k]
};

// Moments of samples [i][channel]. Partial sums are taken over fixed blocks about each block's first
// sample and merged in block order (Chan, Golub, LeVeque), so the result is accurate for 16-bit values
// of 24-megapixel images and the same bits whatever the thread count.
Moments moments(std::span<const float> rgb, int threads);

}  // namespace ct::analyzer
