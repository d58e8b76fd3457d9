// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/cfa.h"

#include <algorithm>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace ct::sensor {
namespace {

// The filters of the top-left 2×2 tile, row by row (0 r, 1 g, 2 b).
struct Tile {
  int c[2][2];
};

Tile tile(BayerPattern pattern) {
  switch (pattern) {
    case BayerPattern::RGGB: return {{{0, 1}, {1, 2}}};
    case BayerPattern::BGGR: return {{{2, 1}, {1, 0}}};
    case BayerPattern::GRBG: return {{{1, 0}, {2, 1}}};
    case BayerPattern::GBRG: return {{{1, 2}, {0, 1}}};
  }
  throw std::logic_error("unknown Bayer pattern");
}

// The pattern as seen from an odd row: the tile's rows swap.
BayerPattern shifted_one_row(BayerPattern pattern) {
  switch (pattern) {
    case BayerPattern::RGGB: return BayerPattern::GBRG;
    case BayerPattern::GBRG: return BayerPattern::RGGB;
    case BayerPattern::BGGR: return BayerPattern::GRBG;
    case BayerPattern::GRBG: return BayerPattern::BGGR;
  }
  throw std::logic_error("unknown Bayer pattern");
}

int opencv_code(BayerPattern pattern, DemosaicMethod method) {
  static constexpr int codes[4][3] = {
      {cv::COLOR_BayerRGGB2RGB, cv::COLOR_BayerRGGB2RGB_VNG, cv::COLOR_BayerRGGB2RGB_EA},
      {cv::COLOR_BayerBGGR2RGB, cv::COLOR_BayerBGGR2RGB_VNG, cv::COLOR_BayerBGGR2RGB_EA},
      {cv::COLOR_BayerGRBG2RGB, cv::COLOR_BayerGRBG2RGB_VNG, cv::COLOR_BayerGRBG2RGB_EA},
      {cv::COLOR_BayerGBRG2RGB, cv::COLOR_BayerGBRG2RGB_VNG, cv::COLOR_BayerGBRG2RGB_EA},
  };
  return codes[static_cast<int>(pattern)][static_cast<int>(method)];
}

template <typename T>
void demosaic_as(std::span<const float> mosaic, int width, int rows, int code, std::span<float> rgb) {
  cv::Mat raw(rows, width, cv::DataType<T>::type);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < width; ++x)
      raw.at<T>(y, x) = static_cast<T>(
          mosaic[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)]);
  cv::Mat out;
  cv::demosaicing(raw, out, code, 3);
  for (int y = 0; y < rows; ++y) {
    const T* row = out.ptr<T>(y);
    for (std::size_t i = 0; i < static_cast<std::size_t>(width) * 3; ++i)
      rgb[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) * 3 + i] = static_cast<float>(row[i]);
  }
}

}  // namespace

int cfa_channel(BayerPattern pattern, int x, int y) { return tile(pattern).c[y & 1][x & 1]; }

RowRange demosaic_context(int y0, int y1, int height) {
  constexpr int margin = 4, edge_rows = 8;
  RowRange r{std::max(0, y0 - margin), std::min(height, y1 + margin)};
  if (r.first == 0) r.last = std::max(r.last, std::min(height, edge_rows));
  if (r.last == height) r.first = std::min(r.first, std::max(0, height - edge_rows));
  return r;
}

void demosaic(std::span<const float> mosaic, int width, int rows, int y0, BayerPattern pattern, DemosaicMethod method,
              int bits, std::span<float> rgb) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(rows);
  if (mosaic.size() != pixels || rgb.size() != 3 * pixels)
    throw std::invalid_argument("demosaic: buffer sizes do not match the rows");
  if (bits > demosaic_max_bits(method)) throw std::invalid_argument("demosaic: too many bits for the method");
  const int code = opencv_code((y0 & 1) ? shifted_one_row(pattern) : pattern, method);
  if (bits <= 8)
    demosaic_as<std::uint8_t>(mosaic, width, rows, code, rgb);
  else
    demosaic_as<std::uint16_t>(mosaic, width, rows, code, rgb);
}

}  // namespace ct::sensor
