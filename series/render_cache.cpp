// SPDX-License-Identifier: Apache-2.0
#include "series/render_cache.h"

#include <cstdint>
#include <filesystem>
#include <string_view>

#include <fmt/core.h>

#include "core/band_plan.h"
#include "core/file_io.h"
#include "core/json_input.h"

namespace ct::series {
namespace {

// FNV-1a, 64 bits: a cache key, not a cryptographic hash.
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 0xcbf29ce484222325ull) {
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

// The scene with every file it names replaced by a hash of the file's bytes: a changed spectrum or mesh
// changes the key, a moved folder does not.
void hash_named_files(Json& document) {
  for_each_scene_path(document, [](Json& path) {
    path = fmt::format("fnv1a:{:016x}", fnv1a(read_file(path.get<std::string>())));
  });
}

// A program by its path, size and modification time (nothing when it cannot be read: the key still holds the path).
Json executable_identity(const std::filesystem::path& program) {
  Json identity = {{"path", program.string()}};
  std::error_code error;
  const auto resolved = std::filesystem::canonical(program, error);
  if (error) return identity;
  const auto size = std::filesystem::file_size(resolved, error);
  if (!error) identity["size"] = size;
  const auto time = std::filesystem::last_write_time(resolved, error);
  if (!error) identity["modified"] = static_cast<std::int64_t>(time.time_since_epoch().count());
  return identity;
}

}  // namespace

Json render_inputs(const Scene& scene, const RunOptions& options) {
  Json document = scene.json;
  document.erase("name");
  document.erase("description");
  hash_named_files(document);
  const Bands& bands = options.bands ? *options.bands : scene.render.bands;
  Json inputs = {{"renderer", renderer_name(options.renderer)},
          {"scene", document},
          {"width", options.width.value_or(scene.camera.width)},
          {"height", options.height.value_or(scene.camera.height)},
          {"samples", options.spp.value_or(scene.render.samples)},
          {"seed", options.seed.value_or(scene.render.seed)},
          {"max_bounces", options.max_bounces.value_or(scene.render.max_bounces)},
          {"bands", bands.edges()},
          {"components", options.components}};
  // The reconstruction changes no pixel's band values, but the file carries it and every colour made of them.
  if (const BandReconstruction* r = bands.reconstruction()) inputs["reconstruction"] = reconstruction_json(*r);
  if (!options.cycles_samples.empty()) inputs["cycles_samples"] = options.cycles_samples;
  if (!options.cycles_guided_groups.empty()) {
    inputs["cycles_guided_groups"] = options.cycles_guided_groups;
    inputs["cycles_guided_threshold"] = options.cycles_guided_threshold;
  }
  // Another Blender is another Cycles (its GGX masking, its sampling): the executable, and its size and time, so
  // that one upgraded in place renders again too.
  if (options.renderer == Renderer::Cycles) inputs["blender"] = executable_identity(options.blender);
  return inputs;
}

std::string render_key(const Json& inputs) { return fmt::format("{:016x}", fnv1a(inputs.dump(-1, ' ', false, kReplaceInvalidUtf8))); }

}  // namespace ct::series
