#include "series/render_cache.h"

#include <cstdint>
#include <string_view>

#include <fmt/core.h>

#include "core/band_plan.h"
#include "core/file_io.h"

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
  return inputs;
}

std::string render_key(const Json& inputs) { return fmt::format("{:016x}", fnv1a(inputs.dump())); }

}  // namespace ct::series
