// SPDX-License-Identifier: Apache-2.0
#include "core/assembly.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>

#include <fmt/core.h>

#include "core/band_plan.h"
#include "core/error.h"
#include "core/exr_vocabulary.h"
#include "core/guided.h"
#include "core/json_input.h"
#include "core/progress.h"
#include "core/spectral_channel_name.h"
#include "core/spectral_exr.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

constexpr int kBlockRows = 32;

// ---- the manifest ------------------------------------------------------------------------------------

// The index of a render file in `inputs`, added on first use so that each file is opened once.
std::size_t input_index(std::vector<AssemblyInput>& inputs, const fs::path& path) {
  const auto it = std::find_if(inputs.begin(), inputs.end(), [&](const AssemblyInput& i) { return i.path == path; });
  if (it != inputs.end()) return static_cast<std::size_t>(it - inputs.begin());
  inputs.push_back({path, {}});
  return inputs.size() - 1;
}

// The index of a channel in the input's list, added on first use so that each channel is read once.
std::size_t channel_index(AssemblyInput& input, const std::string& channel) {
  std::vector<std::string>& list = input.channels;
  const auto it = std::find(list.begin(), list.end(), channel);
  if (it != list.end()) return static_cast<std::size_t>(it - list.begin());
  list.push_back(channel);
  return list.size() - 1;
}

// The terms of one expression (total or component) for every band.
std::vector<PassSum> read_terms(const JsonNode& node, const std::vector<JsonNode>& bands,
                                const std::string& view_layer, const fs::path& directory,
                                std::vector<AssemblyInput>& inputs) {
  std::vector<PassSum> per_band(bands.size());
  const std::vector<JsonNode> terms = node.elements();
  if (terms.empty()) node.fail("needs at least one term");
  for (const JsonNode& term : terms) {
    term.expect_object({"file", "passes", "sign"});
    const std::string key = term.find("file") ? term["file"].non_empty_string() : "main";
    const double sign = term.find("sign") ? static_cast<double>(term["sign"].integer_in(-1, 1)) : 1.0;
    if (sign == 0.0) term["sign"].fail("must be 1 or -1, got 0");
    const std::vector<JsonNode> passes = term["passes"].elements();
    if (passes.empty()) term["passes"].fail("needs at least one pass");
    for (std::size_t b = 0; b < bands.size(); ++b) {
      const auto file = bands[b]["files"].find(key);
      if (!file) (term.has("file") ? term["file"] : term).fail(fmt::format("bands[{}].files has no \"{}\"", b, key));
      PassProduct product;
      product.sign = sign;
      product.input = input_index(inputs, (directory / file->non_empty_string()).lexically_normal());
      const std::string channel = bands[b]["channel"].non_empty_string();
      for (const JsonNode& pass : passes) {
        const std::string name = pass.non_empty_string();
        product.channels.push_back(
            channel_index(inputs[product.input], (view_layer.empty() ? "" : view_layer + ".") + name + "." + channel));
      }
      per_band[b].push_back(std::move(product));
    }
  }
  return per_band;
}

Bands read_edges(const JsonNode& edges_nm) {
  std::vector<double> edges;
  for (const JsonNode& e : edges_nm.elements()) edges.push_back(e.number());
  if (edges.size() < 2) edges_nm.fail(fmt::format("needs at least 2 edges, got {}", edges.size()));
  for (std::size_t i = 1; i < edges.size(); ++i)
    if (!(edges[i] > edges[i - 1]))
      edges_nm.fail(fmt::format("edges must increase, but {} follows {}", edges[i], edges[i - 1]));
  return Bands::from_edges(edges, edges_nm.location());
}

void read_components(const JsonNode& components, const std::vector<JsonNode>& bands, const std::string& view_layer,
                     const fs::path& directory, AssemblyManifest& manifest) {
  for (const JsonNode& c : components.elements()) {
    c.expect_object({"name", "terms"});
    const std::string name = c["name"].non_empty_string();
    if (component_family(name) == ComponentFamily::Unknown)
      c["name"].fail(fmt::format("\"{}\" is not one of emission, diffuse_direct, diffuse_indirect, glossy_direct, "
                                 "glossy_indirect, transmission_direct, transmission_indirect, light.<group>, bounce.<k>",
                                 name));
    if (std::find(manifest.components.begin(), manifest.components.end(), name) != manifest.components.end())
      c["name"].fail(fmt::format("\"{}\" is listed twice", name));
    manifest.components.push_back(name);
    manifest.component_sums.push_back(read_terms(c["terms"], bands, view_layer, directory, manifest.inputs));
  }
}

std::map<std::int32_t, std::string> read_object_names(const JsonNode& names) {
  std::map<std::int32_t, std::string> object_names;
  for (const auto& [key, value] : names.members()) {
    char* end = nullptr;
    const long id = std::strtol(key.c_str(), &end, 10);
    if (key.empty() || *end != '\0' || id < 0 || id > exr::kMaxObjectId)
      names.fail(fmt::format("key \"{}\" is not an object id (a whole number in [0, {}])", key, exr::kMaxObjectId));
    object_names[static_cast<std::int32_t>(id)] = value.string();
  }
  return object_names;
}

std::map<std::string, std::string> read_attributes(const JsonNode& attributes) {
  std::map<std::string, std::string> result;
  for (const auto& [key, value] : attributes.members()) {
    if (!key.starts_with("chromatrace.") || key.size() == 12)
      value.fail(fmt::format("attribute \"{}\" must be named chromatrace.<key>", key));
    result[key] = value.string();
  }
  return result;
}

GuidedAssembly read_guided(const JsonNode& node, std::size_t band_count) {
  node.expect_object({"bands", "radius", "false_refusal", "adaptive"});
  GuidedAssembly guided;
  std::vector<bool> seen(band_count, false);
  for (const JsonNode& band : node["bands"].elements()) {
    const auto b = static_cast<std::size_t>(band.integer_in(0, static_cast<std::int64_t>(band_count) - 1));
    if (seen[b]) band.fail(fmt::format("band {} given twice", b));
    seen[b] = true;
    guided.bands.push_back(b);
  }
  if (guided.bands.empty()) node["bands"].fail("names no band");
  if (guided.bands.size() == band_count) node["bands"].fail("names every band: none is left to guide them");
  if (const auto radius = node.find("radius")) guided.radius = static_cast<int>(radius->integer_in(1, 64));
  if (const auto p = node.find("false_refusal")) guided.false_refusal = p->number_in(1e-12, 0.5);
  if (const auto adaptive = node.find("adaptive")) {
    adaptive->expect_object({"threshold", "max_samples"});
    guided.adaptive_threshold = (*adaptive)["threshold"].number_in(1e-4, 1.0);
    guided.adaptive_max_samples =
        static_cast<int>((*adaptive)["max_samples"].integer_in(1, std::numeric_limits<int>::max()));
  }
  return guided;
}

// ---- the driver --------------------------------------------------------------------------------------

// Opens every render and checks that they are all of one size.
std::vector<SpectralExrReader> open_inputs(const AssemblyManifest& manifest) {
  std::vector<SpectralExrReader> readers;
  for (const AssemblyInput& input : manifest.inputs) readers.emplace_back(input.path);
  const SpectralExrInfo& first = readers[0].info();
  for (const SpectralExrReader& r : readers)
    if (r.info().width != first.width || r.info().height != first.height)
      throw InputError(fmt::format("{}: image size {} x {} differs from {} ({} x {})", r.info().file, r.info().width,
                                   r.info().height, first.file, first.width, first.height));
  return readers;
}

SpectralExrLayout output_layout(const AssemblyManifest& manifest, int width, int height) {
  SpectralExrLayout layout;
  layout.width = width;
  layout.height = height;
  layout.bands = manifest.bands;
  layout.components = manifest.components;
  layout.object_ids = manifest.object_ids.has_value();
  layout.object_names = manifest.object_names;
  layout.attributes = manifest.attributes;
  return layout;
}

// A missing pass is bad input: say so before any pixel.
void check_channels_present(const AssemblyManifest& manifest, const std::vector<SpectralExrReader>& readers) {
  for (std::size_t i = 0; i < readers.size(); ++i)
    for (const std::string& channel : manifest.inputs[i].channels) {
      const auto& present = readers[i].info().channels;
      if (std::none_of(present.begin(), present.end(), [&](const ExrChannel& c) { return c.name == channel; }))
        throw InputError(fmt::format("{}: no channel {}", readers[i].info().file, channel));
    }
}

// One block of rows of every input: [input][row][x][channel], in the manifest's channel order.
struct InputBlock {
  int y0 = 0, rows = 0, width = 0;
  std::vector<std::vector<float>> values;

  std::size_t pixels() const { return static_cast<std::size_t>(rows) * static_cast<std::size_t>(width); }
  std::size_t x(std::size_t pixel) const { return pixel % static_cast<std::size_t>(width); }
  std::size_t y(std::size_t pixel) const {
    return static_cast<std::size_t>(y0) + pixel / static_cast<std::size_t>(width);
  }
};

// Reads rows [y0, y0 + rows) into `block`, reusing its buffers.
void read_block(const AssemblyManifest& manifest, std::vector<SpectralExrReader>& readers, int y0, int rows,
                InputBlock& block) {
  block.y0 = y0;
  block.rows = rows;
  block.values.resize(readers.size());
  for (std::size_t i = 0; i < readers.size(); ++i) {
    const std::vector<std::string>& channels = manifest.inputs[i].channels;
    block.values[i].assign(block.pixels() * channels.size(), 0.0f);
    readers[i].read_channels(channels, y0, y0 + rows, block.values[i]);
    // A NaN or infinity would pass every sum check (NaN compares false) and reach the spectral file unseen.
    const auto bad = std::find_if(block.values[i].begin(), block.values[i].end(), [](float v) { return !std::isfinite(v); });
    if (bad != block.values[i].end()) {
      const std::size_t k = static_cast<std::size_t>(bad - block.values[i].begin()), pixel = k / channels.size();
      throw InputError(fmt::format("{}: channel {}: value {} at pixel ({}, {}) is not finite", manifest.inputs[i].path.string(),
                                   channels[k % channels.size()], *bad, block.x(pixel), block.y(pixel)));
    }
  }
}

// The value of a sum of products of passes at one pixel of the block, in double.
double evaluate(const PassSum& terms, const AssemblyManifest& manifest, const InputBlock& block, std::size_t pixel) {
  double sum = 0.0;
  for (const PassProduct& t : terms) {
    const std::size_t stride = manifest.inputs[t.input].channels.size();
    double product = t.sign;
    for (const std::size_t channel : t.channels) product *= block.values[t.input][pixel * stride + channel];
    sum += product;
  }
  return sum;
}

// The block's pixels as the output file has them, [row][x][band] each.
struct OutputBlock {
  std::vector<float> total;
  std::vector<std::vector<float>> components;
  std::vector<std::int32_t> object_ids;
};

// Evaluates the total and the components at every pixel and band and reconciles the families.
void assemble_values(const AssemblyManifest& manifest, const std::vector<SummingFamily>& families,
                     const InputBlock& block, OutputBlock& out) {
  const std::size_t nb = manifest.bands.size(), nc = manifest.components.size();
  out.total.assign(block.pixels() * nb, 0.0f);
  out.components.assign(nc, std::vector<float>(block.pixels() * nb));
  std::vector<double> value(nc);
  for (std::size_t p = 0; p < block.pixels(); ++p)
    for (std::size_t b = 0; b < nb; ++b) {
      const double t = evaluate(manifest.total[b], manifest, block, p);
      for (std::size_t c = 0; c < nc; ++c) value[c] = evaluate(manifest.component_sums[c][b], manifest, block, p);
      if (const auto mismatch = reconcile_families(t, value, families, manifest.sum_tolerance))
        throw InputError(fmt::format(
            "{}: the {} sum to {:.9g} but the total is {:.9g} at pixel ({}, {}), band {} ({}-{} nm): "
            "more than rounding (sum_tolerance {})",
            manifest.file, families[mismatch->family].name, mismatch->sum, t, block.x(p), block.y(p), b,
            manifest.bands.lo(b), manifest.bands.hi(b), manifest.sum_tolerance));
      out.total[p * nb + b] = static_cast<float>(t);
      for (std::size_t c = 0; c < nc; ++c) out.components[c][p * nb + b] = static_cast<float>(value[c]);
    }
}

// The block's object ids, which the renderer wrote as floats.
void convert_object_ids(const AssemblyManifest& manifest, const InputBlock& block, OutputBlock& out) {
  out.object_ids.clear();
  if (!manifest.object_ids) return;
  const AssemblyInput& input = manifest.inputs[manifest.object_ids->input];
  const std::size_t stride = input.channels.size(), channel = manifest.object_ids->channel;
  for (std::size_t p = 0; p < block.pixels(); ++p) {
    const float v = block.values[manifest.object_ids->input][p * stride + channel];
    if (!exr::is_object_id(v))
      throw InputError(fmt::format("{}: channel {}: value {} at pixel ({}, {}) is not an object id",
                                   input.path.string(), input.channels[channel], v, block.x(p), block.y(p)));
    out.object_ids.push_back(static_cast<std::int32_t>(v));
  }
}

}  // namespace

AssemblyManifest read_assembly_manifest(const fs::path& file) {
  AssemblyManifest manifest;
  manifest.file = file.string();
  const Json document = read_json(file);
  const JsonNode root(document, manifest.file);
  const std::string format = root["format"].string();
  if (format != "chromatrace-assemble/1")
    root["format"].fail(fmt::format("must be \"chromatrace-assemble/1\", got \"{}\"", format));
  root.expect_object({"format", "edges_nm", "reconstruction", "view_layer", "bands", "total", "components", "object_ids",
                      "object_names", "attributes", "sum_tolerance", "guided"});
  const fs::path directory = file.parent_path();
  manifest.bands = read_edges(root["edges_nm"]);
  if (const auto r = root.find("reconstruction")) manifest.bands = read_reconstruction(*r, manifest.bands);

  const std::string view_layer = root.find("view_layer") ? root["view_layer"].string() : "";
  const std::vector<JsonNode> bands = root["bands"].elements();
  if (bands.size() != manifest.bands.size())
    root["bands"].fail(fmt::format("{} entries for {} bands (edges_nm has {} edges)", bands.size(),
                                   manifest.bands.size(), manifest.bands.edges().size()));
  for (const JsonNode& band : bands) {
    band.expect_object({"channel", "files"});
    if (band["files"].members().empty()) band["files"].fail("names no files");
  }
  manifest.total = read_terms(root["total"], bands, view_layer, directory, manifest.inputs);
  if (const auto components = root.find("components"))
    read_components(*components, bands, view_layer, directory, manifest);
  if (const auto ids = root.find("object_ids")) {
    ids->expect_object({"file", "channel"});
    const fs::path file_path = (directory / (*ids)["file"].non_empty_string()).lexically_normal();
    const std::size_t input = input_index(manifest.inputs, file_path);
    const std::size_t channel = channel_index(manifest.inputs[input], (*ids)["channel"].non_empty_string());
    manifest.object_ids = ObjectIdChannel{input, channel};
  }
  if (const auto names = root.find("object_names")) {
    if (!manifest.object_ids) names->fail("object names given without object_ids");
    manifest.object_names = read_object_names(*names);
  }
  if (const auto attributes = root.find("attributes")) manifest.attributes = read_attributes(*attributes);
  if (const auto tolerance = root.find("sum_tolerance")) manifest.sum_tolerance = tolerance->number_in(0.0, 1.0);
  if (const auto guided = root.find("guided")) manifest.guided = read_guided(*guided, manifest.bands.size());
  return manifest;
}

std::vector<SummingFamily> summing_families(const std::vector<std::string>& components) {
  std::vector<SummingFamily> families;
  for (const ComponentFamily family : {ComponentFamily::PathType, ComponentFamily::LightGroup, ComponentFamily::Bounce}) {
    std::vector<std::size_t> members;
    std::vector<std::string> names;
    for (std::size_t c = 0; c < components.size(); ++c)
      if (component_family(components[c]) == family) {
        members.push_back(c);
        names.push_back(components[c]);
      }
    if (members.empty() || (family == ComponentFamily::PathType && !path_types_complete(names))) continue;
    families.push_back({std::string(family_name(family)), std::move(members)});
  }
  return families;
}

std::optional<FamilyMismatch> reconcile_families(double total, std::span<double> components,
                                                 std::span<const SummingFamily> families, double tolerance) {
  for (std::size_t f = 0; f < families.size(); ++f) {
    const std::vector<std::size_t>& members = families[f].members;
    double sum = 0.0, magnitude = std::abs(total);
    std::size_t largest = members[0];
    for (const std::size_t c : members) {
      sum += components[c];
      magnitude += std::abs(components[c]);
      if (std::abs(components[c]) > std::abs(components[largest])) largest = c;
    }
    const double residual = total - sum;
    // Relative to the pixel's magnitude, as float rounding is; 1e-30 is a floor for pixels so dark that
    // rounding among float's denormals is no longer relative.
    if (std::abs(residual) > tolerance * magnitude + 1e-30) return FamilyMismatch{f, sum};
    components[largest] += residual;
  }
  return std::nullopt;
}

namespace {

// The image held whole for guided reconstruction, filled block by block.
GuidedImage whole_image(const AssemblyManifest& manifest, int width, int height) {
  GuidedImage image;
  image.width = width, image.height = height, image.bands = manifest.bands.size();
  image.components = manifest.components;
  const std::size_t values = static_cast<std::size_t>(width) * height * image.bands;
  image.layers.assign(1 + manifest.components.size(), std::vector<float>(values));
  if (manifest.object_ids) image.object_ids.assign(static_cast<std::size_t>(width) * height, 0);
  image.colours.resize(image.layers.size());
  return image;
}

// Where a component is one product of a light pass and a colour pass in every band (Cycles' DiffDir × DiffCol,
// GlossDir × GlossCol, … as "<view_layer>.Diffuse Color.R" in Blender 5), the channel index of each, by band.
struct LightTimesColour {
  std::vector<std::size_t> light, colour;  // [band]: indices into the product's input's channels
};

std::vector<std::optional<LightTimesColour>> light_times_colour(const AssemblyManifest& manifest) {
  std::vector<std::optional<LightTimesColour>> found(manifest.components.size());
  // The pass of "<view_layer>.<pass>.<channel>" (a view layer's name may hold dots; a pass's does not).
  const auto is_colour = [&](const PassProduct& t, std::size_t k) {
    const std::string& channel = manifest.inputs[t.input].channels[t.channels[k]];
    const std::size_t last = channel.rfind('.');
    const std::size_t before = last == std::string::npos || last == 0 ? std::string::npos : channel.rfind('.', last - 1);
    const std::string pass = channel.substr(before == std::string::npos ? 0 : before + 1,
                                            last == std::string::npos ? std::string::npos : last - (before + 1));
    return pass.find("Col") != std::string::npos;
  };
  for (std::size_t c = 0; c < manifest.components.size(); ++c) {
    LightTimesColour split;
    for (const PassSum& sum : manifest.component_sums[c]) {
      if (sum.size() != 1 || sum[0].channels.size() != 2 || sum[0].sign != 1.0) break;
      const bool first_is_colour = is_colour(sum[0], 0);
      if (first_is_colour == is_colour(sum[0], 1)) break;
      split.light.push_back(sum[0].channels[first_is_colour ? 1 : 0]);
      split.colour.push_back(sum[0].channels[first_is_colour ? 0 : 1]);
    }
    if (split.light.size() == manifest.bands.size()) found[c] = std::move(split);
  }
  return found;
}

// The light and the colour of each such component, in place of their product.
void copy_factors(const AssemblyManifest& manifest, const std::vector<std::optional<LightTimesColour>>& factors,
                  const InputBlock& block, GuidedImage& image) {
  const std::size_t nb = image.bands, offset = static_cast<std::size_t>(block.y0) * image.width;
  for (std::size_t c = 0; c < factors.size(); ++c) {
    if (!factors[c]) continue;
    for (std::size_t b = 0; b < nb; ++b) {
      const PassProduct& t = manifest.component_sums[c][b][0];
      const std::size_t stride = manifest.inputs[t.input].channels.size();
      for (std::size_t p = 0; p < block.pixels(); ++p) {
        const std::size_t i = (offset + p) * nb + b;
        image.layers[c + 1][i] = block.values[t.input][p * stride + factors[c]->light[b]];
        image.colours[c + 1][i] = block.values[t.input][p * stride + factors[c]->colour[b]];
      }
    }
  }
}

void copy_block(const OutputBlock& out, int y0, GuidedImage& image) {
  const std::size_t offset = static_cast<std::size_t>(y0) * image.width;
  std::copy(out.total.begin(), out.total.end(), image.layers[0].begin() + offset * image.bands);
  for (std::size_t c = 0; c < out.components.size(); ++c)
    std::copy(out.components[c].begin(), out.components[c].end(), image.layers[c + 1].begin() + offset * image.bands);
  std::copy(out.object_ids.begin(), out.object_ids.end(), image.object_ids.begin() + offset);
}

// The header's chromatrace.guided: which bands were reconstructed, from which, and where it was refused.
std::string guided_attribute(const AssemblyManifest& manifest, const GuidedOptions& options, const GuidedReport& report) {
  const auto band_list = [&](const std::vector<std::size_t>& bands) {
    Json list = Json::array();
    for (const std::size_t b : bands)
      list.push_back({{"band", b}, {"nm", {manifest.bands.lo(b), manifest.bands.hi(b)}}});
    return list;
  };
  Json refused = Json::array();
  std::size_t tested = 0;
  for (const GuidedVerdict& v : report.verdicts) {
    ++tested;
    if (!v.refused) continue;
    const auto name = manifest.object_names.find(v.object);
    refused.push_back({{"layer", v.layer == 0 ? "total" : manifest.components[v.layer - 1]},
                       {"object", name != manifest.object_names.end() ? name->second : std::to_string(v.object)},
                       {"band", v.band},
                       {"z", std::round(v.worst_z * 100) / 100},
                       {"threshold", std::round(v.threshold * 100) / 100}});
  }
  Json j = {{"method", "ratio to the guide bands' sum, per object and component (core/guided.h)"},
            {"guided", band_list(options.guided_bands)},
            {"guides", band_list(options.guide_bands)},
            {"radius", options.radius},
            {"false_refusal", options.false_refusal},
            {"tested", tested},
            {"refused", refused}};
  if (manifest.guided->adaptive_threshold > 0)
    j["adaptive"] = {{"threshold", manifest.guided->adaptive_threshold},
                     {"max_samples", manifest.guided->adaptive_max_samples}};
  return j.dump();
}

// Reconstructs the guided bands of the whole image and writes it.
void write_guided(const AssemblyManifest& manifest, GuidedImage& image, SpectralExrLayout layout, const fs::path& output,
                  bool show_progress) {
  GuidedOptions options;
  options.guided_bands = manifest.guided->bands;
  for (std::size_t b = 0; b < image.bands; ++b)
    if (std::find(options.guided_bands.begin(), options.guided_bands.end(), b) == options.guided_bands.end())
      options.guide_bands.push_back(b);
  options.radius = manifest.guided->radius;
  options.false_refusal = manifest.guided->false_refusal;
  const GuidedReport report = reconstruct_guided(image, options);
  layout.attributes["chromatrace.guided"] = guided_attribute(manifest, options, report);
  if (show_progress)
    fmt::print(stderr, "assemble: {} of {} bands guided; {} of {} object layers and bands refused (the header's "
               "chromatrace.guided names them)\n", options.guided_bands.size(), image.bands, report.refused(),
               report.verdicts.size());
  write_spectral_exr(output, std::move(layout), image.layers, image.object_ids);
}

}  // namespace

void assemble(const AssemblyManifest& manifest, const fs::path& output, bool show_progress) {
  std::vector<SpectralExrReader> readers = open_inputs(manifest);
  const int width = readers[0].info().width, height = readers[0].info().height;
  SpectralExrLayout layout = output_layout(manifest, width, height);
  // Guided: the writer is made once the image is whole, with the reconstruction's report in its header.
  std::optional<SpectralExrWriter> writer;
  if (!manifest.guided) writer.emplace(output, layout);
  check_channels_present(manifest, readers);
  const std::vector<SummingFamily> families = summing_families(manifest.components);
  GuidedImage image;
  std::vector<std::optional<LightTimesColour>> factors;
  if (manifest.guided) {
    image = whole_image(manifest, width, height);
    factors = light_times_colour(manifest);
    for (std::size_t c = 0; c < factors.size(); ++c)
      if (factors[c]) image.colours[c + 1].resize(image.layers[c + 1].size());
  }

  // Created after the first block, so that a problem found there is reported on one line.
  std::unique_ptr<Progress> progress;
  InputBlock in;
  in.width = width;
  OutputBlock out;
  for (int y0 = 0; y0 < height; y0 += kBlockRows) {
    const int rows = std::min(kBlockRows, height - y0);
    read_block(manifest, readers, y0, rows, in);
    assemble_values(manifest, families, in, out);
    convert_object_ids(manifest, in, out);

    if (writer) {
      SpectralRowBlock block;
      block.rows = rows;
      block.total = out.total;
      for (const std::vector<float>& c : out.components) block.components.emplace_back(c);
      block.object_ids = out.object_ids;
      writer->write_rows(block);
    } else {
      copy_block(out, y0, image);
      copy_factors(manifest, factors, in, image);
    }
    if (!progress) progress = std::make_unique<Progress>("assemble", static_cast<std::size_t>(height), show_progress);
    progress->advance(static_cast<std::size_t>(rows));
  }
  if (writer) writer->finish();
  progress->finish();
  if (manifest.guided) write_guided(manifest, image, std::move(layout), output, show_progress);
}

}  // namespace ct
