// SPDX-License-Identifier: Apache-2.0
#include "core/spectral_exr.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <IexBaseExc.h>
#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <ImfVecAttribute.h>
#include <ImfVersion.h>
#include <openexr.h>

#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/exr_output.h"
#include "core/exr_vocabulary.h"
#include "core/file_io.h"
#include "core/limits.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLayoutVersion = "1.0";
constexpr const char* kEmissiveUnits = "W.m^-2.sr^-1";
constexpr const char* kBandEdgesAttribute = "chromatrace.bandEdgesNm";
// The bands' reconstruction (core/spectrum.h): a float vector [lo_nm, step_nm, fine, matrix row by row].
constexpr const char* kReconstructionAttribute = "chromatrace.bandReconstruction";
using exr::kComponentsAttribute;
using exr::kMaxObjectId;
using exr::kObjectIdChannel;
using exr::kObjectsAttribute;

// Two channel wavelengths name the same band when they agree to 1e-10 (relative): far below the
// resolution of the names (six decimals of nm, 1e-9 relative at 1000 nm), far above the rounding of the
// unit conversions (1e-16), so "S0.550,0nm" and "S0.0,55um" collide and neighbouring bands never do.
bool same_wavelength(double a, double b) { return std::abs(a - b) <= 1e-10 * std::max(std::abs(a), std::abs(b)); }

std::string join(const std::vector<std::string>& items, std::string_view separator) {
  std::string text;
  for (const std::string& item : items) {
    if (!text.empty()) text += separator;
    text += item;
  }
  return text;
}

std::string compression_name(Imf::Compression compression) {
  switch (compression) {
    case Imf::NO_COMPRESSION: return "none";
    case Imf::RLE_COMPRESSION: return "rle";
    case Imf::ZIPS_COMPRESSION: return "zips";
    case Imf::ZIP_COMPRESSION: return "zip";
    case Imf::PIZ_COMPRESSION: return "piz";
    case Imf::PXR24_COMPRESSION: return "pxr24";
    case Imf::B44_COMPRESSION: return "b44";
    case Imf::B44A_COMPRESSION: return "b44a";
    case Imf::DWAA_COMPRESSION: return "dwaa";
    case Imf::DWAB_COMPRESSION: return "dwab";
    default: return "unknown";
  }
}

ExrPixelType pixel_type(Imf::PixelType type) {
  switch (type) {
    case Imf::UINT: return ExrPixelType::Uint;
    case Imf::HALF: return ExrPixelType::Half;
    default: return ExrPixelType::Float;
  }
}

// ---------------------------------------------------------------------------------------------------------
// Reading the header

// Missing, unreadable and non-EXR files get their own message before OpenEXR sees them.
void check_openable_exr(const fs::path& path, const std::string& file) {
  check_input_file(path, InputAccess::Seekable, std::numeric_limits<std::uintmax_t>::max());
  std::FILE* stream = std::fopen(file.c_str(), "rb");
  if (stream == nullptr) throw InputError(fmt::format("{}: cannot open: {}", file, std::strerror(errno)));
  char magic[4] = {};
  const std::size_t got = std::fread(magic, 1, sizeof magic, stream);
  std::fclose(stream);
  if (got < sizeof magic || !Imf::isImfMagic(magic))
    throw InputError(fmt::format("{}: not an OpenEXR file (no OpenEXR magic number)", file));
}

// A parsed spectral channel with the name it has in the file.
struct NamedChannel {
  SpectralChannelName parsed;
  std::string name;
};

std::string quantity_layer_name(std::string_view component, SpectralQuantity quantity) {
  if (component.empty()) return std::string(quantity_name(quantity));
  return fmt::format("{}.{}", component, quantity_name(quantity));
}

bool is_stokes(SpectralQuantity quantity) { return quantity != SpectralQuantity::T; }

// Groups the spectral channels into layers sorted by wavelength; a repeated wavelength is an error.
std::vector<SpectralLayer> build_layers(std::vector<NamedChannel> channels, const std::string& file,
                                        std::vector<std::vector<double>>& wavelengths) {
  // Channels arrive in the file's (alphabetical) order; sorting by (layer, quantity, wavelength) keeps
  // that order among equal wavelengths, so the first of two duplicates is the one named first.
  std::stable_sort(channels.begin(), channels.end(), [](const NamedChannel& a, const NamedChannel& b) {
    if (a.parsed.layer != b.parsed.layer) return a.parsed.layer < b.parsed.layer;
    if (a.parsed.quantity != b.parsed.quantity) return a.parsed.quantity < b.parsed.quantity;
    return a.parsed.wavelength_nm < b.parsed.wavelength_nm;
  });
  std::vector<SpectralLayer> layers;
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const SpectralChannelName& c = channels[i].parsed;
    if (layers.empty() || layers.back().component != c.layer || layers.back().quantity != c.quantity) {
      layers.push_back(SpectralLayer{c.layer, c.quantity, {}});
      wavelengths.emplace_back();
    } else if (same_wavelength(wavelengths.back().back(), c.wavelength_nm)) {
      throw InputError(fmt::format("{}: channel {}: duplicated wavelength {} nm (also {})", file, channels[i - 1].name,
                                   c.wavelength_nm, channels[i].name));
    }
    layers.back().channels.push_back(channels[i].name);
    wavelengths.back().push_back(c.wavelength_nm);
  }
  return layers;
}

// Every layer must have the wavelengths of the first (the total's S0, or T): the layout requires it of
// S0..S3 and of S and T, and components are parts of the total.
void check_same_wavelengths(const std::vector<SpectralLayer>& layers,
                            const std::vector<std::vector<double>>& wavelengths, const std::string& file) {
  const SpectralLayer& reference = layers.front();
  for (std::size_t l = 1; l < layers.size(); ++l) {
    const SpectralLayer& layer = layers[l];
    const bool stokes =
        layer.component == reference.component && is_stokes(layer.quantity) && is_stokes(reference.quantity);
    const std::string rule = stokes ? "polarised images need the same wavelengths in S0..S3"
                                    : "every spectral layer needs the wavelengths of the total";
    const std::vector<double>& want = wavelengths.front();
    const std::vector<double>& have = wavelengths[l];
    for (std::size_t i = 0; i < std::max(want.size(), have.size()); ++i) {
      if (i < want.size() && i < have.size() && same_wavelength(want[i], have[i])) continue;
      if (i < have.size() && (i >= want.size() || have[i] < want[i]))
        throw InputError(fmt::format("{}: channel {}: wavelength {} nm is not among the {} wavelengths ({})", file,
                                     layer.channels[i], have[i], reference.name(), rule));
      throw InputError(fmt::format("{}: channel {}: layer {} has no channel at {} nm ({})", file, reference.channels[i],
                                   layer.name(), want[i], rule));
    }
  }
}

// A polarised component needs all four Stokes layers.
void check_complete_stokes(const std::vector<SpectralLayer>& layers, const std::string& file) {
  for (const SpectralLayer& layer : layers) {
    if (!is_stokes(layer.quantity) || layer.quantity == SpectralQuantity::S0) continue;
    for (SpectralQuantity q :
         {SpectralQuantity::S0, SpectralQuantity::S1, SpectralQuantity::S2, SpectralQuantity::S3}) {
      const bool present = std::any_of(layers.begin(), layers.end(), [&](const SpectralLayer& other) {
        return other.component == layer.component && other.quantity == q;
      });
      if (!present)
        throw InputError(fmt::format("{}: channel {}: polarised image has no {} channels (it needs all of S0..S3)",
                                     file, layer.channels.front(), quantity_layer_name(layer.component, q)));
    }
  }
}

std::string attribute_text(const Imf::Attribute& attribute) {
  if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&attribute)) return s->value();
  if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&attribute)) return std::to_string(i->value());
  if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&attribute)) return fmt::format("{}", f->value());
  if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&attribute)) return fmt::format("{}", d->value());
  if (const auto* v = dynamic_cast<const Imf::V2fAttribute*>(&attribute))
    return fmt::format("({}, {})", v->value().x, v->value().y);
  if (const auto* v = dynamic_cast<const Imf::V2iAttribute*>(&attribute))
    return fmt::format("({}, {})", v->value().x, v->value().y);
  return fmt::format("<{}>", attribute.typeName());
}

const Imf::Attribute* find_attribute(const Imf::Header& header, const char* name) {
  const auto it = header.find(name);
  return it == header.end() ? nullptr : &it.attribute();
}

std::optional<std::string> string_attribute(const Imf::Header& header, const char* name, const std::string& file) {
  const Imf::Attribute* attribute = find_attribute(header, name);
  if (attribute == nullptr) return std::nullopt;
  const auto* s = dynamic_cast<const Imf::StringAttribute*>(attribute);
  if (s == nullptr)
    throw InputError(fmt::format("{}: attribute {}: must be a string, got {}", file, name, attribute->typeName()));
  return s->value();
}

// EV is a float in some writers and a string (std::to_string) in the reference library.
std::optional<double> ev_attribute(const Imf::Header& header, const std::string& file) {
  const Imf::Attribute* attribute = find_attribute(header, "EV");
  if (attribute == nullptr) return std::nullopt;
  const std::string text = attribute_text(*attribute);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size() || !std::isfinite(value))
    throw InputError(fmt::format("{}: attribute EV: not a number: \"{}\"", file, text));
  return value;
}

// chromatrace.objects: a JSON object from object id (a decimal string) to name, e.g. {"1":"floor"}.
std::map<std::int32_t, std::string> object_names_attribute(const Imf::Header& header, const std::string& file) {
  const std::optional<std::string> text = string_attribute(header, kObjectsAttribute, file);
  if (!text) return {};
  return exr::parse_object_names(*text, fmt::format("{}: attribute {}", file, kObjectsAttribute));
}

// Band edges: chromatrace.bandEdgesNm when present (checked against the channels' centres), else halfway
// between neighbouring centres as the layout prescribes.
Bands band_edges(const Imf::Header& header, const SpectralLayer& reference, const std::vector<double>& centres,
                 const std::string& file, bool& from_file) {
  const Imf::Attribute* attribute = find_attribute(header, kBandEdgesAttribute);
  from_file = attribute != nullptr;
  if (attribute == nullptr) return Bands::from_centres(centres, fmt::format("{}: band centres", file));

  const std::string where = fmt::format("{}: attribute {}", file, kBandEdgesAttribute);
  const auto* vector = dynamic_cast<const Imf::FloatVectorAttribute*>(attribute);
  if (vector == nullptr)
    throw InputError(fmt::format("{}: must be a float vector, got {}", where, attribute->typeName()));
  const std::vector<float>& edges = vector->value();
  if (edges.size() != centres.size() + 1)
    throw InputError(
        fmt::format("{}: {} edges for {} bands (needs {})", where, edges.size(), centres.size(), centres.size() + 1));
  for (std::size_t i = 0; i < edges.size(); ++i) {
    if (!std::isfinite(edges[i])) throw InputError(fmt::format("{}: edge {} is not finite", where, i));
    if (i > 0 && !(edges[i] > edges[i - 1]))
      throw InputError(fmt::format("{}: edges not increasing: edge {} ({} nm) after edge {} ({} nm)", where, i,
                                   edges[i], i - 1, edges[i - 1]));
  }
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const double lo = edges[i];
    const double hi = edges[i + 1];
    // The name carries the centre to six decimals (error <= 5e-7 nm) and each float edge is within 2^-24
    // (relative) of the true one, so the midpoint of the stored edges is within 5e-7 + 2^-24·hi of the
    // name's centre; twice that allows for both.
    const double tolerance = 1e-6 + std::ldexp(hi, -23);
    if (std::abs(0.5 * (lo + hi) - centres[i]) > tolerance)
      throw InputError(fmt::format("{}: band {} is [{}, {}) nm, centred at {} nm, but its channel {} is at {} nm",
                                   where, i, lo, hi, 0.5 * (lo + hi), reference.channels[i], centres[i]));
  }
  return Bands::from_edges(std::vector<double>(edges.begin(), edges.end()), where);
}

// The bands with chromatrace.bandReconstruction applied, when the file has it (it needs chromatrace.bandEdgesNm).
Bands band_reconstruction(const Imf::Header& header, const Bands& bands, bool edges_from_file, const std::string& file) {
  const Imf::Attribute* attribute = find_attribute(header, kReconstructionAttribute);
  if (attribute == nullptr) return bands;
  const std::string where = fmt::format("{}: attribute {}", file, kReconstructionAttribute);
  if (!edges_from_file) throw InputError(fmt::format("{}: given without {}", where, kBandEdgesAttribute));
  const auto* vector = dynamic_cast<const Imf::FloatVectorAttribute*>(attribute);
  if (vector == nullptr) throw InputError(fmt::format("{}: must be a float vector, got {}", where, attribute->typeName()));
  const std::vector<float>& v = vector->value();
  if (v.size() < 3) throw InputError(fmt::format("{}: {} values, needs at least 3 (lo, step, fine bands)", where, v.size()));
  if (!(v[2] >= 1 && v[2] <= static_cast<float>(kMaxBands) && v[2] == std::floor(v[2])))
    throw InputError(fmt::format("{}: the fine band count {} must be a whole number from 1 to {}", where, v[2], kMaxBands));
  BandReconstruction r;
  r.lo_nm = v[0];
  r.step_nm = v[1];
  r.fine = static_cast<std::size_t>(v[2]);
  r.matrix.assign(v.begin() + 3, v.end());
  return bands.with_reconstruction(std::move(r), where);
}

// The channels sorted into spectral ones, bi-spectral re-radiation ones, object ids and others.
struct SortedChannels {
  std::vector<NamedChannel> spectral, reradiation;
};
SortedChannels sort_channels(const Imf::Header& header, const std::string& file, SpectralExrInfo& info) {
  SortedChannels sorted;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    const std::string name = it.name();
    info.channels.push_back(ExrChannel{name, pixel_type(it.channel().type)});
    std::optional<SpectralChannelName> parsed = parse_spectral_channel_name(name);
    const bool ours = parsed || name == kObjectIdChannel;
    // Slices are read at full resolution, which subsampled channels do not have.
    if (ours && (it.channel().xSampling != 1 || it.channel().ySampling != 1))
      throw InputError(fmt::format("{}: channel {}: subsampled ({}x{}); spectral channels must be full resolution",
                                   file, name, it.channel().xSampling, it.channel().ySampling));
    if (parsed && parsed->reradiated_nm)
      sorted.reradiation.push_back(NamedChannel{std::move(*parsed), name});
    else if (parsed)
      sorted.spectral.push_back(NamedChannel{std::move(*parsed), name});
    else if (name == kObjectIdChannel)
      info.has_object_ids = true;
    else
      info.other_channels.push_back(name);
  }
  return sorted;
}

// Bi-spectral files: the re-radiation channels in wavelength order, next to the diagonal T they need.
void describe_reradiation(std::vector<NamedChannel> reradiation, const std::string& file, SpectralExrInfo& info) {
  info.bispectral = !reradiation.empty();
  if (!info.bispectral) return;
  if (info.find_layer("", SpectralQuantity::T) == nullptr)
    throw InputError(fmt::format("{}: channel {}: bi-spectral re-radiation without the diagonal T channels", file,
                                 reradiation.front().name));
  std::sort(reradiation.begin(), reradiation.end(), [](const NamedChannel& a, const NamedChannel& b) {
    return std::pair(a.parsed.wavelength_nm, *a.parsed.reradiated_nm) <
           std::pair(b.parsed.wavelength_nm, *b.parsed.reradiated_nm);
  });
  for (const NamedChannel& channel : reradiation) info.reradiation_channels.push_back(channel.name);
}

// The band centres and edges every spectral layer shares.
void describe_bands(const Imf::Header& header, const std::string& file, const std::vector<std::vector<double>>& wavelengths,
                    SpectralExrInfo& info) {
  if (!info.spectral()) return;
  check_same_wavelengths(info.layers, wavelengths, file);
  info.centres_nm = wavelengths.front();
  info.bands = band_edges(header, info.layers.front(), info.centres_nm, file, info.edges_from_file);
  info.bands = band_reconstruction(header, info.bands, info.edges_from_file, file);
  const std::size_t n = info.centres_nm.size();
  if (info.bispectral && info.reradiation_channels.size() != n * (n - 1) / 2)
    info.notes.push_back(
        fmt::format("bi-spectral: {} re-radiation channels, where the upper triangle over {} bands has {}",
                    info.reradiation_channels.size(), n, n * (n - 1) / 2));
}

// The layout's own attributes (version, units, handedness, EV), with a note where one is missing or unknown.
void describe_layout_attributes(const Imf::Header& header, const std::string& file, SpectralExrInfo& info) {
  info.layout_version = string_attribute(header, "spectralLayoutVersion", file);
  info.emissive_units = string_attribute(header, "emissiveUnits", file);
  info.polarisation_handedness = string_attribute(header, "polarisationHandedness", file);
  info.ev = ev_attribute(header, file);
  if (info.polarisation_handedness && *info.polarisation_handedness != "left" &&
      *info.polarisation_handedness != "right")
    throw InputError(fmt::format("{}: attribute polarisationHandedness: must be \"left\" or \"right\", got \"{}\"",
                                 file, *info.polarisation_handedness));
  if (!info.spectral()) return;
  if (!info.layout_version)
    info.notes.push_back("no spectralLayoutVersion attribute (the layout requires \"1.0\")");
  else if (*info.layout_version != kLayoutVersion)
    info.notes.push_back(fmt::format("spectralLayoutVersion is \"{}\"; this reader knows \"1.0\"", *info.layout_version));
  if (info.emissive && !info.emissive_units)
    info.notes.push_back(fmt::format("no emissiveUnits attribute: assuming {}", kEmissiveUnits));
  else if (info.emissive && *info.emissive_units != kEmissiveUnits)
    info.notes.push_back(
        fmt::format("emissiveUnits is \"{}\"; the layout defines only \"{}\"", *info.emissive_units, kEmissiveUnits));
  if (info.polarised && !info.polarisation_handedness)
    info.notes.push_back("no polarisationHandedness attribute: the reference library assumes right-handed");
}

SpectralExrInfo describe(const Imf::Header& header, const std::string& file, std::uintmax_t file_bytes) {
  SpectralExrInfo info;
  info.file = file;
  info.file_bytes = file_bytes;
  const Imath::Box2i window = header.dataWindow();
  info.width = window.max.x - window.min.x + 1;
  info.height = window.max.y - window.min.y + 1;
  info.origin_x = window.min.x;
  info.origin_y = window.min.y;
  info.compression = compression_name(header.compression());

  SortedChannels channels = sort_channels(header, file, info);
  std::vector<std::vector<double>> wavelengths;
  info.layers = build_layers(std::move(channels.spectral), file, wavelengths);
  for (const SpectralLayer& layer : info.layers) {
    info.emissive = info.emissive || is_stokes(layer.quantity);
    info.polarised = info.polarised || (is_stokes(layer.quantity) && layer.quantity != SpectralQuantity::S0);
    info.reflective = info.reflective || layer.quantity == SpectralQuantity::T;
  }
  check_complete_stokes(info.layers, file);
  describe_reradiation(std::move(channels.reradiation), file, info);
  describe_bands(header, file, wavelengths, info);

  info.object_names = object_names_attribute(header, file);
  if (!info.object_names.empty() && !info.has_object_ids)
    info.notes.push_back(
        fmt::format("{} names object ids but there is no {} channel", kObjectsAttribute, kObjectIdChannel));
  describe_layout_attributes(header, file, info);

  // Structural attributes are reported through the fields above; everything else is metadata.
  static const std::set<std::string> kReported{
      "channels",  "compression",           "dataWindow",     "displayWindow",
      "lineOrder", "spectralLayoutVersion", "emissiveUnits",  "polarisationHandedness",
      "EV",        kBandEdgesAttribute,     kObjectsAttribute,     kReconstructionAttribute};
  for (auto it = header.begin(); it != header.end(); ++it)
    if (!kReported.contains(it.name())) info.metadata[it.name()] = attribute_text(it.attribute());
  return info;
}

// How many times its stored size a chunk of each compression can expand to; 0 where no bound is practical
// (PIZ's run-length codes, B44's uncompressed float channels, DWA).
double largest_expansion(std::uint8_t compression) {
  switch (compression) {
    case EXR_COMPRESSION_NONE: return 1.0;
    case EXR_COMPRESSION_RLE: return 64.0;  // a run of up to 128 bytes in 2
    case EXR_COMPRESSION_ZIPS:
    case EXR_COMPRESSION_ZIP:
    case EXR_COMPRESSION_PXR24: return 1032.0;  // deflate's largest ratio
    default: return 0.0;
  }
}

// OpenEXR's C reader (OpenEXRCore) checks a header strictly and at once, where the C++ reader can spend
// seconds and a gigabyte on a corrupt one (found by fuzzing); and it reads the chunk table without the pixels.
// InputError "<file>: unreadable OpenEXR header: <its first complaint>".
struct CoreReader {
  explicit CoreReader(const std::string& file) {
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &first_error;
    init.error_handler_fn = [](exr_const_context_t context, exr_result_t, const char* message) {
      void* user = nullptr;
      if (exr_get_user_data(context, &user) == EXR_ERR_SUCCESS && user != nullptr) {
        std::string& first = *static_cast<std::string*>(user);
        if (first.empty()) first = message;
      }
    };
    const exr_result_t result = exr_start_read(&context, file.c_str(), &init);
    // A complaint it recovers from (an attribute whose size runs past the file, which it skips) would cost the
    // C++ reader the allocation the size claims: it is refused as well.
    if (result != EXR_ERR_SUCCESS || !first_error.empty()) {
      exr_finish(&context);
      throw InputError(fmt::format("{}: unreadable OpenEXR header: {}", file,
                                   one_line(first_error.empty() ? exr_get_default_error_message(result) : first_error)));
    }
  }
  ~CoreReader() { exr_finish(&context); }
  CoreReader(const CoreReader&) = delete;
  CoreReader& operator=(const CoreReader&) = delete;

  std::string first_error;  // before context: the error handler writes it while exr_start_read runs
  exr_context_t context = nullptr;
};

// OpenEXR's C++ reader fills rows that a chunk lacks with zeros instead of failing, so a data window patched
// to 100 000 pixels over 4 stored ones reads as an image. Each chunk of a scanline file is checked against the
// rows it must hold, from the chunk table alone: it must be there, hold exactly their bytes if uncompressed,
// and no fewer than its compression can expand to them.
void check_chunks_hold_the_data_window(const CoreReader& reader, const std::string& file) {
  const exr_context_t context = reader.context;
  exr_storage_t storage{};
  std::int32_t lines = 0;
  exr_attr_box2i_t window{};
  if (exr_get_storage(context, 0, &storage) != EXR_ERR_SUCCESS || storage != EXR_STORAGE_SCANLINE ||
      exr_get_scanlines_per_chunk(context, 0, &lines) != EXR_ERR_SUCCESS || lines < 1 ||
      exr_get_data_window(context, 0, &window) != EXR_ERR_SUCCESS)
    return;
  const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
  const long long height = static_cast<long long>(window.max.y) - window.min.y + 1;
  const auto claims = [&](long long first, long long last, const std::string& what) {
    return InputError(fmt::format("{}: pixel data, rows {}-{}: {}; the data window ({}x{} pixels) claims more "
                                  "than the file holds",
                                  file, first, last, what, width, height));
  };
  for (long long y = window.min.y; y <= window.max.y; y += lines) {
    const long long first = y - window.min.y, last = std::min(first + lines, height) - 1;
    exr_chunk_info_t chunk{};
    const exr_result_t result = exr_read_scanline_chunk_info(context, 0, static_cast<int>(y), &chunk);
    if (result != EXR_ERR_SUCCESS)
      throw claims(first, last, fmt::format("no chunk for them ({})", exr_get_default_error_message(result)));
    const double expansion = largest_expansion(chunk.compression);
    if (expansion == 1.0 ? chunk.packed_size != chunk.unpacked_size
                         : expansion > 0 && static_cast<double>(chunk.packed_size) * expansion <
                                                static_cast<double>(chunk.unpacked_size))
      throw claims(first, last,
                   fmt::format("{} stored bytes, which cannot hold their {} bytes", chunk.packed_size, chunk.unpacked_size));
  }
}

[[noreturn]] void throw_not_spectral(const SpectralExrInfo& info) {
  std::vector<std::string> names;
  for (const ExrChannel& channel : info.channels) names.push_back(channel.name);
  throw InputError(fmt::format("{}: no spectral channels (S0.<λ>nm or T.<λ>nm); channels: {}", info.file,
                               names.empty() ? "none" : join(names, ", ")));
}

// ---------------------------------------------------------------------------------------------------------
// Writing

void check_layout(const SpectralExrLayout& layout, const std::string& file) {
  if (layout.width < 1 || layout.height < 1)
    throw InputError(
        fmt::format("{}: image size: must be at least 1 x 1, got {} x {}", file, layout.width, layout.height));
  if (layout.bands.size() == 0) throw InputError(fmt::format("{}: bands: none given", file));
  for (std::size_t i = 1; i < layout.bands.size(); ++i) {
    const std::string a = format_spectral_channel_name("", SpectralQuantity::S0, layout.bands.centre(i - 1));
    if (a == format_spectral_channel_name("", SpectralQuantity::S0, layout.bands.centre(i)))
      throw InputError(
          fmt::format("{}: bands: bands {} and {} both have the channel name {} (centres must differ "
                      "at six decimals)",
                      file, i - 1, i, a));
  }
  if (layout.reflective && !layout.components.empty())
    throw InputError(fmt::format("{}: components: reflective images have no path components", file));
  std::set<std::string> seen;
  for (const std::string& component : layout.components) {
    if (component_family(component) == ComponentFamily::Unknown)
      throw InputError(fmt::format("{}: component \"{}\": not one of {}, light.<group>, bounce.<k>", file, component,
                                   join(path_type_components(), ", ")));
    if (!seen.insert(component).second)
      throw InputError(fmt::format("{}: component \"{}\": listed twice", file, component));
  }
  if (!layout.object_ids && !layout.object_names.empty())
    throw InputError(fmt::format("{}: object names given without object ids", file));
  for (const auto& [id, name] : layout.object_names)
    if (id < 0 || id > kMaxObjectId)
      throw InputError(fmt::format("{}: object \"{}\": id {} outside [0, {}]", file, name, id, kMaxObjectId));
  for (const auto& [name, value] : layout.attributes) {
    if (!name.starts_with("chromatrace.") || name.size() == 12)
      throw InputError(fmt::format("{}: attribute \"{}\": must be named chromatrace.<key>", file, name));
    if (name == kBandEdgesAttribute || name == kObjectsAttribute || name == kComponentsAttribute ||
        name == kReconstructionAttribute)
      throw InputError(fmt::format("{}: attribute \"{}\": written by the writer itself", file, name));
  }
}

std::vector<std::string> layer_channel_names(const Bands& bands, std::string_view component,
                                             SpectralQuantity quantity) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < bands.size(); ++i)
    names.push_back(format_spectral_channel_name(component, quantity, bands.centre(i)));
  return names;
}

// Linear sRGB of band values as one 3 x N matrix: xyz_to_linear_srgb is linear, so it can be applied to
// the XYZ weight of each band. Emission: XYZ = Σ value_i ∫_band c̄. Reflectance: lit by D65 (band
// averages) and divided by the white's Y, so that reflectance 1 gives Y = 1.
std::array<std::vector<double>, 3> preview_matrix(const Bands& bands, bool reflective) {
  std::array<std::vector<double>, 3> xyz = xyz_band_weights(bands);
  if (reflective) {
    const std::vector<double> d65 = band_averages(cie::illuminant("D65"), bands);
    double white_y = 0;
    for (std::size_t i = 0; i < bands.size(); ++i) white_y += d65[i] * xyz[1][i];
    for (auto& weights : xyz)
      for (std::size_t i = 0; i < bands.size(); ++i) weights[i] *= d65[i] / white_y;
  }
  std::array<std::vector<double>, 3> rgb;
  for (auto& row : rgb) row.resize(bands.size());
  for (std::size_t i = 0; i < bands.size(); ++i) {
    const Vec3d column = xyz_to_linear_srgb({xyz[0][i], xyz[1][i], xyz[2][i]});
    for (std::size_t c = 0; c < 3; ++c) rgb[c][i] = column[c];
  }
  return rgb;
}

// The slices of one [row][x][band] block of `channels`, for rows starting at `y0` of a window at `origin`.
void insert_slices(Imf::FrameBuffer& frame, const std::vector<std::string>& channels, const float* block,
                   const Imath::Box2i& rows) {
  const std::size_t x_stride = sizeof(float) * channels.size();
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(rows.max.x - rows.min.x + 1);
  for (std::size_t i = 0; i < channels.size(); ++i)
    frame.insert(channels[i], Imf::Slice::Make(Imf::FLOAT, block + i, rows, x_stride, y_stride));
}

}  // namespace

void set_exr_threads(int threads) { Imf::setGlobalThreadCount(std::max(threads, 0)); }

std::string_view pixel_type_name(ExrPixelType type) {
  switch (type) {
    case ExrPixelType::Uint: return "uint";
    case ExrPixelType::Half: return "half";
    case ExrPixelType::Float: return "float";
  }
  return "?";
}

std::string SpectralLayer::name() const { return quantity_layer_name(component, quantity); }

std::string SpectralExrInfo::kind() const {
  if (!spectral()) return "RGB";
  std::string text = emissive && reflective ? "spectral emissive and reflective"
                     : emissive             ? "spectral emissive"
                                            : "spectral reflective";
  if (polarised) text += ", polarised";
  if (bispectral) text += ", bi-spectral";
  return text;
}

const SpectralLayer* SpectralExrInfo::find_layer(std::string_view component, SpectralQuantity quantity) const {
  for (const SpectralLayer& layer : layers)
    if (layer.component == component && layer.quantity == quantity) return &layer;
  return nullptr;
}

const SpectralLayer& SpectralExrInfo::layer(std::string_view component, SpectralQuantity quantity) const {
  if (!spectral()) throw_not_spectral(*this);
  if (const SpectralLayer* found = find_layer(component, quantity)) return *found;
  throw InputError(fmt::format("{}: no layer {} (no {}.<λ>nm channels)", file, quantity_layer_name(component, quantity),
                               quantity_layer_name(component, quantity)));
}

const SpectralLayer& SpectralExrInfo::total() const {
  if (const SpectralLayer* s0 = find_layer("", SpectralQuantity::S0)) return *s0;
  return layer("", SpectralQuantity::T);
}

// ---------------------------------------------------------------------------------------------------------
// SpectralExrReader

struct SpectralExrReader::File {
  std::unique_ptr<Imf::InputFile> exr;
};

SpectralExrReader::SpectralExrReader(const fs::path& path) : file_(std::make_unique<File>()) {
  const std::string file = path.string();
  check_openable_exr(path, file);
  {
    // Before the C++ reader, which allocates row buffers for the whole data window it is told of.
    const CoreReader core(file);
    check_chunks_hold_the_data_window(core, file);
  }
  try {
    file_->exr = std::make_unique<Imf::InputFile>(file.c_str(), Imf::globalThreadCount());
  } catch (const std::exception& e) {
    throw InputError(fmt::format("{}: unreadable OpenEXR header: {}", file, one_line(e.what())));
  }
  std::error_code error;
  const std::uintmax_t bytes = fs::file_size(path, error);
  info_ = describe(file_->exr->header(), file, error ? 0 : bytes);
  if (Imf::isMultiPart(file_->exr->version())) info_.notes.push_back("multi-part file: only the first part is read");
}

SpectralExrReader::~SpectralExrReader() = default;
SpectralExrReader::SpectralExrReader(SpectralExrReader&&) noexcept = default;
SpectralExrReader& SpectralExrReader::operator=(SpectralExrReader&&) noexcept = default;

void SpectralExrReader::read_channels(const std::vector<std::string>& channels, int y0, int y1, std::span<float> out) {
  if (y0 < 0 || y1 > info_.height || y0 > y1)
    throw std::out_of_range(fmt::format("{}: rows [{}, {}) outside [0, {})", info_.file, y0, y1, info_.height));
  const std::size_t expected =
      static_cast<std::size_t>(y1 - y0) * static_cast<std::size_t>(info_.width) * channels.size();
  if (out.size() != expected)
    throw std::invalid_argument(
        fmt::format("read_channels: buffer holds {} floats, rows need {}", out.size(), expected));
  if (expected == 0) return;
  const Imf::ChannelList& present = file_->exr->header().channels();
  for (const std::string& channel : channels)
    if (present.findChannel(channel) == nullptr)
      throw InputError(fmt::format("{}: no channel {}", info_.file, channel));

  const Imath::Box2i rows({info_.origin_x, info_.origin_y + y0},
                          {info_.origin_x + info_.width - 1, info_.origin_y + y1 - 1});
  Imf::FrameBuffer frame;
  insert_slices(frame, channels, out.data(), rows);
  try {
    file_->exr->setFrameBuffer(frame);
    file_->exr->readPixels(rows.min.y, rows.max.y);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("{}: pixel data, rows {}-{}: {}", info_.file, y0, y1 - 1, one_line(e.what())));
  }
}

void SpectralExrReader::read_rows(const SpectralLayer& layer, int y0, int y1, std::span<float> out) {
  read_channels(layer.channels, y0, y1, out);
}

std::vector<float> SpectralExrReader::read_layer(const SpectralLayer& layer) {
  std::vector<float> values(static_cast<std::size_t>(info_.width) * static_cast<std::size_t>(info_.height) *
                            layer.channels.size());
  read_rows(layer, 0, info_.height, values);
  return values;
}

void SpectralExrReader::read_object_ids(int y0, int y1, std::span<std::int32_t> out) {
  if (!info_.has_object_ids) throw InputError(fmt::format("{}: no channel {}", info_.file, kObjectIdChannel));
  std::vector<float> values(out.size());
  read_channels({kObjectIdChannel}, y0, y1, values);
  const std::size_t width = static_cast<std::size_t>(info_.width);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const float v = values[i];
    exr::check_object_id(v, info_.file, i % width, static_cast<std::size_t>(y0) + i / width);
    out[i] = static_cast<std::int32_t>(v);
  }
}

// ---------------------------------------------------------------------------------------------------------
// SpectralExrWriter

struct SpectralExrWriter::File {
  std::unique_ptr<AtomicExrOutput> output;
  std::vector<std::string> total_channels;
  std::vector<std::vector<std::string>> component_channels;
  std::array<std::vector<double>, 3> preview;

};

SpectralExrWriter::SpectralExrWriter(const fs::path& path, SpectralExrLayout layout)
    : path_(path), layout_(std::move(layout)) {
  const std::string file = path_.string();
  check_layout(layout_, file);

  auto out = std::make_unique<File>();
  const SpectralQuantity quantity = layout_.reflective ? SpectralQuantity::T : SpectralQuantity::S0;
  out->total_channels = layer_channel_names(layout_.bands, "", quantity);
  for (const std::string& component : layout_.components)
    out->component_channels.push_back(layer_channel_names(layout_.bands, component, quantity));
  out->preview = preview_matrix(layout_.bands, layout_.reflective);

  Imf::Header header(layout_.width, layout_.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const char* rgb : {"R", "G", "B"}) header.channels().insert(rgb, Imf::Channel(Imf::FLOAT));
  for (const std::string& name : out->total_channels) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  for (const auto& names : out->component_channels)
    for (const std::string& name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  if (layout_.object_ids) header.channels().insert(kObjectIdChannel, Imf::Channel(Imf::FLOAT));

  header.insert("spectralLayoutVersion", Imf::StringAttribute(kLayoutVersion));
  if (!layout_.reflective) header.insert("emissiveUnits", Imf::StringAttribute(kEmissiveUnits));
  const std::vector<double>& edges = layout_.bands.edges();
  header.insert(kBandEdgesAttribute, Imf::FloatVectorAttribute(std::vector<float>(edges.begin(), edges.end())));
  if (const BandReconstruction* r = layout_.bands.reconstruction()) {
    std::vector<float> v{static_cast<float>(r->lo_nm), static_cast<float>(r->step_nm), static_cast<float>(r->fine)};
    v.insert(v.end(), r->matrix.begin(), r->matrix.end());
    header.insert(kReconstructionAttribute, Imf::FloatVectorAttribute(v));
  }
  if (!layout_.components.empty())
    header.insert(kComponentsAttribute, Imf::StringAttribute(exr::component_list_text(layout_.components)));
  if (layout_.object_ids) header.insert(kObjectsAttribute, Imf::StringAttribute(exr::object_names_text(layout_.object_names)));
  for (const auto& [name, value] : layout_.attributes) header.insert(name, Imf::StringAttribute(value));

  out->output = std::make_unique<AtomicExrOutput>(path_, header);
  file_ = std::move(out);
}

SpectralExrWriter::~SpectralExrWriter() = default;

void SpectralExrWriter::write_rows(const SpectralRowBlock& block) {
  if (!file_) throw std::logic_error(fmt::format("{}: write_rows after finish", path_.string()));
  if (block.rows < 0 || rows_written_ + block.rows > layout_.height)
    throw std::invalid_argument(
        fmt::format("{}: {} more rows after {} of {}", path_.string(), block.rows, rows_written_, layout_.height));
  const std::size_t pixels = static_cast<std::size_t>(block.rows) * static_cast<std::size_t>(layout_.width);
  const std::size_t values = pixels * layout_.bands.size();
  const bool sizes_match =
      block.total.size() == values && block.components.size() == layout_.components.size() &&
      std::all_of(block.components.begin(), block.components.end(), [&](auto c) { return c.size() == values; }) &&
      block.object_ids.size() == (layout_.object_ids ? pixels : 0);
  if (!sizes_match)
    throw std::invalid_argument(fmt::format("{}: row block sizes do not match the layout", path_.string()));
  if (block.rows == 0) return;

  const std::size_t bands = layout_.bands.size();
  std::vector<float> rgb(3 * pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    const float* spectrum = block.total.data() + p * bands;
    for (std::size_t c = 0; c < 3; ++c) {
      double sum = 0;
      for (std::size_t i = 0; i < bands; ++i) sum += file_->preview[c][i] * spectrum[i];
      rgb[3 * p + c] = static_cast<float>(sum);
    }
  }
  std::vector<float> ids(block.object_ids.size());
  for (std::size_t p = 0; p < ids.size(); ++p) {
    if (block.object_ids[p] < 0 || block.object_ids[p] > kMaxObjectId)
      throw std::invalid_argument(
          fmt::format("{}: object id {} outside [0, {}]", path_.string(), block.object_ids[p], kMaxObjectId));
    ids[p] = static_cast<float>(block.object_ids[p]);
  }

  const Imath::Box2i rows({0, rows_written_}, {layout_.width - 1, rows_written_ + block.rows - 1});
  Imf::FrameBuffer frame;
  insert_slices(frame, {"R", "G", "B"}, rgb.data(), rows);
  insert_slices(frame, file_->total_channels, block.total.data(), rows);
  for (std::size_t c = 0; c < layout_.components.size(); ++c)
    insert_slices(frame, file_->component_channels[c], block.components[c].data(), rows);
  if (layout_.object_ids) insert_slices(frame, {kObjectIdChannel}, ids.data(), rows);
  file_->output->write_rows(frame, rows_written_, block.rows);
  rows_written_ += block.rows;
}

void SpectralExrWriter::finish() {
  if (!file_) throw std::logic_error(fmt::format("{}: finish called twice", path_.string()));
  if (rows_written_ != layout_.height)
    throw std::logic_error(
        fmt::format("{}: finish after {} of {} rows", path_.string(), rows_written_, layout_.height));
  file_->output->finish();
  file_.reset();
}

void write_spectral_exr(const std::filesystem::path& path, SpectralExrLayout layout,
                        const std::vector<std::vector<float>>& layers, std::span<const std::int32_t> object_ids) {
  SpectralExrWriter writer(path, std::move(layout));
  SpectralRowBlock block;
  block.rows = writer.layout().height;
  block.total = layers.at(0);
  for (std::size_t l = 1; l < layers.size(); ++l) block.components.emplace_back(layers[l]);
  block.object_ids = object_ids;
  writer.write_rows(block);
  writer.finish();
}

}  // namespace ct
