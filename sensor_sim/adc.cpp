// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/adc.h"

#include <algorithm>
#include <cmath>

namespace ct::sensor {

double AdcConfig::max_dn() const { return std::ldexp(1.0, bits) - 1.0; }

double digitise(const AdcConfig& adc, double electrons) {
  return std::clamp(std::floor(adc.gain_dn_per_e * electrons + adc.black_level_dn + 0.5), 0.0, adc.max_dn());
}

}  // namespace ct::sensor
