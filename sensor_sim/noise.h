// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stage 5 of the sensor model up to the ADC (EMVA 1288 linear camera model, docs/sensor.md): the electrons a
// pixel holds at the end of the exposure and the read noise added as they are read out.
//
// Every random number is a pure function of (seed, pixel, channel) through ct::Random, so an image is the
// same whatever the thread count and the block size. Temporal noise (shot, read) is keyed by noise.seed (a
// new frame); the fixed pattern (DSNU, PRNU) by noise.pattern_seed (a sensor), so frames of one sensor share it.

#include <cstdint>

#include "core/random.h"
#include "sensor_sim/config.h"

namespace ct::sensor {

// A Poisson variate: exact, by inversion for means below 10 and by Hörmann's transformed rejection (PTRS,
// "The transformed rejection method for generating Poisson random variables", 1993) above.
std::uint64_t poisson(double mean, Random& random);
// A standard normal variate (Box–Muller).
double standard_normal(Random& random);

// A sensor pixel: its index y·width + x, its row y and its column x.
struct PixelSite {
  std::uint64_t index = 0;
  std::uint32_t row = 0, column = 0;
};

// The electrons read from channel `channel` of sensor pixel `site` whose noise-free mean photo-electron count is
// `photo_e`, exposed for `exposure_s`:
//   e = Poisson((1 + prnu·z₁ + prnu_row·r₁ + prnu_column·c₁)·photo_e + I_d·T) + dsnu·z₂ + dsnu_row·r₂ + dsnu_column·c₂,
// clipped to the full well, + Normal(0, σ_read), with z the pixel's fixed-pattern normal variates, r its row's and c
// its column's (EMVA 1288 Release 4.0 splits the non-uniformities the same way). Without noise:
// e = min(photo_e + I_d·T, full well).
double read_out_electrons(const NoiseConfig& noise, const FullWellConfig& full_well, double exposure_s, double photo_e,
                          const PixelSite& site, int channel);

}  // namespace ct::sensor
