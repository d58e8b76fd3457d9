// chromatrace assemble MANIFEST.json -o OUT.exr: builds a spectral EXR from RGB renders that each carried
// up to three bands in their R, G and B channels (the Blender add-on's band-multiplexed Cycles renders).
//
// The manifest (chromatrace-assemble/1, written by blender_addon/chromatrace/manifest.py) says which file and
// channel holds each band, which render passes make the total and each component (a sum of signed products
// of passes, e.g. diffuse_direct = DiffDir × DiffCol, bounce.2 = Combined(2 bounces) − Combined(1 bounce)),
// where the object ids are, and the header's metadata:
//
//   {"format": "chromatrace-assemble/1", "edges_nm": [400, 450, 500, 550], "view_layer": "ViewLayer",
//    "bands": [{"channel": "R", "files": {"main": "g000.exr"}}, ...],
//    "total": [{"passes": ["Combined"]}],
//    "components": [{"name": "diffuse_direct", "terms": [{"passes": ["DiffDir", "DiffCol"]}]}, ...],
//    "object_ids": {"file": "g000.exr", "channel": "ViewLayer.IndexOB.X"}, "object_names": {"1": "floor"},
//    "attributes": {"chromatrace.renderer": "..."}, "sum_tolerance": 1e-4}
//
// A term's "file" names an entry of each band's "files" (default "main"); "sign" is 1 or -1 (default 1);
// file paths are relative to the manifest. Pass channel names are "<view_layer>.<pass>.<channel>".
//
// Each family of components (path types, light groups, bounces) must add up to the total: the renderer
// accumulated them separately in float, so they differ by rounding, which must stay within sum_tolerance
// relative to the pixel's magnitude (else an InputError names the family, pixel and band). That rounding
// residual is then added to the family's largest component at that pixel, so the file satisfies the exact
// bound `chromatrace info --check` verifies.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/command.h"
#include "core/error.h"
#include "core/json_input.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/spectral_channel_name.h"
#include "core/spectral_exr.h"

namespace ct::cli {
namespace {

namespace fs = std::filesystem;

constexpr int kBlockRows = 32;

struct Options {
  std::string manifest, output;
  int threads = 0;
  bool quiet = false;
};

// One product of passes, ± : the slots of its factors in its file's read buffer.
struct Term {
  std::size_t file = 0;
  std::vector<std::size_t> slots;
  double sign = 1.0;
};

// The render files and, per file, the channels to read (each once).
class Inputs {
 public:
  std::size_t file(const fs::path& path) {
    const auto it = std::find(paths_.begin(), paths_.end(), path);
    if (it != paths_.end()) return static_cast<std::size_t>(it - paths_.begin());
    paths_.push_back(path);
    channels_.emplace_back();
    return paths_.size() - 1;
  }
  std::size_t slot(std::size_t file, const std::string& channel) {
    std::vector<std::string>& list = channels_[file];
    const auto it = std::find(list.begin(), list.end(), channel);
    if (it != list.end()) return static_cast<std::size_t>(it - list.begin());
    list.push_back(channel);
    return list.size() - 1;
  }
  const std::vector<fs::path>& paths() const { return paths_; }
  const std::vector<std::string>& channels(std::size_t file) const { return channels_[file]; }

 private:
  std::vector<fs::path> paths_;
  std::vector<std::vector<std::string>> channels_;
};

struct Plan {
  Bands bands;
  Inputs inputs;
  std::vector<std::vector<Term>> total;                    // per band
  std::vector<std::string> components;                     // names
  std::vector<std::vector<std::vector<Term>>> component;   // [component][band]
  std::size_t id_file = 0, id_slot = 0;
  bool object_ids = false;
  std::map<std::int32_t, std::string> object_names;
  std::map<std::string, std::string> attributes;
  double sum_tolerance = 1e-4;
};

// The terms of one expression (total or component) for every band.
std::vector<std::vector<Term>> read_terms(const JsonNode& node, const std::vector<JsonNode>& bands,
                                          const std::string& view_layer, const fs::path& directory, Inputs& inputs) {
  std::vector<std::vector<Term>> per_band(bands.size());
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
      Term t;
      t.sign = sign;
      t.file = inputs.file((directory / file->non_empty_string()).lexically_normal());
      const std::string channel = bands[b]["channel"].non_empty_string();
      for (const JsonNode& pass : passes) {
        const std::string name = pass.non_empty_string();
        t.slots.push_back(inputs.slot(t.file, (view_layer.empty() ? "" : view_layer + ".") + name + "." + channel));
      }
      per_band[b].push_back(std::move(t));
    }
  }
  return per_band;
}

Plan read_manifest(const std::string& manifest) {
  const Json document = read_json(manifest);
  const JsonNode root(document, manifest);
  const std::string format = root["format"].string();
  if (format != "chromatrace-assemble/1")
    root["format"].fail(fmt::format("must be \"chromatrace-assemble/1\", got \"{}\"", format));
  root.expect_object({"format", "edges_nm", "view_layer", "bands", "total", "components", "object_ids", "object_names",
                      "attributes", "sum_tolerance"});
  const fs::path directory = fs::path(manifest).parent_path();
  Plan plan;
  std::vector<double> edges;
  for (const JsonNode& e : root["edges_nm"].elements()) edges.push_back(e.number());
  if (edges.size() < 2) root["edges_nm"].fail(fmt::format("needs at least 2 edges, got {}", edges.size()));
  for (std::size_t i = 1; i < edges.size(); ++i)
    if (!(edges[i] > edges[i - 1]))
      root["edges_nm"].fail(fmt::format("edges must increase, but {} follows {}", edges[i], edges[i - 1]));
  plan.bands = Bands::from_edges(edges, root["edges_nm"].location());

  const std::string view_layer = root.find("view_layer") ? root["view_layer"].string() : "";
  const std::vector<JsonNode> bands = root["bands"].elements();
  if (bands.size() != plan.bands.size())
    root["bands"].fail(fmt::format("{} entries for {} bands (edges_nm has {} edges)", bands.size(), plan.bands.size(),
                                   edges.size()));
  for (const JsonNode& band : bands) {
    band.expect_object({"channel", "files"});
    if (band["files"].members().empty()) band["files"].fail("names no files");
  }
  plan.total = read_terms(root["total"], bands, view_layer, directory, plan.inputs);
  if (const auto components = root.find("components")) {
    for (const JsonNode& c : components->elements()) {
      c.expect_object({"name", "terms"});
      const std::string name = c["name"].non_empty_string();
      if (component_family(name) == ComponentFamily::Unknown)
        c["name"].fail(fmt::format("\"{}\" is not one of emission, diffuse_direct, diffuse_indirect, glossy_direct, "
                                   "glossy_indirect, transmission_direct, transmission_indirect, light.<group>, bounce.<k>",
                                   name));
      if (std::find(plan.components.begin(), plan.components.end(), name) != plan.components.end())
        c["name"].fail(fmt::format("\"{}\" is listed twice", name));
      plan.components.push_back(name);
      plan.component.push_back(read_terms(c["terms"], bands, view_layer, directory, plan.inputs));
    }
  }
  if (const auto ids = root.find("object_ids")) {
    ids->expect_object({"file", "channel"});
    plan.object_ids = true;
    plan.id_file = plan.inputs.file((directory / (*ids)["file"].non_empty_string()).lexically_normal());
    plan.id_slot = plan.inputs.slot(plan.id_file, (*ids)["channel"].non_empty_string());
  }
  if (const auto names = root.find("object_names")) {
    if (!plan.object_ids) names->fail("object names given without object_ids");
    for (const auto& [key, value] : names->members()) {
      char* end = nullptr;
      const long id = std::strtol(key.c_str(), &end, 10);
      if (key.empty() || *end != '\0' || id < 0 || id > (1 << 24))
        names->fail(fmt::format("key \"{}\" is not an object id (a whole number in [0, 16777216])", key));
      plan.object_names[static_cast<std::int32_t>(id)] = value.string();
    }
  }
  if (const auto attributes = root.find("attributes"))
    for (const auto& [key, value] : attributes->members()) {
      if (!key.starts_with("chromatrace.") || key.size() == 12)
        value.fail(fmt::format("attribute \"{}\" must be named chromatrace.<key>", key));
      plan.attributes[key] = value.string();
    }
  if (const auto tolerance = root.find("sum_tolerance")) plan.sum_tolerance = tolerance->number_in(0.0, 1.0);
  return plan;
}

// The families of the planned components that must sum to the total, as lists of component indices.
std::vector<std::pair<std::string, std::vector<std::size_t>>> summing_families(const std::vector<std::string>& components) {
  std::vector<std::pair<std::string, std::vector<std::size_t>>> families;
  for (const ComponentFamily family : {ComponentFamily::PathType, ComponentFamily::LightGroup, ComponentFamily::Bounce}) {
    std::vector<std::size_t> members;
    std::vector<std::string> names;
    for (std::size_t c = 0; c < components.size(); ++c)
      if (component_family(components[c]) == family) {
        members.push_back(c);
        names.push_back(components[c]);
      }
    if (members.empty() || (family == ComponentFamily::PathType && !path_types_complete(names))) continue;
    families.emplace_back(std::string(family_name(family)), std::move(members));
  }
  return families;
}

int run(const Options& o) {
  Plan plan = read_manifest(o.manifest);
  if (o.output.empty()) throw InputError("--output: no file name");
  const fs::path parent = fs::absolute(o.output).parent_path();
  if (!fs::is_directory(parent))
    throw InputError(fmt::format("{}: directory {} does not exist", o.output, parent.string()));
  set_exr_threads(thread_count(o.threads));

  std::vector<SpectralExrReader> readers;
  for (const fs::path& path : plan.inputs.paths()) readers.emplace_back(path);
  const int width = readers[0].info().width, height = readers[0].info().height;
  for (const SpectralExrReader& r : readers)
    if (r.info().width != width || r.info().height != height)
      throw InputError(fmt::format("{}: image size {} x {} differs from {} ({} x {})", r.info().file, r.info().width,
                                   r.info().height, readers[0].info().file, width, height));

  SpectralExrLayout layout;
  layout.width = width;
  layout.height = height;
  layout.bands = plan.bands;
  layout.components = plan.components;
  layout.object_ids = plan.object_ids;
  layout.object_names = plan.object_names;
  layout.attributes = plan.attributes;
  SpectralExrWriter writer(o.output, layout);

  const std::size_t nb = plan.bands.size(), nc = plan.components.size();
  const auto families = summing_families(plan.components);
  for (std::size_t f = 0; f < readers.size(); ++f)  // a missing pass is bad input: say so before any pixel
    for (const std::string& channel : plan.inputs.channels(f)) {
      const auto& present = readers[f].info().channels;
      if (std::none_of(present.begin(), present.end(), [&](const ExrChannel& c) { return c.name == channel; }))
        throw InputError(fmt::format("{}: no channel {}", readers[f].info().file, channel));
    }
  // Created after the first block, so that a problem found there is reported on one line.
  std::unique_ptr<Progress> progress;
  std::vector<std::vector<float>> buffers(readers.size());
  for (int y0 = 0; y0 < height; y0 += kBlockRows) {
    const int rows = std::min(kBlockRows, height - y0);
    const std::size_t pixels = static_cast<std::size_t>(rows) * static_cast<std::size_t>(width);
    for (std::size_t f = 0; f < readers.size(); ++f) {
      const std::vector<std::string>& channels = plan.inputs.channels(f);
      buffers[f].assign(pixels * channels.size(), 0.0f);
      readers[f].read_channels(channels, y0, y0 + rows, buffers[f]);
    }
    auto evaluate = [&](const std::vector<Term>& terms, std::size_t pixel) {
      double sum = 0.0;
      for (const Term& t : terms) {
        const std::size_t stride = plan.inputs.channels(t.file).size();
        double product = t.sign;
        for (const std::size_t slot : t.slots) product *= buffers[t.file][pixel * stride + slot];
        sum += product;
      }
      return sum;
    };

    std::vector<float> total(pixels * nb);
    std::vector<std::vector<float>> components(nc, std::vector<float>(pixels * nb));
    std::vector<double> value(nc);
    for (std::size_t p = 0; p < pixels; ++p)
      for (std::size_t b = 0; b < nb; ++b) {
        const double t = evaluate(plan.total[b], p);
        for (std::size_t c = 0; c < nc; ++c) value[c] = evaluate(plan.component[c][b], p);
        for (const auto& [family, members] : families) {
          double sum = 0.0, magnitude = std::abs(t);
          std::size_t largest = members[0];
          for (const std::size_t c : members) {
            sum += value[c];
            magnitude += std::abs(value[c]);
            if (std::abs(value[c]) > std::abs(value[largest])) largest = c;
          }
          const double residual = t - sum;
          if (std::abs(residual) > plan.sum_tolerance * magnitude + 1e-30)
            throw InputError(fmt::format(
                "{}: the {} sum to {:.9g} but the total is {:.9g} at pixel ({}, {}), band {} ({}-{} nm): "
                "more than rounding (sum_tolerance {})",
                o.manifest, family, sum, t, p % static_cast<std::size_t>(width), static_cast<std::size_t>(y0) + p / static_cast<std::size_t>(width), b,
                plan.bands.lo(b), plan.bands.hi(b), plan.sum_tolerance));
          value[largest] += residual;
        }
        total[p * nb + b] = static_cast<float>(t);
        for (std::size_t c = 0; c < nc; ++c) components[c][p * nb + b] = static_cast<float>(value[c]);
      }

    std::vector<std::int32_t> ids;
    if (plan.object_ids) {
      const std::size_t stride = plan.inputs.channels(plan.id_file).size();
      for (std::size_t p = 0; p < pixels; ++p) {
        const float v = buffers[plan.id_file][p * stride + plan.id_slot];
        if (!(v >= 0.0f && v <= static_cast<float>(1 << 24) && v == std::floor(v)))
          throw InputError(fmt::format("{}: channel {}: value {} at pixel ({}, {}) is not an object id",
                                       plan.inputs.paths()[plan.id_file].string(),
                                       plan.inputs.channels(plan.id_file)[plan.id_slot], v,
                                       p % static_cast<std::size_t>(width), static_cast<std::size_t>(y0) + p / static_cast<std::size_t>(width)));
        ids.push_back(static_cast<std::int32_t>(v));
      }
    }
    SpectralRowBlock block;
    block.rows = rows;
    block.total = total;
    for (const auto& c : components) block.components.emplace_back(c);
    block.object_ids = ids;
    writer.write_rows(block);
    if (!progress) progress = std::make_unique<Progress>("assemble", static_cast<std::size_t>(height), !o.quiet);
    progress->advance(static_cast<std::size_t>(rows));
  }
  writer.finish();
  progress->finish();
  return 0;
}

}  // namespace

Action add_assemble(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "assemble", "Build a spectral EXR from band-multiplexed RGB renders listed in a manifest (chromatrace-assemble/1)");
  cmd->add_option("manifest", o->manifest, "Manifest JSON")->required();
  cmd->add_option("-o,--output", o->output, "Output spectral EXR, written atomically")->required();
  cmd->add_option("--threads", o->threads, "OpenEXR threads (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress output");
  return [o] { return run(*o); };
}

}  // namespace ct::cli
