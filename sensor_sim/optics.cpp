// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/optics.h"

#include <cmath>
#include <numbers>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace ct::sensor {
namespace {

constexpr const char* kCameraAttribute = "chromatrace.camera";

double tan_half(double fov_deg) { return std::tan(fov_deg * std::numbers::pi / 360.0); }

}  // namespace

std::optional<FieldOfView> field_of_view(const SpectralExrInfo& info, std::optional<double> horizontal_fov_deg) {
  const auto it = info.metadata.find(kCameraAttribute);
  if (it != info.metadata.end()) {
    const std::string where = fmt::format("{}: attribute {}", info.file, kCameraAttribute);
    const nlohmann::json camera = nlohmann::json::parse(it->second, nullptr, false);
    if (camera.is_discarded() || !camera.is_object()) throw InputError(fmt::format("{}: not a JSON object", where));
    FieldOfView fov;
    fov.source = kCameraAttribute;
    for (auto [key, value] :
         {std::pair{"horizontal_fov_deg", &fov.horizontal_deg}, std::pair{"vertical_fov_deg", &fov.vertical_deg}}) {
      if (!camera.contains(key) || !camera[key].is_number())
        throw InputError(fmt::format("{}: {}: missing or not a number", where, key));
      *value = camera[key].get<double>();
      if (!(*value > 0 && *value < 180))
        throw InputError(fmt::format("{}: {}: must be in (0, 180) degrees, got {}", where, key, *value));
    }
    return fov;
  }
  if (!horizontal_fov_deg) return std::nullopt;
  // Square pixels: the half-heights of the image plane are in the ratio of the pixel counts.
  const double vertical =
      2.0 * std::atan(tan_half(*horizontal_fov_deg) * info.height / info.width) * 180.0 / std::numbers::pi;
  return FieldOfView{*horizontal_fov_deg, vertical, "optics.fov_deg"};
}

double aperture_factor(double f_number) { return std::numbers::pi / 4.0 / (f_number * f_number); }

Cos4Falloff::Cos4Falloff(const FieldOfView& fov, int width, int height)
    : plane_(ImagePlane::from_fov_deg(fov.horizontal_deg, fov.vertical_deg, width, height)) {
  for (int i = 0; i < width; ++i) x_.push_back(plane_.x(i + 0.5));
  for (int j = 0; j < height; ++j) y_.push_back(plane_.y(j + 0.5));
}

}  // namespace ct::sensor
