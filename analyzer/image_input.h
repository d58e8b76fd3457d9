#pragma once
// The image an analysis reads: any file OpenImageIO opens (8/16-bit PNG/TIFF, float EXR, …), and from
// the sensor simulator's EXR output also the noise-free linear signal, the light-path components and the
// object ids (docs/analyze.md, "Input").
//
// Values keep the file's own scale: integer files in digital numbers (0…255, 0…65535), float files as
// stored (HDR values above 1 stay above 1), so every number in analysis.json is in the units a person
// sees when they open the file.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace ct::analyzer {

// Three channels per pixel, [y][x][channel], rows from the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;

  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
};

struct ImageEncoding {
  bool integer = false;    // stored as unsigned integers
  int bits = 0;            // bits per sample of integer files (8, 16, 32); 0 for float
  double full_scale = 1;   // the value of a full-scale sample: 2^bits − 1, or 1 for float files
};

// One light-path component layer, <name>.R/G/B, in the units of the linear layer.
struct ComponentLayer {
  std::string name;  // "diffuse_direct", "light.key", "bounce.2", …
  RgbImage image;
};

struct AnalysisImage {
  std::string file;  // as given, for messages
  RgbImage image;    // R, G, B: the final image
  ImageEncoding encoding;
  std::optional<RgbImage> linear;          // linear.R/G/B: noise-free linear camera signal of the total
  std::vector<ComponentLayer> components;  // in chromatrace.components order when the file names them
  std::vector<std::int32_t> object_ids;    // channel object_id, [y][x]; empty when absent
  std::map<std::int32_t, std::string> object_names;  // attribute chromatrace.objects
};

// Reads R, G, B (or a grey-free file's first three channels) and whatever extra layers are present.
// An unreadable file, fewer than three channels or a malformed object_id / chromatrace.objects is an
// InputError naming the file.
AnalysisImage read_analysis_image(const std::filesystem::path& file);

// The RGB layer the histograms are made of: "" or "final" for R,G,B, "linear", or a component's name.
// An unknown name is an InputError listing the layers the file has.
const RgbImage& select_layer(const AnalysisImage& input, const std::string& layer);

// A single-channel integer image (a label image), [y][x]. Integer files give their stored integers; a
// float file must hold whole numbers. InputError naming the file otherwise.
struct LabelImage {
  int width = 0;
  int height = 0;
  std::vector<std::int32_t> labels;
};
LabelImage read_label_image(const std::filesystem::path& file);

}  // namespace ct::analyzer
