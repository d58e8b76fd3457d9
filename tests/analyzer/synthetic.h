// SPDX-License-Identifier: Apache-2.0
#pragma once
// Synthetic images of known histogram structure, made by the tests (nothing binary is committed).
//
// Each image lays its colours out smoothly over the pixel grid, as shading and highlights do on real
// objects, so that the neighbour-difference noise estimate sees noise, not structure. Colours follow the
// dichromatic model I = m_b·body + m_s·illuminant unless said otherwise; all values are linear, in [0, 1].

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/moments.h"

namespace ct::test {

using analyzer::RgbImage;
using analyzer::Vec3;

inline const Vec3 kBody = Vec3(0.8, 0.45, 0.25).normalized();
inline const Vec3 kIlluminant = Vec3(1.0, 0.93, 0.8).normalized();

// width × height pixels; pixel (x, y) gets colour(u, v) with u = x / (width − 1), v = y / (height − 1).
template <class F>
RgbImage make_image(int width, int height, F colour) {
  RgbImage image{width, height, std::vector<float>(static_cast<std::size_t>(width) * height * 3)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Vec3 c = colour(x / double(width - 1), y / double(height - 1));
      for (int k = 0; k < 3; ++k) image.rgb[(static_cast<std::size_t>(y) * width + x) * 3 + k] = static_cast<float>(c[k]);
    }
  return image;
}

// The shapes, noise-free, 128 × 128.
RgbImage matte_line();      // m_b from 0.05 to 1
RgbImage l_shape();         // matte, plus a narrow highlight leaving the body line at its bright end
RgbImage skewed_t();        // … leaving it half-way
RgbImage p_shape();         // a broad highlight filling an area beside the body line
RgbImage curved_cluster();  // a bent (parabolic) cluster no power curve straightens
RgbImage clipped_line();    // a matte line over-exposed so that red clips at 1
RgbImage gamma_line();      // a line with an ambient offset, encoded with I' = I^(1/2.2)
RgbImage thickened_plane(); // an L whose pixels are pushed off its plane by a smooth third colour
RgbImage small_highlight_l(); // an L whose highlight holds 0.5 % of the pixels (a small sphere's highlight)
RgbImage fork_shape();      // two lines diverging from near black: one object lit by two light colours
RgbImage thickened_line();  // a matte line whose colour turns a little, both ways, across the object (interreflection)
inline const Vec3 kSecondLight = Vec3(0.55, 0.95, 0.5).normalized();  // the fork's second light colour
inline constexpr double kGamma = 1 / 2.2;

// A scene of several dichromatic objects (different body colours, one illuminant), each a block of pixels
// with its own object id (1…count); background id 0 is black. Four spheres of `size` pixels in a 2 × 2 grid.
struct Scene {
  RgbImage image;
  std::vector<std::int32_t> ids;
  std::map<std::int32_t, std::string> names;
};
Scene dichromatic_scene(const Vec3& illuminant, int size = 96);

// Shot noise (Poisson in electrons, full scale = full_well electrons) and Gaussian read noise (read_noise
// electrons), with a fixed seed; values stay in the image's scale.
RgbImage add_sensor_noise(const RgbImage& image, double full_well, double read_noise, std::uint32_t seed);

// Writes an EXR the way the sensor simulator does (R,G,B, linear.*, <component>.*, object_id and the
// chromatrace.objects / chromatrace.components attributes).
struct SensorExr {
  RgbImage final_image;
  RgbImage linear;
  std::vector<std::pair<std::string, RgbImage>> components;
  std::vector<std::int32_t> ids;
  std::map<std::int32_t, std::string> names;
};
void write_sensor_exr(const std::filesystem::path& file, const SensorExr& exr);
// The same as the analyzer reads it from such a file.
analyzer::AnalysisImage analysis_image(const SensorExr& exr);

// A matte object (id 1, "wall"), 64 × 64, lit by two luminaires: light.warm's colour is body ∘ warm, light.cool's
// body ∘ cool, their shares varying across it (share_b of the light is cool's on average).
SensorExr two_luminaires(double share_b, const Vec3& warm, const Vec3& cool);
// Two matte objects side by side, 64 × 64, each shaded top to bottom: ids 1 ("left", x < 32) and 2 ("right").
// With pixel-area integration (box_filter) column 31 records a mix: 75 % object 1, 25 % object 2.
SensorExr two_objects_edge(bool box_filter);
// A plain 8- or 16-bit RGB file (PNG/TIFF by extension), values in [0, 1] scaled to full scale.
void write_rgb(const std::filesystem::path& file, const RgbImage& image, int bits);

// A dichromatic scene with component layers: diffuse_direct, glossy_direct, diffuse_indirect (a
// smooth third colour), summing to linear; final = linear.
SensorExr scene_with_components();

}  // namespace ct::test
