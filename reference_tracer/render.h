// SPDX-License-Identifier: Apache-2.0
#pragma once
// Renders a scene with the reference tracer into a spectral EXR (spectral-exr.md).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/scene.h"
#include "reference_tracer/integrator.h"

namespace ct::rt {

struct RenderOptions {
  std::optional<int> samples;        // default: the scene's render.samples
  std::optional<int> max_bounces;    // default: render.max_bounces
  std::optional<Bands> bands;        // default: render.bands
  std::optional<SpectralMode> mode;  // default: render.spectral_mode
  std::optional<std::uint64_t> seed; // default: render.seed
  ComponentSelection components;
  int threads = 0;                   // 0: all cores
  double time_limit_s = 0.0;         // 0: none; else stop after the pass during which it ran out
  bool progress = true;
};

struct RenderedImage {
  int width = 0, height = 0;
  Bands bands;
  std::vector<std::string> components;
  std::vector<std::vector<float>> layers;  // total, then components; each [y][x][band]
  std::vector<std::int32_t> object_ids;    // [y][x]
  std::map<std::int32_t, std::string> object_names;
  int samples = 0;                         // paths per pixel actually traced
  double seconds = 0.0;
  std::uint64_t paths = 0;
  TracerSettings settings;
};

// Throws InputError naming the option when one is out of range (render() checks too; a command checks first to
// fail before anything else is said or done).
void check_options(const RenderOptions& options);
// Throws InputError when the image `render` would allocate needs more memory than the machine has (render() checks
// too, before allocating).
void check_image_memory(const Scene& scene, const RenderOptions& options);
RenderedImage render(const Scene& scene, const RenderOptions& options);
// Writes the image atomically; `scene` supplies the header's scene and camera description.
void write_render(const std::filesystem::path& path, const Scene& scene, const RenderedImage& image);

}  // namespace ct::rt
