// SPDX-License-Identifier: Apache-2.0
#pragma once
// The vocabulary of colour-histogram structures: the classes the analyzer assigns to a cluster, and so the
// words an experiment series may `expect` (docs/analyze.md defines each by numbers). One list, used by the
// analyzer (analyzer/cluster_shape.h), the series format (core/scene.h) and the series runner.

#include <array>
#include <optional>
#include <string_view>

namespace ct {

enum class Structure {
  None, Clipped, Mixed, Point, Linear, ThickenedLine, L, SkewedT, Fork, Gamma, Curved, Thickened, Volume, P,
  Superposed, Planar
};

struct StructureWord {
  Structure structure;
  std::string_view word;     // as written in analysis.json and a series' `expect`
  std::string_view meaning;  // one line, for messages and the figure page
};

inline constexpr std::array<StructureWord, 16> kStructureWords{{
    {Structure::None, "none", "no shape measured: too few samples, or all black"},
    {Structure::Clipped, "clipped", "saturation flattened the cluster onto faces of the RGB cube"},
    {Structure::Mixed, "mixed", "object-edge pixels mixing two objects' colours (pixel area): between their clusters"},
    {Structure::Point, "point", "a single colour: no spread beyond noise"},
    {Structure::Linear, "linear", "a line along one colour: matte shading (LD)"},
    {Structure::ThickenedLine, "thickened-line", "a line thickened all along it: interreflection adds other colours"},
    {Structure::L, "L", "a body line with a highlight line leaving its bright end: a sharp highlight"},
    {Structure::SkewedT, "skewed-T", "a highlight line leaving the body line part-way along it"},
    {Structure::Fork, "fork", "two lines diverging from near black: two light colours on one surface (or two surfaces)"},
    {Structure::Gamma, "gamma", "bent by the camera's response curve: a power curve, or undoing the file's named curve, straightens it"},
    {Structure::Curved, "curved", "bent, and no power curve straightens it: the \"banana\""},
    {Structure::Thickened, "thickened", "a plane with spread off it: interreflection or noise"},
    {Structure::Volume, "volume", "spread in all three directions"},
    {Structure::P, "P", "a body line with a broad highlight filling an area on one side: a broad highlight"},
    {Structure::Superposed, "superposed", "the structures of several luminaires of different colours, added"},
    {Structure::Planar, "planar", "a cluster in a plane: body and interface reflection (LD and LS)"},
}};

// "none", "clipped", "linear", "L", "skewed-T" …
constexpr std::string_view structure_word(Structure s) {
  for (const StructureWord& w : kStructureWords)
    if (w.structure == s) return w.word;
  return "none";
}

// The structure a word names; nullopt if it names none (case matters: "L" and "P" are shapes).
constexpr std::optional<Structure> structure_from_word(std::string_view word) {
  for (const StructureWord& w : kStructureWords)
    if (w.word == word) return w.structure;
  return std::nullopt;
}

}  // namespace ct
