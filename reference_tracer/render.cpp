// SPDX-License-Identifier: Apache-2.0
#include "reference_tracer/render.h"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <mutex>

#include <fmt/core.h>

#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace ct::rt {
namespace {

constexpr int kTileSize = 16;

}  // namespace

void check_options(const RenderOptions& o) {
  if (o.samples && *o.samples < 1) throw InputError(fmt::format("--spp: must be at least 1, got {}", *o.samples));
  if (o.max_bounces && (*o.max_bounces < 0 || *o.max_bounces > kMaxBounces))
    throw InputError(fmt::format("--max-bounces: must be in [0, {}], got {}", kMaxBounces, *o.max_bounces));
  if (!(o.time_limit_s >= 0) || !std::isfinite(o.time_limit_s))
    throw InputError(fmt::format("--time-limit: must be a finite number of seconds >= 0 (0: no limit), got {}", o.time_limit_s));
  if (o.threads < 0) throw InputError(fmt::format("--threads: must be >= 0, got {}", o.threads));
}

void check_image_memory(const Scene& scene, const RenderOptions& options) {
  // The light groups in TracerScene's order: the lights' (a light without one is its own), then the environment's.
  std::vector<std::string> groups;
  auto add = [&](const std::string& g) {
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
  };
  for (const Light& light : scene.lights) add(light.group.empty() ? light.name : light.group);
  if (scene.environment) add(scene.environment->group);
  const LayerPlan plan =
      plan_layers(options.components, groups, options.max_bounces.value_or(scene.render.max_bounces));
  const int w = scene.camera.width, h = scene.camera.height;
  const int nb = static_cast<int>(options.bands.value_or(scene.render.bands).size());
  // Before allocating: an image of 10^9 x 10^9 pixels or of 10^6 bands is bad input, not a process to kill.
  check_memory((static_cast<double>(plan.layer_count()) * nb * sizeof(float) + sizeof(std::int32_t)) * w * h,
               fmt::format("the image ({}x{} pixels, {} bands, {} layers: the resolution, --bands and --components)",
                           w, h, nb, plan.layer_count()));
}

RenderedImage render(const Scene& scene, const RenderOptions& options) {
  check_options(options);
  const auto start = std::chrono::steady_clock::now();
  TracerSettings settings;
  settings.max_bounces = options.max_bounces.value_or(scene.render.max_bounces);
  settings.mode = options.mode.value_or(scene.render.spectral_mode);
  settings.bands = options.bands.value_or(scene.render.bands);
  settings.seed = options.seed.value_or(scene.render.seed);
  settings.box_filter = scene.render.pixel_filter == PixelFilter::Box;
  settings.threads = options.threads;
  const int spp = options.samples.value_or(scene.render.samples);

  const TracerScene tracer_scene(scene, options.threads);
  const LayerPlan plan = plan_layers(options.components, tracer_scene.groups(), settings.max_bounces);
  const PathTracer tracer(tracer_scene, settings, plan);

  RenderedImage image;
  image.width = scene.camera.width;
  image.height = scene.camera.height;
  image.bands = settings.bands;
  image.components = plan.components;
  image.settings = settings;
  const int w = image.width, h = image.height, nb = static_cast<int>(settings.bands.size());
  const std::size_t layer_size = static_cast<std::size_t>(w) * h * nb;
  check_image_memory(scene, options);
  image.layers.assign(static_cast<std::size_t>(plan.layer_count()), std::vector<float>(layer_size, 0.0f));
  image.object_ids.resize(static_cast<std::size_t>(w) * h);
  for (const Object& o : scene.objects) image.object_names[o.id] = o.name;
  for (const Light& l : scene.lights) image.object_names[l.id] = l.name;

  // Passes of samples: all at once without a time limit; otherwise growing passes so the limit is honoured
  // to within about one pass while early passes stay cheap.
  std::vector<int> passes;
  if (options.time_limit_s <= 0.0) {
    passes.push_back(spp);
  } else {
    for (int done = 0, step = 1; done < spp; done += step, step = std::min(step * 2, 64))
      passes.push_back(std::min(step, spp - done));
  }

  const std::size_t tiles = tile_count(w, h, kTileSize);
  Progress progress("render", tiles * passes.size(), options.progress);
  int first_sample = 0;
  for (const int pass : passes) {
    parallel_for(tiles, options.threads, [&](std::size_t index) {
      const Tile tile = tile_at(w, h, kTileSize, index);
      PixelAccumulator pixel(plan.layer_count(), nb);
      for (int y = tile.y0; y < tile.y1; ++y)
        for (int x = tile.x0; x < tile.x1; ++x) {
          pixel.clear();
          const std::uint64_t pixel_index = static_cast<std::uint64_t>(y) * w + x;
          for (int s = first_sample; s < first_sample + pass; ++s) {
            const std::uint64_t stream = (pixel_index << 32) | static_cast<std::uint64_t>(s);
            const auto [px, py] = tracer.film_position(x, y, stream);
            tracer.trace(px, py, stream, pixel);
          }
          const std::size_t offset = pixel_index * nb;
          for (int l = 0; l < plan.layer_count(); ++l) {
            const double* sum = pixel.layer(l);
            float* out = image.layers[static_cast<std::size_t>(l)].data() + offset;
            for (int b = 0; b < nb; ++b) out[b] += static_cast<float>(sum[b]);
          }
          if (first_sample == 0) image.object_ids[pixel_index] = tracer.object_id_at(x, y);
        }
      progress.advance();
    });
    first_sample += pass;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (options.time_limit_s > 0.0 && elapsed >= options.time_limit_s) break;
  }
  progress.finish();

  image.samples = first_sample;
  const float inv = 1.0f / static_cast<float>(first_sample);
  for (auto& layer : image.layers)
    for (float& v : layer) v *= inv;
  image.paths = static_cast<std::uint64_t>(w) * h * first_sample;
  image.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return image;
}

}  // namespace ct::rt
