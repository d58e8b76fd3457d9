// SPDX-License-Identifier: Apache-2.0
#pragma once
// The directional albedo ρ(wo) = ∫ f cos θi dωi of a lobe, estimated from the lobe's own samples as the mean
// of their weights (eval / pdf), with its standard error: a known answer the tracer's tests hold lobes and
// renders to.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "reference_tracer/bsdf.h"

namespace ct::test {

struct AlbedoEstimate {
  double mean = 0, se = 0;
};

template <class Lobe>
AlbedoEstimate directional_albedo(const Lobe& lobe, const rt::Vec3& wo, int samples, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < samples; ++i) {
    const auto s = lobe.sample(wo, rt::Vec2(uni(rng), uni(rng)));
    const double w = s ? s->weight : 0.0;
    sum += w;
    sum2 += w * w;
  }
  const double mean = sum / samples;
  return {mean, std::sqrt(std::max(0.0, sum2 / samples - mean * mean) / samples)};
}

}  // namespace ct::test
