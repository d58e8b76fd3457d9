// SPDX-License-Identifier: Apache-2.0
// A file that stores something other than R, G, B — CMYK inks, or indices into a palette — is converted by
// OpenImageIO as it is read; the analysis says so (analysis.json's notes and stderr), and a plain RGB file gets
// no such note.
#include <array>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "analyzer/image_input.h"
#include "core/file_io.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

void put32(std::string& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<char>((v >> shift) & 0xff));
}

std::uint32_t crc32(std::string_view bytes) {  // PNG's CRC (ISO 3309), bit by bit
  std::uint32_t c = 0xffffffffu;
  for (const unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

void chunk(std::string& png, const std::string& type, const std::string& data) {
  put32(png, static_cast<std::uint32_t>(data.size()));
  const std::string body = type + data;
  png += body;
  put32(png, crc32(body));
}

// An 8-bit palette PNG (colour type 3), its image data in stored (uncompressed) deflate blocks.
std::string palette_png(int width, int height, const std::vector<std::array<std::uint8_t, 3>>& palette,
                        const std::vector<std::uint8_t>& indices) {
  std::string png = "\x89PNG\r\n\x1a\n";
  std::string ihdr;
  put32(ihdr, static_cast<std::uint32_t>(width));
  put32(ihdr, static_cast<std::uint32_t>(height));
  ihdr += std::string{'\x08', '\x03', '\0', '\0', '\0'};  // 8 bits, palette, deflate, no filter, no interlace
  chunk(png, "IHDR", ihdr);
  std::string plte;
  for (const auto& c : palette) plte += std::string{static_cast<char>(c[0]), static_cast<char>(c[1]), static_cast<char>(c[2])};
  chunk(png, "PLTE", plte);
  std::string raw;  // each row: filter type 0, then its indices
  for (int y = 0; y < height; ++y) {
    raw.push_back('\0');
    for (int x = 0; x < width; ++x) raw.push_back(static_cast<char>(indices[static_cast<std::size_t>(y * width + x)]));
  }
  std::string zlib = "\x78\x01";
  zlib += '\x01';  // one final stored block
  const auto n = static_cast<std::uint16_t>(raw.size());
  zlib += std::string{static_cast<char>(n & 0xff), static_cast<char>(n >> 8), static_cast<char>(~n & 0xff), static_cast<char>((~n >> 8) & 0xff)};
  zlib += raw;
  std::uint32_t a = 1, b = 0;  // Adler-32
  for (const unsigned char ch : raw) a = (a + ch) % 65521, b = (b + a) % 65521;
  put32(zlib, (b << 16) | a);
  chunk(png, "IDAT", zlib);
  chunk(png, "IEND", "");
  return png;
}

std::string notes_of(const AnalysisImage& image) {
  std::string all;
  for (const std::string& n : image.notes) all += n + "\n";
  return all;
}

TEST(InputConversions, PalettePngIsNoted) {
  TempDir dir;
  const std::vector<std::array<std::uint8_t, 3>> palette{{200, 40, 30}, {30, 160, 60}, {20, 50, 220}, {240, 240, 240}};
  const int w = 32, h = 16;
  std::vector<std::uint8_t> indices(static_cast<std::size_t>(w * h));
  for (int p = 0; p < w * h; ++p) indices[static_cast<std::size_t>(p)] = static_cast<std::uint8_t>((p % w) / 8);
  const std::filesystem::path file = dir.file("palette.png");
  std::ofstream(file, std::ios::binary) << palette_png(w, h, palette, indices);

  const AnalysisImage image = read_analysis_image(file);
  ASSERT_EQ(image.image.width, w);
  for (int x = 0; x < w; ++x)  // the palette's colours, expanded
    for (int c = 0; c < 3; ++c) EXPECT_EQ(image.image.rgb[static_cast<std::size_t>(x * 3 + c)], palette[static_cast<std::size_t>(x / 8)][static_cast<std::size_t>(c)]);
  EXPECT_NE(notes_of(image).find("indices into a palette (PNG colour type 3)"), std::string::npos) << notes_of(image);

  const CommandResult r = run_chromatrace({"analyze", file.string(), "-o", dir.file("o").string(), "--no-plots", "--no-report"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("palette.png: note: the file stores indices into a palette"), std::string::npos) << r.err;
  const nlohmann::json a = nlohmann::json::parse(read_file(dir.file("o") / "analysis.json"));
  EXPECT_NE(a["notes"].dump().find("indices into a palette"), std::string::npos) << a["notes"].dump();
}

TEST(InputConversions, CmykTiffIsNotedAndAnRgbFileIsNot) {
  TempDir dir;
  const int w = 16, h = 8;
  const std::array<std::uint8_t, 3> rgb{51, 128, 204};
  std::vector<std::uint8_t> pixels;
  for (int p = 0; p < w * h; ++p) pixels.insert(pixels.end(), rgb.begin(), rgb.end());
  auto write = [&](const std::filesystem::path& file, bool cmyk) {
    OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
    if (cmyk) spec.attribute("tiff:ColorSpace", "CMYK");  // OpenImageIO's TIFF writer stores inks (photometric 5)
    auto out = OIIO::ImageOutput::create(file.string());
    ASSERT_TRUE(out && out->open(file.string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) && out->close());
  };
  write(dir.file("cmyk.tif"), true);
  write(dir.file("rgb.tif"), false);
  {
    auto in = OIIO::ImageInput::open(dir.file("cmyk.tif").string());
    ASSERT_TRUE(in);
    ASSERT_EQ(in->spec().get_int_attribute("tiff:PhotometricInterpretation"), 5);  // the file really holds inks
  }
  const AnalysisImage cmyk = read_analysis_image(dir.file("cmyk.tif"));
  EXPECT_NE(notes_of(cmyk).find("CMYK ink values (tiff:ColorSpace CMYK)"), std::string::npos) << notes_of(cmyk);
  // Back to R, G, B: two 8-bit roundings of the inks (≤ 0.5 DN each) through 1 − K = 0.8: within 1.25 DN.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(cmyk.image.rgb[static_cast<std::size_t>(c)], rgb[static_cast<std::size_t>(c)], 1.25);

  const AnalysisImage plain = read_analysis_image(dir.file("rgb.tif"));
  EXPECT_EQ(notes_of(plain).find("the file stores"), std::string::npos) << notes_of(plain);
}

}  // namespace
}  // namespace ct::test
