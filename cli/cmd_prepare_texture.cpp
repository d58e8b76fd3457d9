// SPDX-License-Identifier: Apache-2.0
// chromatrace prepare-texture IMAGE -o DIR: per-band-group textures for Cycles (the Blender add-on), upsampled
// per texel exactly as the tracer upsamples the original texture (core/texture_prep.h).
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "core/band_plan.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/texture_prep.h"

namespace ct::cli {
namespace {

struct PrepareTextureOptions {
  std::string image, bands, bands_file, kind, colour_space = "auto", output;
  int bands_per_render = 3;
  int threads = 0;
  double scale = 1.0;
  bool json = false, quiet = false, replicate = false, check = false;
};

// --check: the image read and judged as a render would, nothing written; its size and capture noise as JSON.
int check_only(const PrepareTextureOptions& o, TextureUse use, std::optional<TextureColourSpace> colour_space) {
  const ImageTexture texture = read_image_texture(o.image, o.image, colour_space, use, o.scale);
  const Json summary = {{"image", o.image},
                        {"width", texture.width},
                        {"height", texture.height},
                        {"negative_texels", negative_texels_json(texture.negatives)}};
  fmt::print("{}\n", summary.dump(1, ' ', false, kReplaceInvalidUtf8));
  return 0;
}

int run(const PrepareTextureOptions& o) {
  if (!o.bands.empty() && !o.bands_file.empty())
    throw InputError("--bands-file: give either --bands or --bands-file, not both");
  if (o.bands.empty() && o.bands_file.empty() && !o.check)
    throw InputError("--bands: give --bands lo:hi:width or --bands-file PLAN");
  if (o.output.empty() && !o.check) throw InputError("--output: give the output directory (-o DIR)");
  TexturePrepRequest request;
  request.image = o.image;
  if (o.kind == "reflectance") request.use = TextureUse::Reflectance;
  else if (o.kind == "radiance") request.use = TextureUse::Radiance;
  else throw InputError(fmt::format("--kind: expected reflectance or radiance, got \"{}\"", o.kind));
  if (o.colour_space == "sRGB") request.colour_space = TextureColourSpace::Srgb;
  else if (o.colour_space == "linear") request.colour_space = TextureColourSpace::Linear;
  else if (o.colour_space != "auto")
    throw InputError(fmt::format("--colour-space: expected sRGB, linear or auto, got \"{}\"", o.colour_space));
  if (o.check) return check_only(o, request.use, request.colour_space);
  request.bands = o.bands.empty() ? read_band_plan(o.bands_file) : Bands::parse(o.bands, "--bands");
  if (o.bands_per_render < 1 || o.bands_per_render > 3)
    throw InputError(fmt::format("--bands-per-render: must be 1 to 3, got {}", o.bands_per_render));
  request.bands_per_render = o.bands_per_render;
  if (o.replicate && o.bands_per_render != 1)
    throw InputError(fmt::format("--replicate: needs --bands-per-render 1, got {}", o.bands_per_render));
  request.replicate = o.replicate;
  if (!(o.scale >= 0.0) || !std::isfinite(o.scale))
    throw InputError(fmt::format("--scale: must be a finite number >= 0, got {}", o.scale));
  request.scale = o.scale;
  request.threads = o.threads;
  std::vector<std::filesystem::path> inputs = {o.image};
  if (!o.bands_file.empty()) inputs.push_back(o.bands_file);
  check_not_an_input(o.output, inputs);  // the cache directory is created with its parents, if need be
  if (std::filesystem::exists(o.output) && !std::filesystem::is_directory(o.output))
    throw InputError(fmt::format("{}: exists and is not a directory", o.output));

  const TexturePrepResult r = prepare_texture(request, o.output);
  const char* space = r.colour_space == TextureColourSpace::Srgb ? "sRGB" : "linear";
  if (!o.quiet) {
    if (r.had_alpha) fmt::print(stderr, "chromatrace prepare-texture: {}: alpha channel ignored\n", o.image);
    if (r.negatives.count > 0)
      fmt::print(stderr,
                 "chromatrace prepare-texture: {}: {} negative channel values (capture noise, down to {:.3g}, within the "
                 "image's dark end {:.3g}) set to zero\n",
                 o.image, r.negatives.count, -r.negatives.largest, r.negatives.threshold);
    if (r.cached)
      fmt::print(stderr, "chromatrace prepare-texture: {}: cached ({} files for hash {} in {}), nothing to do\n", o.image,
                 r.files.size(), r.hash, o.output);
    else
      fmt::print(stderr, "chromatrace prepare-texture: {}: {}x{} texels ({} colours, {}) -> {} group files in {} ({:.2f} s)\n",
                 o.image, r.width, r.height, r.distinct_colours, space, r.files.size(), o.output, r.seconds);
  }
  if (o.json) {
    Json groups = Json::array();
    for (std::size_t g = 0; g < r.groups.size(); ++g) {
      std::vector<double> centres;
      for (const std::size_t b : r.groups[g]) centres.push_back(request.bands.centre(b));
      groups.push_back({{"group", g}, {"bands", r.groups[g]}, {"centres_nm", centres}, {"file", r.files[g].string()}});
    }
    const Json summary = {{"image", o.image},
                          {"hash", r.hash},
                          {"cached", r.cached},
                          {"kind", o.kind},
                          {"colour_space", space},
                          {"width", r.width},
                          {"height", r.height},
                          {"texels", r.texels},
                          {"distinct_colours", r.distinct_colours},
                          {"alpha_ignored", r.had_alpha},
                          {"negative_texels", negative_texels_json(r.negatives)},
                          {"bands_per_render", request.bands_per_render},
                          {"replicate", request.replicate},
                          {"scale", request.scale},
                          {"manifest", r.manifest.string()},
                          {"groups", groups},
                          {"seconds", r.seconds}};
    fmt::print("{}\n", summary.dump(1, ' ', false, kReplaceInvalidUtf8));
  } else {
    for (const auto& f : r.files) fmt::print("{}\n", f.string());
  }
  return 0;
}

}  // namespace

Action add_prepare_texture(CLI::App& app) {
  auto o = std::make_shared<PrepareTextureOptions>();
  auto* cmd = add_command(app, "prepare-texture");
  cmd->add_option("image", o->image, "image texture or HDRI (any format OpenImageIO reads)")->required();
  cmd->add_option("--bands", o->bands, "Band plan lo:hi:width in nm");
  cmd->add_option("--bands-file", o->bands_file, "Band plan file (chromatrace-bands/1: {\"edges_nm\": [...]})");
  cmd->add_option("--kind", o->kind, "reflectance (texels in [0, 1]) or radiance (lights, environment)")->required();
  cmd->add_option("--colour-space", o->colour_space,
                  "sRGB, linear or auto (auto: linear for float images, sRGB for integer ones)")->capture_default_str();
  cmd->add_option("--bands-per-render", o->bands_per_render, "Bands to a group (1 to 3), as the add-on renders them")->capture_default_str();
  cmd->add_option("--scale", o->scale, "Multiplies every texel's spectrum (a texture's \"scale\")")->capture_default_str();
  cmd->add_flag("--replicate", o->replicate,
                "With --bands-per-render 1: the band in R, G and B (the add-on's one-band fallback), not R alone");
  cmd->add_option("-o,--output", o->output, "Output directory (the cache); not with --check");
  cmd->add_flag("--check", o->check,
                "Read and judge the image as a render would (capture noise zeroed, negative light refused) and print "
                "its size and negative texels as JSON; write nothing");
  cmd->add_option("--threads", o->threads, "Threads (0: all)")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print a JSON summary");
  cmd->add_flag("--quiet", o->quiet, "No messages on stderr");
  return [o] { return run(*o); };
}

}  // namespace ct::cli
