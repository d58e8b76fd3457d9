// SPDX-License-Identifier: Apache-2.0
#include "analyzer/analysis_image.h"

#include <fmt/format.h>

#include "core/colour.h"
#include "core/error.h"

namespace ct::analyzer {

std::string ToneCurve::describe() const {
  if (srgb) return "the sRGB curve";
  if (linear()) return "linear";
  return fmt::format("I' = {:g}·I^{:g}", k, gamma);
}

double ToneCurve::decode(double stored, double full_scale) const {
  const double n = std::abs(stored) / full_scale;
  const double v = srgb ? srgb_decode(n) : std::pow(n / k, 1.0 / gamma);
  return std::copysign(v * full_scale, stored);
}

CodeDecoder::CodeDecoder(const std::optional<ToneCurve>& c, double fs)
    : curve(c && !c->linear() ? c : std::nullopt), full_scale(fs) {
  if (curve && fs >= 1 && fs <= 65535 && fs == std::floor(fs)) {
    table.resize(static_cast<std::size_t>(fs) + 1);
    for (std::size_t k = 0; k < table.size(); ++k) table[k] = static_cast<float>(curve->decode(static_cast<double>(k), fs));
  }
}

RgbImage linear_light(const AnalysisImage& input) {
  RgbImage out = input.image;
  const ImageEncoding& e = input.encoding;
  if (!e.curve || e.curve->linear()) return out;
  // Codes of integer files are fractions of full scale; a float file stores the normalised signal itself.
  const CodeDecoder decode(e.curve, e.integer ? e.full_scale : 1.0);
  for (float& v : out.rgb)
    if (std::isfinite(v)) v = decode(v);
  return out;
}

const RgbImage& select_layer(const AnalysisImage& input, const std::string& layer) {
  if (layer.empty() || layer == "final") return input.image;
  if (layer == "linear" && input.linear) return *input.linear;
  for (const ComponentLayer& c : input.components)
    if (c.name == layer) return c.image;
  std::vector<std::string> have{"final"};
  if (input.linear) have.push_back("linear");
  for (const ComponentLayer& c : input.components) have.push_back(c.name);
  throw InputError(fmt::format("{}: --layer: no layer \"{}\" (the file has {})", input.file, layer, fmt::join(have, ", ")));
}

}  // namespace ct::analyzer
