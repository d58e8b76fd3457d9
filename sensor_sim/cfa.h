// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stage 4 of the sensor model (docs/sensor.md): a Bayer colour filter array keeps one channel per pixel, and
// OpenCV's demosaicing (bilinear, VNG, edge-aware) brings back three from the digital numbers, as a camera's
// processing does after the ADC. OpenCV demosaics 8- and 16-bit integers only (VNG: 8-bit), which is why
// the CFA needs the ADC (config.cpp checks it).

#include <span>

#include "sensor_sim/config.h"

namespace ct::sensor {

// The channel (0 r, 1 g, 2 b) whose filter covers pixel (x, y). The pattern names the filters of the 2×2
// tile at the top-left corner, row by row: RGGB is R G over G B.
int cfa_channel(BayerPattern pattern, int x, int y);

// The rows [first, last) that demosaicing must see so that rows [y0, y1) of a `height`-row image come out as
// they do when the whole image is demosaiced. OpenCV's VNG, the widest method, needs 4 rows either side of a
// row, and fills the rows next to an edge of its input from inner rows; so a block takes 4 rows of context
// each way, and a block at an edge of the image takes the first (last) 8 rows, which hold those inner rows and
// their context (tests/sensor_sim/test_cfa.cpp checks every block size against the whole image).
struct RowRange {
  int first, last;
};
RowRange demosaic_context(int y0, int y1, int height);

// Demosaics `rows` rows of a width-wide mosaic of whole digital numbers in [0, 2^bits − 1] whose first row
// is image row `y0` (its parity fixes where the pattern starts). `rgb` receives rows·width·3 values.
void demosaic(std::span<const float> mosaic, int width, int rows, int y0, BayerPattern pattern, DemosaicMethod method,
              int bits, std::span<float> rgb);

}  // namespace ct::sensor
