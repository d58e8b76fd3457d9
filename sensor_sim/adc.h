// SPDX-License-Identifier: Apache-2.0
#pragma once
// The end of stage 5 (docs/sensor.md): conversion gain, black level and the analogue-to-digital converter.

#include "sensor_sim/config.h"

namespace ct::sensor {

// Digital numbers from electrons: y = round(K·e + black) clipped to [0, 2^bits − 1]. Rounding adds the
// uniform quantisation noise σ_q² = 1/12 DN² of EMVA 1288.
double digitise(const AdcConfig& adc, double electrons);

}  // namespace ct::sensor
