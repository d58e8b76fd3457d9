#pragma once
// Mean, covariance and principal axes of a cluster of colours.

#include <cstddef>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products of colour directions

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

// The principal axes of a set of colours, about their mean (a cluster's own axes: lines and planes anywhere)
// or about black (the second moments Σ x xᵀ / n: lines and planes through black, the dichromatic model's).
enum class About { Mean, Black };
struct PrincipalAxes {
  std::size_t count = 0;
  Vec3 mean = Vec3::Zero();     // the points' mean (also when taken about black)
  Vec3 values = Vec3::Zero();   // eigenvalues of the moment matrix divided by count, largest first
  Mat3 axes = Mat3::Identity(); // column k: the unit eigenvector of values[k], oriented as principal_axes()
};
// Of every point, or of points[i] for i in `subset` when it is given.
PrincipalAxes principal_axes_of(std::span<const Vec3> points, About about, std::span<const std::size_t> subset = {});

// The eigen-decomposition of a symmetric 3×3 matrix, largest eigenvalue first, each eigenvector's sign
// chosen so that its largest-magnitude component is positive (a stable, printable orientation).
void principal_axes(const Mat3& symmetric, Vec3& eigenvalues, Mat3& axes);

}  // namespace ct::analyzer
