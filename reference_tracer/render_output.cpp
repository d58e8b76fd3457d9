// SPDX-License-Identifier: Apache-2.0
// write_render: a render written as a spectral EXR. Apart from render.cpp so that the tracer itself, which
// `chromatrace check-scene` runs through plan's model, is linked without OpenEXR (chromatrace_tracer_core).
#include <cmath>
#include <filesystem>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/json_input.h"
#include "core/spectral_exr.h"
#include "reference_tracer/render.h"

namespace ct::rt {

void write_render(const std::filesystem::path& path, const Scene& scene, const RenderedImage& image) {
  SpectralExrLayout layout;
  layout.width = image.width;
  layout.height = image.height;
  layout.bands = image.bands;
  layout.components = image.components;
  layout.object_ids = true;
  layout.object_names = image.object_names;
  const Camera& c = scene.camera;
  const nlohmann::json camera = {
      {"position", {c.position.x(), c.position.y(), c.position.z()}},
      {"look_at", {c.look_at.x(), c.look_at.y(), c.look_at.z()}},
      {"up", {c.up.x(), c.up.y(), c.up.z()}},
      {"fov_deg", c.fov_deg},
      {"horizontal_fov_deg", 2.0 * std::atan(c.tan_half_width()) * 180.0 / M_PI},
      {"vertical_fov_deg", 2.0 * std::atan(c.tan_half_height()) * 180.0 / M_PI},
      {"sensor_width_mm", c.sensor_width_mm},
      {"focal_length_mm", c.focal_length_mm()},
      {"resolution", {c.width, c.height}}};
  layout.attributes["chromatrace.renderer"] = fmt::format("chromatrace reference tracer ({} mode, max {} bounces)",
                                              image.settings.mode == SpectralMode::Bands ? "bands" : "continuous",
                                              image.settings.max_bounces);
  layout.attributes["chromatrace.samples"] = std::to_string(image.samples);
  layout.attributes["chromatrace.seed"] = std::to_string(image.settings.seed);
  layout.attributes["chromatrace.scene"] = scene.json.dump(-1, ' ', false, kReplaceInvalidUtf8);
  // Where its relative paths (textures, spectra, meshes) resolve, for a reader of the scene (compare's white).
  if (!scene.directory.empty()) layout.attributes["chromatrace.scene_directory"] = std::filesystem::absolute(scene.directory).string();
  layout.attributes["chromatrace.camera"] = camera.dump(-1, ' ', false, kReplaceInvalidUtf8);

  write_spectral_exr(path, std::move(layout), image.layers, image.object_ids);
}

}  // namespace ct::rt
