// SPDX-License-Identifier: Apache-2.0
#pragma once
// The spatial non-uniformity as EMVA 1288 Release 4.0 shows it beside its numbers: spectrograms (periodic patterns
// stand out of the white pixel noise), profiles (the row and column means: shading, a column pattern), and the
// logarithmic and accumulated histograms (defect and outlier pixels), of the DSNU image (the mean of the dark frames)
// and of the PRNU image (the mean of the flats at half saturation less the dark mean).

#include <utility>
#include <vector>

#include "calibrate/photon_transfer.h"

namespace ct::calibrate {


// The curves (SpatialCurves, photon_transfer.h) of `image`, its values times `scale` (1 for DN, 100/signal for per
// cent), an image that is a mean of frames and holds `temporal_variance_of_mean` of their temporal noise (in the
// image's units before scaling).
SpatialCurves spatial_curves(const Plane& image, double scale, double temporal_variance_of_mean);

}  // namespace ct::calibrate
