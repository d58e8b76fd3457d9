// SPDX-License-Identifier: Apache-2.0
#include "core/series_format.h"

#include <algorithm>
#include <exception>
#include <map>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/error.h"
#include "core/file_io.h"
#include "core/named.h"
#include "core/parallel.h"
#include "core/structures.h"

namespace ct {
namespace {

// `extends` names an earlier variant. Naming itself or a later one would make a cycle or a forward reference;
// the message says which, following the chain through the variants not yet read.
[[noreturn]] void fail_extends(const JsonNode& extends, const JsonNode& variants, const std::string& name) {
  std::map<std::string, std::string> parent;
  for (const JsonNode& v : variants.elements())
    if (v.json().is_object() && v.json().contains("name") && v.json()["name"].is_string())
      parent[v.json()["name"].get<std::string>()] =
          v.json().contains("extends") && v.json()["extends"].is_string() ? v.json()["extends"].get<std::string>() : "";
  const std::string target = extends.string();
  if (!parent.count(target))
    extends.fail(fmt::format("\"{}\" is not the name of a variant", target));
  std::vector<std::string> chain = {name, target};
  for (std::string at = target; !parent[at].empty() && chain.size() <= parent.size() + 1;) {
    at = parent[at];
    chain.push_back(at);
    if (at == name)
      extends.fail(fmt::format("a cycle of extends: {}", fmt::join(chain, " → ")));
  }
  extends.fail(fmt::format("\"{}\" is not an earlier variant (a variant extends one listed before it)", target));
}

Expectation read_expectation(const std::string& target, const JsonNode& node, const Scene& scene,
                             const std::vector<std::pair<std::string, std::vector<std::string>>>& groups) {
  Expectation e;
  e.target = target;
  if (target != "image") {
    const auto group = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == target; });
    if (group != groups.end()) {
      e.objects = group->second;
    } else if (std::any_of(scene.objects.begin(), scene.objects.end(), [&](const Object& o) { return o.name == target; })) {
      e.objects = {target};
    } else {
      std::vector<std::string> names;
      for (const auto& g : groups) names.push_back(g.first);
      names.push_back("image");
      node.fail(fmt::format("\"{}\" is neither an object of the scene ({}) nor a group ({})", target,
                            names_of(scene.objects), fmt::join(names, ", ")));
    }
  }
  const auto add_word = [&](const JsonNode& word_node) {
    const std::string word = word_node.non_empty_string();
    if (!structure_from_word(word)) {
      std::vector<std::string_view> words;
      for (const StructureWord& w : kStructureWords) words.push_back(w.word);
      word_node.fail(fmt::format("unknown structure \"{}\" (the analyzer's classes: {})", word, fmt::join(words, ", ")));
    }
    e.any_of.push_back(word);
  };
  const auto add_words = [&](const JsonNode& words) {
    if (words.json().is_string()) {
      add_word(words);
    } else {
      for (const JsonNode& word : words.elements()) add_word(word);
      if (e.any_of.empty()) words.fail("expects at least one structure");
    }
  };
  if (!node.json().is_object()) {
    add_words(node);
    return e;
  }
  // {"classes": …, "bent_by": cause, "thickened_by": cause, "paper": word}
  node.expect_object({"classes", "bent_by", "thickened_by", "paper"});
  add_words(node["classes"]);
  if (const auto bent_by = node.find("bent_by")) {
    e.bent_by = bent_by->non_empty_string();
    if (std::find(kBendCauses.begin(), kBendCauses.end(), e.bent_by) == kBendCauses.end())
      bent_by->fail(fmt::format("unknown cause \"{}\" (causes: {})", e.bent_by, fmt::join(kBendCauses, ", ")));
  }
  if (const auto thickened_by = node.find("thickened_by")) {
    e.thickened_by = thickened_by->non_empty_string();
    if (std::find(kThickeningCauses.begin(), kThickeningCauses.end(), e.thickened_by) == kThickeningCauses.end())
      thickened_by->fail(fmt::format("unknown cause \"{}\" (causes: {})", e.thickened_by, fmt::join(kThickeningCauses, ", ")));
  }
  if (const auto paper = node.find("paper")) {
    e.paper = paper->non_empty_string();
    if (!structure_from_word(e.paper)) paper->fail(fmt::format("unknown structure \"{}\"", e.paper));
  }
  return e;
}

}  // namespace

const SeriesVariant* Series::find_variant(std::string_view name) const { return find_by_name(variants, name); }

const SeriesVariant& Series::variant(std::string_view name, std::string_view what) const {
  if (const SeriesVariant* v = find_variant(name)) return *v;
  throw InputError(fmt::format("{}: {} has no variant \"{}\" (variants: {})", what, source, name, names_of(variants)));
}

Series load_series(const std::filesystem::path& file, int threads) {
  const Json document = read_json(file);
  const JsonNode root(document, file.string());
  const std::string format = root["format"].string();
  if (format != kSeriesFormat) root["format"].fail(fmt::format("must be \"{}\", got \"{}\"", kSeriesFormat, format));
  root.expect_object({"format", "name", "description", "base", "groups", "variants"});

  Series series;
  series.source = file.string();
  series.name = root.find("name") ? root["name"].non_empty_string() : file.stem().string();
  if (const auto description = root.find("description")) series.description = description->string();
  series.base = root["base"].non_empty_string();
  const std::filesystem::path series_dir = file.parent_path();
  const std::filesystem::path base_file = (series_dir / series.base).lexically_normal();
  // The overload that reports rather than throws: a name the system refuses (too long, say) is bad input too.
  std::error_code error;
  if (!std::filesystem::is_regular_file(base_file, error))
    root["base"].fail(fmt::format("{}: {}", base_file.string(),
                                  error && error != std::errc::no_such_file_or_directory ? error.message() : "no such scene file"));
  try {
    series.base_scene = load_scene(base_file);
  } catch (const InputError& e) {
    root["base"].fail(e.what());
  }
  if (const auto groups = root.find("groups")) {
    for (const auto& [name, members] : groups->members()) {
      std::vector<std::string> objects;
      for (const JsonNode& member : members.elements()) {
        const std::string object = member.non_empty_string();
        if (!find_by_name(series.base_scene.objects, object))
          member.fail(fmt::format("\"{}\" is not an object of {} ({})", object, series.base,
                                  names_of(series.base_scene.objects)));
        objects.push_back(object);
      }
      if (objects.empty()) members.fail("a group needs at least one object");
      if (name == "image") members.fail("\"image\" names the whole image and cannot be a group");
      series.groups.emplace_back(name, std::move(objects));
    }
  }

  // Merge in order (a variant may extend an earlier one), then validate the merged scenes in parallel. Paths
  // are made absolute first: the base scene's relative to its file, a patch's relative to the series file.
  const Json base_json = rebase_scene_paths(series.base_scene.json, series.base_scene.directory, {});
  const JsonNode variants = root["variants"];
  // A figure's worth of variants, or a study's grid: a thousand is far beyond either, and each costs a parse and a
  // render, so a file that lists more is refused before any is read.
  if (variants.json().is_array() && variants.json().size() > kMaxSeriesVariants)
    variants.fail(fmt::format("{} variants; a series holds at most {} (split it into several)", variants.json().size(), kMaxSeriesVariants));
  std::vector<Json> merged;  // merged[i]: variant i's scene document
  std::vector<std::optional<JsonNode>> expects;
  for (const JsonNode& node : variants.elements()) {
    node.expect_object({"name", "description", "extends", "patch", "sensor", "figure", "components", "expect"});
    SeriesVariant variant;
    variant.name = node["name"].non_empty_string();
    // The name becomes the variant's directory in series' output: one plain name inside it, none of the names
    // series writes at its top.
    try {
      check_file_name(variant.name, "");
    } catch (const InputError& e) {
      node["name"].fail(e.what());
    }
    if (variant.name == "renders" || variant.name == "series.json" || variant.name == "index.html")
      node["name"].fail(fmt::format("\"{}\" is a name series writes at the top of its output directory", variant.name));
    if (find_by_name(series.variants, variant.name))
      node["name"].fail(fmt::format("\"{}\" is already the name of an earlier variant", variant.name));
    if (const auto description = node.find("description")) variant.description = description->string();

    Json scene_json = base_json;
    variant.sensor = Json::object();
    if (const auto extends = node.find("extends")) {
      variant.extends = extends->string();
      const SeriesVariant* earlier = find_by_name(series.variants, variant.extends);
      if (!earlier) fail_extends(*extends, variants, variant.name);
      scene_json = merged[static_cast<std::size_t>(earlier - series.variants.data())];
      variant.sensor = earlier->sensor;
    }
    auto merge_patch_at = [&](const char* key, Json& target, bool scene) {
      const auto patch = node.find(key);
      if (!patch) return Json::object();
      if (!patch->json().is_object())
        patch->fail(fmt::format("must be an object (a JSON Merge Patch), got {}", describe_json(patch->json())));
      target.merge_patch(scene ? rebase_scene_paths(patch->json(), series_dir, {}) : patch->json());
      return patch->json();
    };
    variant.patch = merge_patch_at("patch", scene_json, true);
    merge_patch_at("sensor", variant.sensor, false);
    if (const auto figure = node.find("figure")) {
      for (const JsonNode& panel : figure->elements()) variant.figure.push_back(panel.non_empty_string());
    }
    if (const auto components = node.find("components")) {
      variant.components = components->non_empty_string();
      std::stringstream items(variant.components);
      for (std::string item; std::getline(items, item, ',');)
        if (item != "paths" && item != "lights" && item != "bounces" && item != "all")
          components->fail(fmt::format("unknown component family \"{}\" (known: paths, lights, bounces, all)", item));
    }
    expects.push_back(node.find("expect"));
    merged.push_back(std::move(scene_json));
    series.variants.push_back(std::move(variant));
  }
  if (series.variants.empty()) variants.fail("a series needs at least one variant");

  std::vector<std::exception_ptr> errors(series.variants.size());
  parallel_for(series.variants.size(), threads, [&](std::size_t i) {
    try {
      SeriesVariant& variant = series.variants[i];
      const std::string source = fmt::format("{}: variants[{}] \"{}\"", file.string(), i, variant.name);
      variant.scene = parse_scene(merged[i], source, series_dir);
      if (variant.scene.name.empty()) variant.scene.name = series.base_scene.name;
      if (expects[i]) {
        for (const auto& [target, words] : expects[i]->members())
          variant.expect.push_back(read_expectation(target, words, variant.scene, series.groups));
      }
    } catch (...) {
      errors[i] = std::current_exception();
    }
  });
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
  return series;
}

}  // namespace ct
