// SPDX-License-Identifier: Apache-2.0
#include "reference_tracer/seed_split.h"

#include <algorithm>
#include <charconv>
#include <map>
#include <memory>
#include <set>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_input.h"
#include "core/progress.h"
#include "core/spectral_exr.h"

namespace ct::rt {
namespace fs = std::filesystem;

SeedSplit::SeedSplit(int parts_, int samples_, std::uint64_t first_seed_)
    : parts(parts_), samples(samples_), first_seed(first_seed_) {
  if (parts < 1) throw InputError(fmt::format("--seeds: must be at least 1, got {}", parts));
  if (parts > samples)
    throw InputError(fmt::format("--seeds: {} parts of {} samples would leave a part without samples", parts, samples));
}

int SeedSplit::part_samples(int part) const { return samples / parts + (part < samples % parts ? 1 : 0); }

std::string part_file_name(int part) { return fmt::format("part_{}.exr", part); }

std::vector<fs::path> missing_parts(const std::vector<fs::path>& parts) {
  std::vector<fs::path> missing;
  for (const fs::path& part : parts)
    if (!fs::is_regular_file(part)) missing.push_back(part);
  return missing;
}

namespace {

// Attributes that differ from part to part; every other chromatrace.* attribute must be the same in all.
const std::set<std::string> kPerPart{"chromatrace.samples", "chromatrace.seed", "chromatrace.parts"};
// Written by the EXR writer itself from the layout.
const std::set<std::string> kWriterOwned{"chromatrace.components"};

std::uint64_t integer_attribute(const SpectralExrInfo& info, const std::string& name, std::uint64_t least) {
  const auto it = info.metadata.find(name);
  if (it == info.metadata.end())
    throw InputError(fmt::format("{}: {}: missing (not a chromatrace reference-tracer render)", info.file, name));
  std::uint64_t value = 0;
  const std::string& text = it->second;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < least)
    throw InputError(fmt::format("{}: {}: expected an integer >= {}, got \"{}\"", info.file, name, least, text));
  return value;
}

struct Part {
  SpectralExrReader reader;
  std::uint64_t samples = 0, seed = 0;
};

// `part` must be a tracer render of the same scene, settings and image layout as `first`.
void check_matches(const SpectralExrInfo& first, const SpectralExrInfo& part) {
  const auto differs = [&](std::string_view field) {
    return InputError(fmt::format("{}: {}: differs from {} (parts must be one scene and settings, seeds apart)",
                                  part.file, field, first.file));
  };
  if (part.width != first.width || part.height != first.height) throw differs("size");
  if (part.bands.edges() != first.bands.edges()) throw differs("chromatrace.bandEdgesNm");
  if (part.layers.size() != first.layers.size()) throw differs("layers");
  for (std::size_t l = 0; l < part.layers.size(); ++l)
    if (part.layers[l].channels != first.layers[l].channels) throw differs(fmt::format("layer {}", part.layers[l].name()));
  if (part.has_object_ids != first.has_object_ids) throw differs("object_id");
  if (part.object_names != first.object_names) throw differs("chromatrace.objects");
  std::set<std::string> names;
  for (const auto* info : {&first, &part})
    for (const auto& [name, value] : info->metadata)
      if (name.starts_with("chromatrace.") && !kPerPart.contains(name)) names.insert(name);
  for (const std::string& name : names) {
    const auto a = first.metadata.find(name), b = part.metadata.find(name);
    if (a == first.metadata.end() || b == part.metadata.end() || a->second != b->second) throw differs(name);
  }
}

}  // namespace

void combine_parts(const std::vector<fs::path>& paths, const fs::path& output, bool progress) {
  if (paths.empty()) throw InputError("parts: none given");
  const std::vector<fs::path> missing = missing_parts(paths);
  if (!missing.empty()) {
    std::string names;
    for (const fs::path& p : missing) names += (names.empty() ? "" : ", ") + p.string();
    throw InputError(fmt::format("{} of {} parts missing: {}", missing.size(), paths.size(), names));
  }

  std::vector<std::unique_ptr<Part>> parts;
  std::map<std::uint64_t, std::string> seeds;
  for (const fs::path& path : paths) {
    auto part = std::make_unique<Part>(Part{SpectralExrReader(path)});
    const SpectralExrInfo& info = part->reader.info();
    const auto renderer = info.metadata.find("chromatrace.renderer");
    if (renderer == info.metadata.end() || !renderer->second.starts_with("chromatrace reference tracer"))
      throw InputError(fmt::format("{}: chromatrace.renderer: not a chromatrace reference-tracer render", info.file));
    if (!info.emissive || info.reflective || info.polarised)
      throw InputError(fmt::format("{}: channels: not an emissive tracer render", info.file));
    part->samples = integer_attribute(info, "chromatrace.samples", 1);
    part->seed = integer_attribute(info, "chromatrace.seed", 0);
    if (!parts.empty()) check_matches(parts.front()->reader.info(), info);
    if (const auto [it, fresh] = seeds.emplace(part->seed, info.file); !fresh)
      throw InputError(fmt::format("{}: chromatrace.seed: {} is also the seed of {} (the same samples twice)",
                                   info.file, part->seed, it->second));
    parts.push_back(std::move(part));
  }

  const SpectralExrInfo& first = parts.front()->reader.info();
  SpectralExrLayout layout;
  layout.width = first.width;
  layout.height = first.height;
  layout.bands = first.bands;
  for (const SpectralLayer& layer : first.layers)
    if (!layer.component.empty()) layout.components.push_back(layer.component);
  layout.object_ids = first.has_object_ids;
  layout.object_names = first.object_names;
  for (const auto& [name, value] : first.metadata)
    if (name.starts_with("chromatrace.") && !kPerPart.contains(name) && !kWriterOwned.contains(name))
      layout.attributes[name] = value;
  std::uint64_t total = 0;
  nlohmann::json listing = nlohmann::json::array();
  for (const auto& part : parts) {
    total += part->samples;
    listing.push_back({{"seed", part->seed}, {"samples", part->samples}});
  }
  layout.attributes["chromatrace.samples"] = std::to_string(total);
  layout.attributes["chromatrace.seed"] = std::to_string(parts.front()->seed);
  layout.attributes["chromatrace.parts"] = listing.dump(-1, ' ', false, kReplaceInvalidUtf8);

  SpectralExrWriter writer(output, layout);
  const int width = first.width, height = first.height, bands = static_cast<int>(first.bands.size());
  constexpr int kBlockRows = 16;
  const std::size_t block_values = static_cast<std::size_t>(kBlockRows) * width * bands;
  std::vector<std::vector<float>> combined(first.layers.size(), std::vector<float>(block_values));
  std::vector<double> sum(block_values);
  std::vector<float> values(block_values);
  std::vector<std::int32_t> ids(static_cast<std::size_t>(kBlockRows) * width), other_ids(ids.size());
  Progress bar("combine", static_cast<std::size_t>((height + kBlockRows - 1) / kBlockRows), progress);
  for (int y0 = 0; y0 < height; y0 += kBlockRows) {
    const int y1 = std::min(height, y0 + kBlockRows);
    const std::size_t n = static_cast<std::size_t>(y1 - y0) * width * bands;
    for (std::size_t l = 0; l < first.layers.size(); ++l) {
      std::fill_n(sum.begin(), n, 0.0);
      for (const auto& part : parts) {
        part->reader.read_rows(part->reader.info().layers[l], y0, y1, std::span<float>(values.data(), n));
        const double weight = static_cast<double>(part->samples);
        for (std::size_t i = 0; i < n; ++i) sum[i] += weight * values[i];
      }
      for (std::size_t i = 0; i < n; ++i) combined[l][i] = static_cast<float>(sum[i] / static_cast<double>(total));
    }
    SpectralRowBlock block;
    block.rows = y1 - y0;
    block.total = std::span<const float>(combined[0].data(), n);
    for (std::size_t l = 1; l < combined.size(); ++l) block.components.emplace_back(combined[l].data(), n);
    const std::size_t pixels = static_cast<std::size_t>(y1 - y0) * width;
    if (layout.object_ids) {
      parts.front()->reader.read_object_ids(y0, y1, std::span<std::int32_t>(ids.data(), pixels));
      for (std::size_t p = 1; p < parts.size(); ++p) {
        parts[p]->reader.read_object_ids(y0, y1, std::span<std::int32_t>(other_ids.data(), pixels));
        if (!std::equal(ids.begin(), ids.begin() + static_cast<std::ptrdiff_t>(pixels), other_ids.begin()))
          throw InputError(fmt::format("{}: object_id: rows {}..{} differ from {}", parts[p]->reader.info().file, y0,
                                       y1 - 1, first.file));
      }
      block.object_ids = std::span<const std::int32_t>(ids.data(), pixels);
    }
    writer.write_rows(block);
    bar.advance();
  }
  bar.finish();
  writer.finish();
}

}  // namespace ct::rt
