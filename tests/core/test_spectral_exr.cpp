// SPDX-License-Identifier: Apache-2.0
// Spectral EXR reading and writing: channel-name grammar, the three reference sample files, bit-exact
// round trips, atomic and deterministic writing, and a clear error for each kind of bad file.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include <ImfFloatVectorAttribute.h>
#include <ImfStringAttribute.h>

#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/spectral_channel_name.h"
#include "core/spectral_exr.h"
#include "core/spectral_exr_scan.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::ComponentImage;
using test::RawChannel;
using test::TempDir;

const fs::path kSamples = fs::path(CHROMATRACE_TEST_DATA) / "spectral_exr_samples";
const fs::path kD65 = kSamples / "spectral-exr_D65_emissive.exr";
const fs::path kMacbeth = kSamples / "spectral-exr_Macbeth_reflective.exr";
const fs::path kPolarised = kSamples / "colour_Polarised_emissive_stokes.exr";

std::size_t band_at(const SpectralExrInfo& info, double nm) {
  const auto it = std::find(info.centres_nm.begin(), info.centres_nm.end(), nm);
  EXPECT_NE(it, info.centres_nm.end()) << nm << " nm is not a band centre";
  return static_cast<std::size_t>(it - info.centres_nm.begin());
}

// Runs `action`, which must throw an InputError whose message holds every one of `parts`.
template <typename Action>
void expect_input_error(Action action, const std::vector<std::string>& parts) {
  try {
    action();
    ADD_FAILURE() << "no InputError; expected one mentioning " << parts.front();
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& part : parts)
      EXPECT_NE(message.find(part), std::string::npos) << message << "\nlacks: " << part;
  }
}

// Opens a file and reads every spectral value, as `info` does.
void read_everything(const fs::path& path) {
  SpectralExrReader reader(path);
  scan_spectral_exr(reader);
}

// Spectral channels at the given wavelengths with the value 1 in every pixel.
std::vector<RawChannel> channels_at(const std::string& prefix, const std::vector<std::string>& wavelengths,
                                    int width = 2, int height = 2) {
  std::vector<RawChannel> channels;
  for (const std::string& wavelength : wavelengths)
    channels.push_back(test::constant_channel(prefix + wavelength, width, height, 1.0f));
  return channels;
}

// ---------------------------------------------------------------------------------------------------------
// Channel names

TEST(SpectralExrChannelName, ParsesTheWritersFormats) {
  struct Case {
    const char* name;
    SpectralQuantity quantity;
    double nm;
  };
  for (const Case& c :
       {Case{"S0.550,000000nm", SpectralQuantity::S0, 550.0},  // reference library
        Case{"S0.560,0nm", SpectralQuantity::S0, 560.0},       // colour-science
        Case{"S0.412,500nm", SpectralQuantity::S0, 412.5},     // pbrt-v4
        Case{"T.380,000000nm", SpectralQuantity::T, 380.0}, Case{"S3.640,000000nm", SpectralQuantity::S3, 640.0},
        Case{"S0.550nm", SpectralQuantity::S0, 550.0}}) {
    const std::optional<SpectralChannelName> parsed = parse_spectral_channel_name(c.name);
    ASSERT_TRUE(parsed) << c.name;
    EXPECT_EQ(parsed->layer, "") << c.name;
    EXPECT_EQ(parsed->quantity, c.quantity) << c.name;
    EXPECT_EQ(parsed->wavelength_nm, c.nm) << c.name;
    EXPECT_FALSE(parsed->reradiated_nm) << c.name;
  }
}

TEST(SpectralExrChannelName, ParsesExponentsPrefixesAndFrequencies) {
  EXPECT_EQ(parse_spectral_channel_name("S0.5,5e2nm")->wavelength_nm, 550.0);
  EXPECT_EQ(parse_spectral_channel_name("S0.5,5E+2nm")->wavelength_nm, 550.0);
  EXPECT_EQ(parse_spectral_channel_name("S0.5500e-1nm")->wavelength_nm, 550.0);
  EXPECT_EQ(parse_spectral_channel_name("S0.0,55um")->wavelength_nm, 550.0);
  EXPECT_EQ(parse_spectral_channel_name("S0.0,00055mm")->wavelength_nm, 550.0);
  EXPECT_EQ(parse_spectral_channel_name("S0.5,5e-7m")->wavelength_nm, 550.0);
  EXPECT_EQ(parse_spectral_channel_name("S0.0,055dam")->wavelength_nm, 550.0e6);  // deca, the two-letter prefix
  // "E" followed by a unit is the exa prefix, not an exponent.
  EXPECT_DOUBLE_EQ(parse_spectral_channel_name("S0.2Em")->wavelength_nm, 2e27);
  // λ = c / f: 550 nm is 545 077.1965 GHz.
  const double c = 299792458.0;
  EXPECT_NEAR(parse_spectral_channel_name("S0.545077196,5MHz")->wavelength_nm, 550.0, 1e-6);
  EXPECT_NEAR(parse_spectral_channel_name("S0.545,0771965THz")->wavelength_nm, 550.0, 1e-6);
  EXPECT_NEAR(parse_spectral_channel_name("S0.545077,1965GHz")->wavelength_nm, 550.0, 1e-6);
  // …so 545077196,5 GHz (a thousand times higher) is 0.55 nm.
  EXPECT_DOUBLE_EQ(parse_spectral_channel_name("S0.545077196,5GHz")->wavelength_nm, c / 545077196.5e9 * 1e9);
}

TEST(SpectralExrChannelName, ParsesBispectralAndLayers) {
  const auto bispectral = parse_spectral_channel_name("T.380,0nm.400,0nm");
  ASSERT_TRUE(bispectral);
  EXPECT_EQ(bispectral->quantity, SpectralQuantity::T);
  EXPECT_EQ(bispectral->wavelength_nm, 380.0);
  EXPECT_EQ(bispectral->reradiated_nm, 400.0);

  const auto light = parse_spectral_channel_name("light.ceiling.S0.550,000000nm");
  ASSERT_TRUE(light);
  EXPECT_EQ(light->layer, "light.ceiling");
  EXPECT_EQ(light->quantity, SpectralQuantity::S0);
  EXPECT_EQ(light->wavelength_nm, 550.0);

  const auto bounce = parse_spectral_channel_name("bounce.2.S0.550,000000nm");
  ASSERT_TRUE(bounce);
  EXPECT_EQ(bounce->layer, "bounce.2");

  const auto diffuse = parse_spectral_channel_name("diffuse_direct.S1.412,500000nm");
  ASSERT_TRUE(diffuse);
  EXPECT_EQ(diffuse->layer, "diffuse_direct");
  EXPECT_EQ(diffuse->quantity, SpectralQuantity::S1);
}

TEST(SpectralExrChannelName, RejectsNamesOutsideTheGrammar) {
  for (const char* name :
       {"S0.abcnm",   "S4.550nm",         "S0.550",    "R",         "A",          "object_id",    "S0",
        "S0.nm",      "S0..550nm",        ".S0.550nm", "S0.550nm.", "S0.550,0Xm", "S0.550,0nM",   "S0.-550nm",
        "S0.+550nm",  "S0.0nm",           "S0.0Hz",    "S0.550 nm", "S0.5,5enm",  "S0.550,0,0nm", "s0.550nm",
        "S0.550.0nm", "S0.550,0nm.400nm", "T.380nm.",  "S0.1e999nm"})
    EXPECT_FALSE(parse_spectral_channel_name(name)) << name;
}

TEST(SpectralExrChannelName, FormatsAsTheReferenceWriterAndParsesBack) {
  EXPECT_EQ(format_spectral_channel_name("", SpectralQuantity::S0, 550.0), "S0.550,000000nm");
  EXPECT_EQ(format_spectral_channel_name("", SpectralQuantity::T, 380.0), "T.380,000000nm");
  EXPECT_EQ(format_spectral_channel_name("light.ceiling", SpectralQuantity::S0, 412.5),
            "light.ceiling.S0.412,500000nm");
  for (double nm : {380.0, 412.5, 555.125, 1000.0}) {
    const auto parsed = parse_spectral_channel_name(format_spectral_channel_name("bounce.3", SpectralQuantity::S0, nm));
    ASSERT_TRUE(parsed);
    EXPECT_EQ(*parsed, (SpectralChannelName{"bounce.3", SpectralQuantity::S0, nm, std::nullopt}));
  }
}

TEST(SpectralExrChannelName, KnowsTheComponentFamilies) {
  for (const std::string& name : path_type_components()) EXPECT_EQ(component_family(name), ComponentFamily::PathType);
  EXPECT_EQ(path_type_components().size(), 7u);
  EXPECT_EQ(component_family("light.ceiling"), ComponentFamily::LightGroup);
  EXPECT_EQ(component_family("light.key_2-a"), ComponentFamily::LightGroup);
  EXPECT_EQ(component_family("bounce.0"), ComponentFamily::Bounce);
  EXPECT_EQ(component_family("bounce.12"), ComponentFamily::Bounce);
  for (const char* other : {"", "light.", "light.a.b", "bounce.", "bounce.02", "bounce.x", "diffuse", "left"})
    EXPECT_EQ(component_family(other), ComponentFamily::Unknown) << other;
}

// ---------------------------------------------------------------------------------------------------------
// The reference samples (values from the D65 table and the BabelColor/ART data, see tests/data README)

TEST(SpectralExrSamples, D65IsEmissiveWithNinetyBands) {
  SpectralExrReader reader(kD65);
  const SpectralExrInfo& info = reader.info();
  EXPECT_EQ(info.kind(), "spectral emissive");
  EXPECT_TRUE(info.emissive);
  EXPECT_FALSE(info.reflective || info.polarised || info.bispectral);
  EXPECT_EQ(info.width, 1);
  EXPECT_EQ(info.height, 1);
  ASSERT_EQ(info.bands.size(), 90u);
  EXPECT_EQ(info.centres_nm.front(), 380.0);
  EXPECT_EQ(info.centres_nm.back(), 825.0);
  // No chromatrace.bandEdgesNm: each band reaches halfway to its neighbours.
  EXPECT_FALSE(info.edges_from_file);
  EXPECT_EQ(info.bands.min_wavelength(), 377.5);
  EXPECT_EQ(info.bands.max_wavelength(), 827.5);
  EXPECT_EQ(info.layout_version, "1.0");
  EXPECT_EQ(info.emissive_units, "W.m^-2.sr^-1");
  EXPECT_EQ(info.ev, 0.0);
  EXPECT_EQ(info.other_channels, (std::vector<std::string>{"B", "G", "R"}));
  EXPECT_TRUE(info.notes.empty());

  const std::vector<float> s0 = reader.read_layer(info.total());
  EXPECT_EQ(s0[band_at(info, 560)], 100.0f);
  EXPECT_FLOAT_EQ(s0[band_at(info, 555)], 102.023f);
}

TEST(SpectralExrSamples, MacbethIsReflectiveAndReadsRowBlocks) {
  SpectralExrReader reader(kMacbeth);
  const SpectralExrInfo& info = reader.info();
  EXPECT_EQ(info.kind(), "spectral reflective");
  EXPECT_TRUE(info.reflective);
  EXPECT_FALSE(info.emissive);
  EXPECT_EQ(info.width, 600);
  EXPECT_EQ(info.height, 400);
  ASSERT_EQ(info.bands.size(), 36u);
  EXPECT_EQ(info.centres_nm.front(), 380.0);
  EXPECT_EQ(info.centres_nm.back(), 730.0);
  EXPECT_FALSE(info.emissive_units);
  EXPECT_EQ(info.total().name(), "T");

  // One row streamed on its own: pixel (50, 50) is the dark skin patch.
  const std::size_t bands = info.bands.size();
  std::vector<float> row(static_cast<std::size_t>(info.width) * bands);
  reader.read_rows(info.total(), 50, 51, row);
  const float* pixel = row.data() + 50 * bands;
  EXPECT_NEAR(pixel[band_at(info, 380)], 0.055, 1e-6);
  EXPECT_NEAR(pixel[band_at(info, 390)], 0.058, 1e-6);
  EXPECT_NEAR(pixel[band_at(info, 400)], 0.061, 1e-6);

  // The same pixel from a block of 16 rows, and from the whole layer.
  std::vector<float> block(16 * static_cast<std::size_t>(info.width) * bands);
  reader.read_rows(info.total(), 48, 64, block);
  const std::vector<float> whole = reader.read_layer(info.total());
  for (std::size_t i = 0; i < bands; ++i) {
    EXPECT_EQ(block[(2 * 600 + 50) * bands + i], pixel[i]);
    EXPECT_EQ(whole[(50 * 600 + 50) * bands + i], pixel[i]);
  }
}

TEST(SpectralExrSamples, PolarisedHasFourStokesComponents) {
  SpectralExrReader reader(kPolarised);
  const SpectralExrInfo& info = reader.info();
  EXPECT_EQ(info.kind(), "spectral emissive, polarised");
  EXPECT_TRUE(info.polarised);
  EXPECT_EQ(info.polarisation_handedness, "right");
  ASSERT_EQ(info.bands.size(), 8u);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(info.centres_nm[i], 400.0 + 40.0 * static_cast<double>(i));
  ASSERT_EQ(info.layers.size(), 4u);
  EXPECT_EQ(info.other_channels, (std::vector<std::string>{"A", "B", "G", "R"}));
  EXPECT_EQ(info.metadata.at("fileCreatedBy"), "artist, ART 2.0.4-dev");

  const std::size_t band = band_at(info, 560);
  const double expected[4] = {0.1359, -0.0060, 0.0199, -0.0021};
  const SpectralQuantity stokes[4] = {SpectralQuantity::S0, SpectralQuantity::S1, SpectralQuantity::S2,
                                      SpectralQuantity::S3};
  for (int s = 0; s < 4; ++s) {
    std::vector<float> row(32 * 8);
    reader.read_rows(info.layer("", stokes[s]), 10, 11, row);
    EXPECT_NEAR(row[10 * 8 + band], expected[s], 5e-5) << quantity_name(stokes[s]);
  }
}

// ---------------------------------------------------------------------------------------------------------
// Reading files from other writers

TEST(SpectralExrReading, SortsChannelsByNumericWavelength) {
  TempDir dir;
  const fs::path path = dir.file("units.exr");
  // String order is 0,5um < 1000,0nm < 380,0nm; wavelength order is 380 < 500 < 1000.
  test::write_raw_exr(
      path, 1, 1,
      {test::constant_channel("S0.1000,0nm", 1, 1, 3.0f), test::constant_channel("S0.380,0nm", 1, 1, 1.0f),
       test::constant_channel("S0.0,5um", 1, 1, 2.0f)});
  SpectralExrReader reader(path);
  EXPECT_EQ(reader.info().centres_nm, (std::vector<double>{380, 500, 1000}));
  EXPECT_EQ(reader.read_layer(reader.info().total()), (std::vector<float>{1, 2, 3}));
  EXPECT_EQ(reader.info().notes.front(), "no spectralLayoutVersion attribute (the layout requires \"1.0\")");
}

TEST(SpectralExrReading, ConvertsHalfChannelsToFloat) {
  TempDir dir;
  const fs::path path = dir.file("half.exr");
  test::write_raw_exr(path, 2, 1,
                      {RawChannel{"S0.500,0nm", {0.5f, 1.25f}, Imf::HALF}, RawChannel{"S0.600,0nm", {-2.0f, 1024.0f}}});
  SpectralExrReader reader(path);
  EXPECT_EQ(reader.info().channels.front().type, ExrPixelType::Half);
  EXPECT_EQ(reader.read_layer(reader.info().total()), (std::vector<float>{0.5f, -2.0f, 1.25f, 1024.0f}));
}

TEST(SpectralExrReading, RecognisesBispectralFiles) {
  TempDir dir;
  const fs::path path = dir.file("fluorescent.exr");
  test::write_raw_exr(path, 2, 2,
                      channels_at("T.", {"400,0nm", "500,0nm", "600,0nm", "400,0nm.500,0nm", "400,0nm.600,0nm"}));
  SpectralExrReader reader(path);
  const SpectralExrInfo& info = reader.info();
  EXPECT_TRUE(info.bispectral);
  EXPECT_EQ(info.kind(), "spectral reflective, bi-spectral");
  EXPECT_EQ(info.reradiation_channels, (std::vector<std::string>{"T.400,0nm.500,0nm", "T.400,0nm.600,0nm"}));
  ASSERT_EQ(info.bands.size(), 3u);
  // The full upper triangle over 3 bands has 3 entries; 500 -> 600 is missing.
  EXPECT_NE(std::find_if(info.notes.begin(), info.notes.end(),
                         [](const std::string& n) { return n.starts_with("bi-spectral: 2 re-radiation"); }),
            info.notes.end());
}

TEST(SpectralExrReading, ListsComponentLayersWithDotsInTheirNames) {
  TempDir dir;
  const fs::path path = dir.file("layers.exr");
  std::vector<RawChannel> channels = channels_at("S0.", {"500nm", "600nm"});
  for (const char* layer : {"light.ceiling.S0.", "bounce.2.S0.", "diffuse_direct.S0."})
    for (RawChannel& c : channels_at(layer, {"500nm", "600nm"})) channels.push_back(std::move(c));
  test::write_raw_exr(path, 2, 2, channels);
  const SpectralExrInfo info = SpectralExrReader(path).info();
  std::vector<std::string> names;
  for (const SpectralLayer& layer : info.layers) names.push_back(layer.name());
  EXPECT_EQ(names, (std::vector<std::string>{"S0", "bounce.2.S0", "diffuse_direct.S0", "light.ceiling.S0"}));
  EXPECT_EQ(info.layer("light.ceiling", SpectralQuantity::S0).channels,
            (std::vector<std::string>{"light.ceiling.S0.500nm", "light.ceiling.S0.600nm"}));
  expect_input_error([&] { info.layer("glossy_direct", SpectralQuantity::S0); },
                     {path.string(), "no layer glossy_direct.S0"});
}

// ---------------------------------------------------------------------------------------------------------
// Writing

// Random bit patterns over every finite float, with subnormals, zeros of both signs and extremes mixed in.
std::vector<float> random_floats(std::size_t count, std::uint32_t seed) {
  std::mt19937 random(seed);
  const float specials[] = {0.0f,
                            -0.0f,
                            std::numeric_limits<float>::denorm_min(),
                            -std::numeric_limits<float>::denorm_min(),
                            std::bit_cast<float>(0x007fffffu),
                            std::numeric_limits<float>::min(),
                            std::numeric_limits<float>::max(),
                            -std::numeric_limits<float>::max()};
  std::vector<float> values(count);
  for (std::size_t i = 0; i < count; ++i) {
    std::uint32_t bits = random();
    if (i % 5 == 0) bits &= 0x807fffffu;                           // exponent 0: a subnormal
    if ((bits & 0x7f800000u) == 0x7f800000u) bits &= 0xbfffffffu;  // keep it finite
    values[i] = i % 17 == 0 ? specials[i / 17 % std::size(specials)] : std::bit_cast<float>(bits);
  }
  return values;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(SpectralExrWriter, RoundTripsBitExact) {
  TempDir dir;
  const fs::path path = dir.file("round trip.exr");
  ComponentImage image = test::make_component_image(9, 13, 1);
  image.total = random_floats(image.total.size(), 2);
  for (std::size_t c = 0; c < image.components.size(); ++c)
    image.components[c] = random_floats(image.total.size(), 3 + static_cast<std::uint32_t>(c));
  test::write_image(path, image, 4);

  SpectralExrReader reader(path);
  const SpectralExrInfo& info = reader.info();
  EXPECT_EQ(info.kind(), "spectral emissive");
  EXPECT_EQ(info.width, 9);
  EXPECT_EQ(info.height, 13);
  EXPECT_EQ(info.compression, "zip");
  EXPECT_TRUE(info.edges_from_file);
  EXPECT_EQ(info.bands, image.layout.bands);
  EXPECT_EQ(info.total().channels.front(), "S0.406,250000nm");
  EXPECT_TRUE(same_bits(reader.read_layer(info.total()), image.total));
  for (std::size_t c = 0; c < image.components.size(); ++c)
    EXPECT_TRUE(
        same_bits(reader.read_layer(info.layer(image.layout.components[c], SpectralQuantity::S0)), image.components[c]))
        << image.layout.components[c];

  ASSERT_TRUE(info.has_object_ids);
  std::vector<std::int32_t> ids(image.object_ids.size());
  reader.read_object_ids(0, info.height, ids);
  EXPECT_EQ(ids, image.object_ids);
  EXPECT_EQ(info.object_names, image.layout.object_names);

  EXPECT_EQ(info.layout_version, "1.0");
  EXPECT_EQ(info.emissive_units, "W.m^-2.sr^-1");
  EXPECT_EQ(info.metadata.at("chromatrace.renderer"), "test");
  EXPECT_EQ(info.metadata.at("chromatrace.samples"), "16");
  EXPECT_EQ(info.metadata.at("chromatrace.components"),
            "emission,diffuse_direct,diffuse_indirect,glossy_direct,glossy_indirect,transmission_direct,"
            "transmission_indirect");
  EXPECT_EQ(info.other_channels, (std::vector<std::string>{"B", "G", "R"}));
  EXPECT_TRUE(info.notes.empty());
}

// The bands' reconstruction travels in the header (chromatrace.bandReconstruction) and reads back the same, and the
// colours of the file's band values then come through it (here: a matrix that puts each band's value on the fine
// band [lo + j, lo + j + 1) of index j = band, which makes the CIE weights those of that 1 nm band).
TEST(SpectralExrWriter, CarriesTheBandReconstruction) {
  TempDir dir;
  const fs::path path = dir.file("reconstructed.exr");
  ComponentImage image = test::make_component_image(5, 4, 1);
  const Bands& bands = image.layout.bands;
  BandReconstruction r{500, 1, bands.size(), std::vector<double>(bands.size() * bands.size(), 0.0)};
  for (std::size_t i = 0; i < bands.size(); ++i) r.matrix[i * bands.size() + i] = 1;
  image.layout.bands = bands.with_reconstruction(r);
  test::write_image(path, image, 2);
  const SpectralExrReader reader(path);
  EXPECT_EQ(reader.info().bands, image.layout.bands);
  const auto w = xyz_band_weights(reader.info().bands);
  for (std::size_t i = 0; i < bands.size(); ++i)
    EXPECT_NEAR(w[1][i], cie::y_bar().integral(500.0 + i, 501.0 + i), 1e-12) << i;
}

TEST(SpectralExrWriter, SameInputGivesTheSameBytesWhateverTheBlocksAndThreads) {
  TempDir dir;
  const ComponentImage image = test::make_component_image(11, 23, 7);
  test::write_image(dir.file("all.exr"), image, 23);
  test::write_image(dir.file("again.exr"), image, 23);
  test::write_image(dir.file("one.exr"), image, 1);
  test::write_image(dir.file("seven.exr"), image, 7);
  set_exr_threads(4);
  test::write_image(dir.file("threads.exr"), image, 7);
  set_exr_threads(0);
  const std::vector<char> reference = test::read_bytes(dir.file("all.exr"));
  for (const char* name : {"again.exr", "one.exr", "seven.exr", "threads.exr"})
    EXPECT_TRUE(test::read_bytes(dir.file(name)) == reference) << name;
}

TEST(SpectralExrWriter, WritesAtomically) {
  TempDir dir;
  const fs::path path = dir.file("out.exr");
  const ComponentImage image = test::make_component_image(4, 4, 3);
  {
    SpectralExrWriter writer(path, image.layout);
    SpectralRowBlock block;
    block.rows = 1;
    block.total = std::span<const float>(image.total).first(4 * 6);
    for (const auto& component : image.components)
      block.components.push_back(std::span<const float>(component).first(4 * 6));
    block.object_ids = std::span<const std::int32_t>(image.object_ids).first(4);
    writer.write_rows(block);
    EXPECT_FALSE(fs::exists(path)) << "visible before finish()";
  }
  // Abandoned: no file, no temporary.
  EXPECT_TRUE(fs::is_empty(dir.path()));

  // An abandoned rewrite leaves the previous file as it was.
  test::write_image(path, image, 4);
  const std::vector<char> before = test::read_bytes(path);
  { SpectralExrWriter abandoned(path, image.layout); }
  EXPECT_TRUE(test::read_bytes(path) == before);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(SpectralExrWriter, RejectsBadLayoutsNamingTheField) {
  TempDir dir;
  const fs::path path = dir.file("bad.exr");
  const SpectralExrLayout good = test::make_component_image(2, 2, 1).layout;
  auto with = [&](auto change) {
    SpectralExrLayout layout = good;
    change(layout);
    return layout;
  };
  expect_input_error([&] { SpectralExrWriter(path, with([](auto& l) { l.components.push_back("difuse"); })); },
                     {path.string(), "component \"difuse\""});
  expect_input_error([&] { SpectralExrWriter(path, with([](auto& l) { l.components.push_back("emission"); })); },
                     {path.string(), "component \"emission\": listed twice"});
  expect_input_error([&] { SpectralExrWriter(path, with([](auto& l) { l.width = 0; })); },
                     {path.string(), "image size"});
  expect_input_error([&] { SpectralExrWriter(path, with([](auto& l) { l.reflective = true; })); },
                     {path.string(), "components"});
  expect_input_error(
      [&] { SpectralExrWriter(path, with([](auto& l) { l.attributes["chromatrace.bandEdgesNm"] = "1"; })); },
      {path.string(), "chromatrace.bandEdgesNm"});
  expect_input_error([&] { SpectralExrWriter(path, with([](auto& l) { l.attributes["renderer"] = "x"; })); },
                     {path.string(), "attribute \"renderer\""});
  expect_input_error(
      [&] {
        SpectralExrWriter(path, with([](auto& l) { l.bands = Bands::from_edges({500, 500.0000001, 500.0000002}); }));
      },
      {path.string(), "bands"});
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// The preview is the CIE 1931 colour in linear sRGB: a perfect white reflector lit by D65 has Y = 1 and,
// D65 being sRGB's white, R = G = B = 1 up to the discretisation into 10 nm bands.
TEST(SpectralExrWriter, PreviewOfAWhiteReflectorIsWhite) {
  TempDir dir;
  const fs::path path = dir.file("white.exr");
  SpectralExrLayout layout;
  layout.width = 1;
  layout.height = 1;
  layout.bands = Bands::uniform(380, 780, 10);
  layout.reflective = true;
  const std::vector<float> white(layout.bands.size(), 1.0f);
  SpectralExrWriter writer(path, layout);
  writer.write_rows({1, white, {}, {}});
  writer.finish();

  SpectralExrReader reader(path);
  EXPECT_EQ(reader.info().kind(), "spectral reflective");
  EXPECT_FALSE(reader.info().emissive_units);
  std::vector<float> rgb(3);
  reader.read_channels({"R", "G", "B"}, 0, 1, rgb);
  EXPECT_NEAR(linear_srgb_to_xyz({rgb[0], rgb[1], rgb[2]})[1], 1.0, 1e-6);
  for (float c : rgb) EXPECT_NEAR(c, 1.0, 0.01);
}

// Emission: XYZ = ∫ L x̄ dλ, so D65 radiance previews as a neutral grey of Y = ∫ D65 ȳ dλ.
TEST(SpectralExrWriter, PreviewOfD65RadianceIsNeutral) {
  TempDir dir;
  const fs::path path = dir.file("d65.exr");
  SpectralExrLayout layout;
  layout.width = 1;
  layout.height = 1;
  layout.bands = Bands::uniform(380, 780, 10);
  const std::vector<double> d65 = band_averages(cie::illuminant("D65"), layout.bands);
  const std::vector<float> radiance(d65.begin(), d65.end());
  SpectralExrWriter writer(path, layout);
  writer.write_rows({1, radiance, {}, {}});
  writer.finish();

  SpectralExrReader reader(path);
  std::vector<float> rgb(3);
  reader.read_channels({"R", "G", "B"}, 0, 1, rgb);
  const double y = linear_srgb_to_xyz({rgb[0], rgb[1], rgb[2]})[1];
  EXPECT_NEAR(y, bands_to_xyz(d65, layout.bands)[1], 1e-4 * y);
  for (float c : rgb) EXPECT_NEAR(c / y, 1.0, 0.01);
}

// The reference library wrote R, G, B previews into its samples by the same conventions (emission
// unnormalised, reflectance under D65 with white Y = 1); it samples the observer at the band centres where
// we integrate it over each band, so the two differ by that discretisation: 0.01–0.1 % on these samples.
TEST(SpectralExrWriter, PreviewMatchesTheReferenceLibrarys) {
  TempDir dir;
  for (const auto& [sample, x, y] : {std::tuple{kD65, 0, 0}, std::tuple{kMacbeth, 50, 50}}) {
    SpectralExrReader reference(sample);
    const SpectralExrInfo& info = reference.info();
    const std::size_t width = static_cast<std::size_t>(info.width);
    std::vector<float> spectra(width * info.bands.size());
    std::vector<float> reference_rgb(width * 3);
    reference.read_rows(info.total(), y, y + 1, spectra);
    reference.read_channels({"R", "G", "B"}, y, y + 1, reference_rgb);

    SpectralExrLayout layout;
    layout.width = 1;
    layout.height = 1;
    layout.bands = info.bands;
    layout.reflective = info.reflective;
    const fs::path ours = dir.file(sample.filename().string());
    SpectralExrWriter writer(ours, layout);
    writer.write_rows(
        {1,
         std::span<const float>(spectra).subspan(static_cast<std::size_t>(x) * info.bands.size(), info.bands.size()),
         {},
         {}});
    writer.finish();
    std::vector<float> rgb(3);
    SpectralExrReader(ours).read_channels({"R", "G", "B"}, 0, 1, rgb);
    for (std::size_t c = 0; c < 3; ++c) {
      const float expected = reference_rgb[static_cast<std::size_t>(x) * 3 + c];
      EXPECT_NEAR(rgb[c], expected, 0.005 * std::abs(expected)) << sample.filename() << " channel "
                                                                << "RGB"[c];
    }
  }
}

// ---------------------------------------------------------------------------------------------------------
// Bad input

TEST(SpectralExrBadInput, MissingFile) {
  TempDir dir;
  const fs::path path = dir.file("absent.exr");
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "cannot open"});
}

TEST(SpectralExrBadInput, NotAnExr) {
  TempDir dir;
  const fs::path path = dir.file("notes.exr");
  std::ofstream(path) << "S0.550,000000nm\n";
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "not an OpenEXR file"});
  expect_input_error([&] { SpectralExrReader reader(dir.path()); }, {dir.path().string(), "directory"});
}

TEST(SpectralExrBadInput, TruncatedFilesAtManyLengths) {
  TempDir dir;
  // A sample from another writer, and one of ours with components and object ids.
  test::write_image(dir.file("ours.exr"), test::make_component_image(40, 40, 5), 40);
  for (const fs::path& source : {kMacbeth, dir.file("ours.exr")}) {
    const std::size_t size = fs::file_size(source);
    for (std::size_t cut : {std::size_t{0}, std::size_t{3}, std::size_t{8}, std::size_t{100}, std::size_t{1000},
                            std::size_t{4000}, size / 3, size / 2, size - 1000, size - 17, size - 1}) {
      const fs::path truncated = dir.file("cut-" + std::to_string(cut) + "-" + source.filename().string());
      test::write_truncated_copy(source, truncated, cut);
      expect_input_error([&] { read_everything(truncated); }, {truncated.string()});
    }
  }
}

TEST(SpectralExrBadInput, NoSpectralChannels) {
  TempDir dir;
  const fs::path path = dir.file("rgb.exr");
  test::write_raw_exr(path, 2, 2, channels_at("", {"R", "G", "B"}));
  SpectralExrReader reader(path);  // an RGB file opens and describes itself…
  EXPECT_EQ(reader.info().kind(), "RGB");
  EXPECT_FALSE(reader.info().spectral());
  // …but has no spectral data to give.
  expect_input_error([&] { reader.info().total(); }, {path.string(), "no spectral channels", "channels: B, G, R"});
  expect_input_error([&] { scan_spectral_exr(reader); }, {path.string(), "no spectral channels"});
}

TEST(SpectralExrBadInput, DuplicatedWavelengths) {
  TempDir dir;
  const fs::path path = dir.file("img.exr");
  test::write_raw_exr(path, 2, 2, channels_at("S0.", {"540,0nm", "550,0nm", "550,000000nm"}));
  expect_input_error([&] { SpectralExrReader reader(path); },
                     {path.string() + ": channel S0.550,000000nm: duplicated wavelength 550 nm (also S0.550,0nm)"});
  // Different units, the same wavelength.
  test::write_raw_exr(path, 2, 2, channels_at("T.", {"0,55um", "550nm"}));
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "duplicated wavelength 550 nm"});
}

TEST(SpectralExrBadInput, PolarisedWithMismatchedStokesSets) {
  TempDir dir;
  const fs::path path = dir.file("stokes.exr");
  std::vector<RawChannel> channels = channels_at("S0.", {"500nm", "510nm"});
  for (const char* s : {"S1.", "S2.", "S3."})
    for (RawChannel& c : channels_at(s, {"500nm", s == std::string("S2.") ? "520nm" : "510nm"}))
      channels.push_back(std::move(c));
  test::write_raw_exr(path, 2, 2, channels);
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "channel S0.510nm", "S2", "S0..S3"});

  // S3 missing altogether.
  channels.resize(6);
  test::write_raw_exr(path, 2, 2, channels);
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "no S3 channels"});
}

TEST(SpectralExrBadInput, ComponentWithOtherWavelengths) {
  TempDir dir;
  const fs::path path = dir.file("parts.exr");
  std::vector<RawChannel> channels = channels_at("S0.", {"500nm", "510nm"});
  for (RawChannel& c : channels_at("emission.S0.", {"500nm", "510nm", "530nm"})) channels.push_back(std::move(c));
  test::write_raw_exr(path, 2, 2, channels);
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "channel emission.S0.530nm", "530 nm"});
}

TEST(SpectralExrBadInput, BadBandEdges) {
  TempDir dir;
  const fs::path path = dir.file("edges.exr");
  const std::vector<RawChannel> channels = channels_at("S0.", {"500,000000nm", "510,000000nm", "520,000000nm"});
  auto write_with_edges = [&](const Imf::Attribute& attribute) {
    test::write_raw_exr(path, 2, 2, channels, [&](Imf::Header& h) { h.insert("chromatrace.bandEdgesNm", attribute); });
  };
  const std::string where = path.string() + ": attribute chromatrace.bandEdgesNm: ";

  write_with_edges(Imf::FloatVectorAttribute({495, 505, 515, 525}));
  EXPECT_EQ(SpectralExrReader(path).info().bands, Bands::from_edges({495, 505, 515, 525}));

  write_with_edges(Imf::FloatVectorAttribute({495, 505, 515}));
  expect_input_error([&] { SpectralExrReader reader(path); }, {where + "3 edges for 3 bands (needs 4)"});
  write_with_edges(Imf::FloatVectorAttribute({495, 505, 505, 525}));
  expect_input_error([&] { SpectralExrReader reader(path); }, {where + "edges not increasing"});
  write_with_edges(Imf::FloatVectorAttribute({490, 500, 510, 520}));
  expect_input_error([&] { SpectralExrReader reader(path); }, {where + "band 0 is [490, 500) nm", "S0.500,000000nm"});
  write_with_edges(Imf::FloatVectorAttribute({495, 505, NAN, 525}));
  expect_input_error([&] { SpectralExrReader reader(path); }, {where + "edge 2 is not finite"});
  write_with_edges(Imf::StringAttribute("495 505 515 525"));
  expect_input_error([&] { SpectralExrReader reader(path); }, {where + "must be a float vector"});
}

TEST(SpectralExrBadInput, BadAttributes) {
  TempDir dir;
  const fs::path path = dir.file("attributes.exr");
  std::vector<RawChannel> channels = channels_at("S0.", {"500nm", "510nm"});
  channels.push_back(test::constant_channel("object_id", 2, 2, 1.5f));
  auto write_with = [&](const char* name, const std::string& value) {
    test::write_raw_exr(path, 2, 2, channels, [&](Imf::Header& h) { h.insert(name, Imf::StringAttribute(value)); });
  };
  write_with("chromatrace.objects", "{\"1\": \"floor\"");
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "attribute chromatrace.objects"});
  write_with("chromatrace.objects", "{\"floor\": \"1\"}");
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "chromatrace.objects", "\"floor\""});
  write_with("polarisationHandedness", "up");
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "attribute polarisationHandedness"});
  write_with("EV", "bright");
  expect_input_error([&] { SpectralExrReader reader(path); }, {path.string(), "attribute EV"});

  write_with("chromatrace.objects", "{\"1\": \"floor\"}");
  SpectralExrReader reader(path);
  std::vector<std::int32_t> ids(4);
  expect_input_error([&] { reader.read_object_ids(0, 2, ids); }, {path.string(), "channel object_id", "1.5"});
}

// ---------------------------------------------------------------------------------------------------------
// Scanning: non-finite values, statistics, component sums

TEST(SpectralExrScan, CountsNonFiniteValuesExactly) {
  TempDir dir;
  const fs::path path = dir.file("nan.exr");
  ComponentImage image = test::make_component_image(6, 5, 11);
  const std::size_t bands = image.layout.bands.size();
  auto at = [&](int x, int y, std::size_t band) {
    return (static_cast<std::size_t>(y) * 6 + static_cast<std::size_t>(x)) * bands + band;
  };
  image.total[at(3, 1, 2)] = NAN;
  image.total[at(0, 2, 2)] = NAN;
  image.total[at(5, 4, 2)] = INFINITY;
  image.components[3][at(1, 0, 0)] = -INFINITY;  // glossy_direct
  test::write_image(path, image, 2);

  SpectralExrReader reader(path);
  const SpectralExrScan scan = scan_spectral_exr(reader);
  ASSERT_EQ(scan.non_finite.size(), 2u);
  EXPECT_EQ(scan.non_finite[0].channel, "S0.450,000000nm");
  EXPECT_EQ(scan.non_finite[0].count, 3u);
  EXPECT_EQ(scan.non_finite[0].first_x, 3);
  EXPECT_EQ(scan.non_finite[0].first_y, 1);
  EXPECT_EQ(scan.non_finite[1].channel, "glossy_direct.S0.406,250000nm");
  EXPECT_EQ(scan.non_finite[1].count, 1u);
  EXPECT_EQ(scan.non_finite[1].first_x, 1);
  EXPECT_EQ(scan.non_finite[1].first_y, 0);
  // Statistics skip the non-finite values.
  EXPECT_EQ(scan.total_statistics[2].finite, 27u);
}

TEST(SpectralExrScan, BandStatisticsOfKnownValues) {
  TempDir dir;
  const fs::path path = dir.file("stats.exr");
  test::write_raw_exr(path, 2, 2, {RawChannel{"S0.500nm", {1, 2, 3, 4}}, RawChannel{"S0.600nm", {5, NAN, 7, 8}}});
  SpectralExrReader reader(path);
  const SpectralExrScan scan = scan_spectral_exr(reader);
  ASSERT_EQ(scan.total_statistics.size(), 2u);
  EXPECT_EQ(scan.total_statistics[0].min, 1.0);
  EXPECT_EQ(scan.total_statistics[0].mean, 2.5);
  EXPECT_EQ(scan.total_statistics[0].max, 4.0);
  EXPECT_EQ(scan.total_statistics[1].min, 5.0);
  EXPECT_DOUBLE_EQ(scan.total_statistics[1].mean, 20.0 / 3.0);
  EXPECT_EQ(scan.total_statistics[1].max, 8.0);
  EXPECT_EQ(scan.total_statistics[1].finite, 3u);
  ASSERT_EQ(scan.non_finite.size(), 1u);
  EXPECT_EQ(scan.non_finite[0].first_x, 1);
  EXPECT_EQ(scan.non_finite[0].first_y, 0);
}

TEST(SpectralExrScan, ToleranceFollowsFromFloatRounding) {
  EXPECT_EQ(component_sum_tolerance(7, 1.0), 8 * (std::ldexp(1.0, -23) + std::ldexp(1.0, -149)));
  // All components zero: only the subnormal floor remains, still above zero.
  EXPECT_GT(component_sum_tolerance(3, 0.0), 0.0);
  // One ulp of a float total is within the bound for a single component (n = 1).
  const float total = 1.1f;
  EXPECT_LE(std::nextafter(total, 2.0f) - total, component_sum_tolerance(1, total));
}

TEST(SpectralExrScan, ComponentsThatSumPass) {
  TempDir dir;
  const fs::path path = dir.file("sums.exr");
  ComponentImage image = test::make_component_image(16, 9, 21);
  test::write_image(path, image, 16);
  SpectralExrReader reader(path);
  const SpectralExrScan scan = scan_spectral_exr(reader, {true, {}});
  ASSERT_EQ(scan.component_sums.size(), 1u);
  const ComponentSumCheck& check = scan.component_sums[0];
  EXPECT_EQ(check.family, ComponentFamily::PathType);
  EXPECT_TRUE(check.checked);
  EXPECT_TRUE(check.passed()) << check.worst_ratio;
  EXPECT_GT(check.worst_ratio, 0.0);  // rounding shows, but within the bound

  // A total summed in float, component after component, is within the bound too.
  for (std::size_t i = 0; i < image.total.size(); ++i) {
    float sum = 0;
    for (const auto& component : image.components) sum += component[i];
    image.total[i] = sum;
  }
  test::write_image(path, image, 16);
  SpectralExrReader float_sums(path);
  EXPECT_TRUE(scan_spectral_exr(float_sums, {true, {}}).component_sums[0].passed());
}

TEST(SpectralExrScan, AnAlteredComponentFailsAtItsPixel) {
  TempDir dir;
  const fs::path path = dir.file("altered.exr");
  ComponentImage image = test::make_component_image(16, 9, 21);
  const std::size_t index = (3 * 16 + 2) * image.layout.bands.size() + 4;
  image.components[1][index] += 1e-3f;  // far above rounding: ~150 tolerances
  test::write_image(path, image, 16);
  SpectralExrReader reader(path);
  const ComponentSumCheck check = scan_spectral_exr(reader, {true, {}}).component_sums.at(0);
  EXPECT_FALSE(check.passed());
  EXPECT_EQ(check.channel, "S0.530,000000nm");
  EXPECT_EQ(check.x, 2);
  EXPECT_EQ(check.y, 3);
}

TEST(SpectralExrScan, ChecksEachFamilyOnItsOwn) {
  TempDir dir;
  const fs::path path = dir.file("families.exr");
  SpectralExrLayout layout;
  layout.width = 3;
  layout.height = 2;
  layout.bands = Bands::uniform(400, 700, 100);
  // Two light groups and three bounce depths sum to the total; two path types do not (and need not).
  layout.components = {"light.ceiling", "light.lamp_2",   "bounce.0",     "bounce.1",
                       "bounce.2",      "diffuse_direct", "glossy_direct"};
  const std::vector<float> total(18, 6.0f), third(18, 2.0f), half(18, 3.0f), small(18, 0.5f);
  SpectralExrWriter writer(path, layout);
  writer.write_rows({2, total, {half, half, third, third, third, small, small}, {}});
  writer.finish();

  SpectralExrReader reader(path);
  const std::vector<ComponentSumCheck> checks = scan_spectral_exr(reader, {true, {}}).component_sums;
  ASSERT_EQ(checks.size(), 3u);
  EXPECT_EQ(checks[0].family, ComponentFamily::PathType);
  EXPECT_FALSE(checks[0].checked);
  EXPECT_EQ(checks[1].family, ComponentFamily::LightGroup);
  EXPECT_TRUE(checks[1].checked && checks[1].passed());
  EXPECT_EQ(checks[1].components, (std::vector<std::string>{"light.ceiling", "light.lamp_2"}));
  EXPECT_EQ(checks[2].family, ComponentFamily::Bounce);
  EXPECT_TRUE(checks[2].checked && checks[2].passed());
  EXPECT_EQ(checks[2].worst_ratio, 0.0);  // 2 + 2 + 2 = 6 exactly
}

}  // namespace
}  // namespace ct
