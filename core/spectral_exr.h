// SPDX-License-Identifier: Apache-2.0
#pragma once
// Spectral OpenEXR files: reads any file in the Fichet–Pacanowski–Wilkie layout (JCGT 10(3), 2021) and
// writes chromatrace's own (total, component layers, object ids, RGB preview; docs/spectral-exr.md).
//
// Both directions stream blocks of scanlines, so a large image never has to be held as a whole spectral
// cube. Pixel buffers are float, laid out [row][x][band] (or [row][x][channel] for a list of channels);
// rows and x count from 0 at the top-left of the file's data window.
//
// Every problem with a file is an InputError whose one-line message names the file and the channel,
// attribute or rows at fault, e.g. "img.exr: channel S0.550,000000nm: duplicated wavelength 550 nm
// (also S0.550,0nm)".

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/spectral_channel_name.h"
#include "core/spectrum.h"

namespace ct {

// OpenEXR compresses and decompresses with one process-wide pool of this many threads (0: in the calling
// thread). Values and bytes never depend on it.
void set_exr_threads(int threads);

enum class ExrPixelType { Uint, Half, Float };
std::string_view pixel_type_name(ExrPixelType type);  // "uint", "half", "float"

struct ExrChannel {
  std::string name;
  ExrPixelType type = ExrPixelType::Float;
};

// One quantity (S0..S3 or T) of the total or of a component: one channel per band, in band order.
struct SpectralLayer {
  std::string component;  // "" for the total
  SpectralQuantity quantity = SpectralQuantity::S0;
  std::vector<std::string> channels;

  // "S0", "T", "diffuse_direct.S0": the channel names without their wavelength.
  std::string name() const;
};

// What a file holds, from its header.
struct SpectralExrInfo {
  std::string file;  // the path as given, for messages
  std::uintmax_t file_bytes = 0;
  int width = 0;
  int height = 0;
  int origin_x = 0;  // data window's top-left corner
  int origin_y = 0;
  std::string compression;           // "zip", "piz", …
  std::vector<ExrChannel> channels;  // every channel, in the file's (alphabetical) order

  bool emissive = false;           // S0 channels
  bool polarised = false;          // S1..S3 channels as well
  bool reflective = false;         // T channels
  bool bispectral = false;         // T.a.b re-radiation channels
  std::vector<double> centres_nm;  // band centres from the channel names, increasing
  Bands bands;                     // from chromatrace.bandEdgesNm, else halfway between centres
  bool edges_from_file = false;    // whether chromatrace.bandEdgesNm gave the edges
  // The total's layers (S0..S3, then T), then component layers by name and quantity. All share the bands.
  std::vector<SpectralLayer> layers;
  std::vector<std::string> reradiation_channels;  // T.a.b, sorted by (a, b)

  bool has_object_ids = false;                       // channel object_id
  std::map<std::int32_t, std::string> object_names;  // from chromatrace.objects
  std::vector<std::string> other_channels;           // neither spectral nor object_id (R, G, B, A, …)

  std::optional<std::string> layout_version;           // spectralLayoutVersion
  std::optional<std::string> emissive_units;           // emissiveUnits
  std::optional<std::string> polarisation_handedness;  // "left" or "right"
  std::optional<double> ev;                            // EV: exposure of the RGB preview, in stops
  // Every other attribute as text, e.g. chromatrace.renderer, chromatrace.samples, the renderer's own.
  // Strings, numbers and 2-vectors ("(0, 0)") are spelled out; other types appear as their type name in
  // angle brackets ("<chromaticities>").
  std::map<std::string, std::string> metadata;
  // What the reader tolerated but a person may want to know (missing spectralLayoutVersion, unusual units …).
  std::vector<std::string> notes;

  bool spectral() const { return !layers.empty(); }
  // "spectral emissive", "spectral reflective", "spectral emissive, polarised",
  // "spectral reflective, bi-spectral", "spectral emissive and reflective", or "RGB" for any EXR without
  // spectral channels.
  std::string kind() const;
  const SpectralLayer* find_layer(std::string_view component, SpectralQuantity quantity) const;
  // As find_layer, but a missing layer is an InputError naming the file ("no spectral channels" for an
  // RGB file).
  const SpectralLayer& layer(std::string_view component, SpectralQuantity quantity) const;
  // The total: S0 for emissive files, else T.
  const SpectralLayer& total() const;
};

// Reads a file in blocks of scanlines. Opening reads and checks the header only.
class SpectralExrReader {
 public:
  explicit SpectralExrReader(const std::filesystem::path& path);
  ~SpectralExrReader();
  SpectralExrReader(SpectralExrReader&&) noexcept;
  SpectralExrReader& operator=(SpectralExrReader&&) noexcept;

  const SpectralExrInfo& info() const { return info_; }

  // Reads rows [y0, y1) of the named channels into `out` as [row][x][channel]; `out` must hold
  // (y1 - y0) · width · channels.size() floats. HALF and UINT channels are converted to float.
  void read_channels(const std::vector<std::string>& channels, int y0, int y1, std::span<float> out);
  // Rows [y0, y1) of a layer as [row][x][band].
  void read_rows(const SpectralLayer& layer, int y0, int y1, std::span<float> out);
  // The whole layer as [y][x][band].
  std::vector<float> read_layer(const SpectralLayer& layer);
  // Rows [y0, y1) of object_id as integers; a value that is not a whole number in [0, 2^24] is an InputError.
  void read_object_ids(int y0, int y1, std::span<std::int32_t> out);

 private:
  struct File;
  std::unique_ptr<File> file_;
  SpectralExrInfo info_;
};

// What chromatrace writes (docs/spectral-exr.md).
struct SpectralExrLayout {
  int width = 0;
  int height = 0;
  Bands bands;
  // false: S0 radiance in W·m⁻²·sr⁻¹·nm⁻¹ (band averages); true: T reflectance, previewed lit by D65.
  bool reflective = false;
  // Component layers <component>.S0.<λ>nm, in the order their rows are given; names as component_family
  // knows them (emission, diffuse_direct, …, light.<group>, bounce.<k>). Emissive files only.
  std::vector<std::string> components;
  bool object_ids = false;                           // write channel object_id
  std::map<std::int32_t, std::string> object_names;  // written as chromatrace.objects
  // Further string attributes, each named "chromatrace.<key>" (renderer, samples, scene, camera …).
  // chromatrace.bandEdgesNm, chromatrace.objects and chromatrace.components are written by the writer.
  std::map<std::string, std::string> attributes;
};

// The next block of rows for SpectralExrWriter::write_rows. Each span holds rows · width · bands floats
// ([row][x][band]); object_ids holds rows · width ids when the layout has object ids.
struct SpectralRowBlock {
  int rows = 0;
  std::span<const float> total;
  std::vector<std::span<const float>> components;  // in SpectralExrLayout::components order
  std::span<const std::int32_t> object_ids;
};

// Writes a file block by block, atomically: the data goes to a temporary file beside the target, which
// finish() renames into place; a writer destroyed before finish() removes it. The same layout and pixels
// give the same bytes whatever the blocks and the thread count.
class SpectralExrWriter {
 public:
  // Checks the layout (an InputError names the file and the field) and creates the temporary file.
  SpectralExrWriter(const std::filesystem::path& path, SpectralExrLayout layout);
  ~SpectralExrWriter();
  SpectralExrWriter(const SpectralExrWriter&) = delete;
  SpectralExrWriter& operator=(const SpectralExrWriter&) = delete;

  const SpectralExrLayout& layout() const { return layout_; }
  int rows_written() const { return rows_written_; }
  // Appends the next rows, top to bottom.
  void write_rows(const SpectralRowBlock& block);
  // After the last row: completes the file and renames it into place.
  void finish();

 private:
  struct File;
  std::filesystem::path path_;
  SpectralExrLayout layout_;
  std::unique_ptr<File> file_;
  int rows_written_ = 0;
};

// Writes a whole image at once, atomically: `layers` holds the total, then the components in the layout's order,
// each height · width · bands floats ([y][x][band]); `object_ids` height · width ids when the layout has them.
void write_spectral_exr(const std::filesystem::path& path, SpectralExrLayout layout,
                        const std::vector<std::vector<float>>& layers, std::span<const std::int32_t> object_ids);

}  // namespace ct
