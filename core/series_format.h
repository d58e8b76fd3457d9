// SPDX-License-Identifier: Apache-2.0
#pragma once
// Experiment series (`chromatrace-series/1`, docs/scene-format.md): a base scene, variants that patch it (and
// the sensor settings), and what each variant expects the analyzer to find. Reading and validation.
//
// It is in core/, beside the scene format it builds on, rather than in series/ (which runs a series): the small
// front program (`bin/chromatrace`, cli/front.cpp) checks series files itself with `check-scene`, and it links
// core/ but none of series/'s image libraries.

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/json_input.h"
#include "core/scene.h"

namespace ct {

inline constexpr std::string_view kSeriesFormat = "chromatrace-series/1";

// What a variant expects of one object, a group of objects or the whole image: the class the analyzer
// gives it (each object of a group on its own) is one of `any_of`, words of core/structures.h; with `bent_by`,
// the analyzer also names that cause of its bend (analyzer/bend_cause.h); with `thickened_by`, that cause of its
// spread off the direct light's line or plane (analyzer/explain.h). `paper` is the paper's own word, when the scene
// shows something else (a finding, stated with its numbers on the figure page).
struct Expectation {
  std::string target;                // as written: an object's name, a group's name, or "image"
  std::vector<std::string> objects;  // the objects it covers, in scene order; empty for "image"
  std::vector<std::string> any_of;
  std::string bent_by;               // "", "camera curve", "mixing at edges", "highlight lobe" or "interreflection"
  std::string thickened_by;          // "" or "interreflection"
  std::string paper;                 // "" when the expectation is the paper's
};
inline constexpr std::array<std::string_view, 4> kBendCauses = {"camera curve", "mixing at edges", "highlight lobe",
                                                                 "interreflection"};
// A cause as a sentence names it after "bent by": "the highlight lobe", "the camera curve", "interreflection",
// "mixing at edges".
inline std::string bend_cause_phrase(std::string_view cause) {
  return (cause == "highlight lobe" || cause == "camera curve" ? "the " : "") + std::string(cause);
}
inline constexpr std::array<std::string_view, 1> kThickeningCauses = {"interreflection"};
// An expectation in words: its classes joined by `separator`, then ", bent by …" and ", thickened by …".
inline std::string expectation_phrase(const std::vector<std::string>& any_of, std::string_view separator, std::string_view bent_by,
                                      std::string_view thickened_by) {
  std::string text;
  for (std::size_t i = 0; i < any_of.size(); ++i) text += (i ? std::string(separator) : "") + any_of[i];
  if (!bent_by.empty()) text += ", bent by " + bend_cause_phrase(bent_by);
  if (!thickened_by.empty()) text += ", thickened by " + std::string(thickened_by);
  return text;
}

struct SeriesVariant {
  std::string name;
  std::string description;
  std::string extends;  // an earlier variant whose merged scene and sensor this one patches; empty: the base
  Json patch;           // JSON Merge Patch (RFC 7386) as given
  Json sensor;          // sensor settings (a chromatrace-sensor/1 patch), merged along `extends`; {} if none
  std::vector<std::string> figure;  // the paper's panels it reproduces, e.g. {"3b", "4a"}
  std::string components;  // component families its render holds besides the run's ("bounces"); empty: the run's
  std::vector<Expectation> expect;
  Scene scene;  // the patched scene, validated; scene.json has every path absolute
};

struct Series {
  std::string source;
  std::string name;
  std::string description;
  std::string base;  // the base scene's path as written, relative to the series file
  Scene base_scene;
  std::vector<std::pair<std::string, std::vector<std::string>>> groups;  // name → object names
  std::vector<SeriesVariant> variants;

  const SeriesVariant* find_variant(std::string_view name) const;
  // The variant named `name`; InputError "<what>: <source> has no variant "x" (variants: …)" otherwise.
  const SeriesVariant& variant(std::string_view name, std::string_view what) const;
};

// The most variants a series may list (more is an InputError naming "variants").
inline constexpr std::size_t kMaxSeriesVariants = 1000;

// Loads a series: the base scene must be valid on its own, and each variant's merged scene is validated,
// on up to `threads` threads (0: all); the error reported is that of the first invalid variant in file order.
Series load_series(const std::filesystem::path& file, int threads = 0);

}  // namespace ct
