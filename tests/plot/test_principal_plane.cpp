// SPDX-License-Identifier: Apache-2.0
// The principal plane of a set of colours: for points spread along two known orthogonal directions the plane is
// theirs, with the variance shares their spreads give, oriented for reading.
#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "plot/principal_plane.h"

namespace ct::plot {
namespace {

using Vec3 = Eigen::Vector3d;

// Four points m ± 3u ± v: the covariance is 9 uuᵀ + vvᵀ, so the axes are u and v with shares 0.9 and 0.1.
std::vector<Vec3> cross_of(const Vec3& m, const Vec3& u, const Vec3& v) {
  std::vector<Vec3> points;
  for (const double a : {-1.0, 1.0})
    for (const double b : {-1.0, 1.0}) points.push_back(m + 3 * a * u + b * v);
  return points;
}

TEST(PrincipalPlane, AxesAndSharesOfAKnownSpread) {
  const Vec3 u = Vec3(1, 1, 1).normalized(), v = Vec3(1, -2, 1).normalized();
  const PrincipalPlane plane = principal_plane(cross_of(Vec3(0.2, 0.3, 0.4), u, v));
  EXPECT_NEAR((plane.axis[0] - u).norm(), 0, 1e-12);   // its components sum to ≥ 0 as they are
  EXPECT_NEAR((plane.axis[1] + v).norm(), 0, 1e-12);   // turned so that its largest component, G's, is positive
  EXPECT_NEAR(plane.share[0], 0.9, 1e-12);
  EXPECT_NEAR(plane.share[1], 0.1, 1e-12);
}

// The first axis points the way its components sum positive (brighter to the right), even where its largest
// component is then negative.
TEST(PrincipalPlane, FirstAxisPointsTowardsBrighter) {
  const Vec3 u = Vec3(1, -0.9, -0.9).normalized();
  const Vec3 v = u.cross(Vec3(0, 0, 1)).normalized();
  const PrincipalPlane plane = principal_plane(cross_of(Vec3(0.5, 0.5, 0.5), u, v));
  EXPECT_NEAR((plane.axis[0] + u).norm(), 0, 1e-12);
  EXPECT_GE(plane.axis[0].sum(), 0);
  EXPECT_NEAR(std::abs(plane.axis[1].dot(v)), 1, 1e-12);
}

TEST(PrincipalPlane, TooFewPointsOrNoSpreadGiveTheAchromaticPlane) {
  for (const std::vector<Vec3>& points : {std::vector<Vec3>{Vec3(1, 0, 0), Vec3(0, 1, 0)}, std::vector<Vec3>(5, Vec3(0.1, 0.2, 0.3))}) {
    const PrincipalPlane plane = principal_plane(points);
    EXPECT_NEAR((plane.axis[0] - Vec3(1, 1, 1).normalized()).norm(), 0, 1e-15);
    EXPECT_NEAR((plane.axis[1] - Vec3(1, 0, -1).normalized()).norm(), 0, 1e-15);
    EXPECT_EQ(plane.share[0], 0);
    EXPECT_EQ(plane.share[1], 0);
  }
}

}  // namespace
}  // namespace ct::plot
