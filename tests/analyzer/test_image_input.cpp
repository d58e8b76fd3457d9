// SPDX-License-Identifier: Apache-2.0
// Reading images: integer files in digital numbers, float files as stored, the sensor simulator's EXR
// layers and object ids, and one-line errors naming the file.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "analyzer/analysis.h"
#include "analyzer/analysis_json.h"
#include "analyzer/image_input.h"
#include "core/error.h"
#include "tests/analyzer/synthetic.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

TEST(ImageInput, IntegerFilesKeepTheirDigitalNumbers) {
  TempDir dir;
  const RgbImage image = make_image(8, 4, [](double u, double v) -> Vec3 { return Vec3(u, v, 1.0); });
  write_rgb(dir.file("a.png"), image, 8);
  write_rgb(dir.file("b.tif"), image, 16);
  const AnalysisImage png = read_analysis_image(dir.file("a.png"));
  EXPECT_TRUE(png.encoding.integer);
  EXPECT_EQ(png.encoding.bits, 8);
  EXPECT_EQ(png.encoding.full_scale, 255);
  EXPECT_EQ(png.image.rgb[2], 255.0f);
  EXPECT_EQ(png.image.rgb[(7 * 3)], 255.0f);  // u = 1 at x = 7
  const AnalysisImage tif = read_analysis_image(dir.file("b.tif"));
  EXPECT_EQ(tif.encoding.full_scale, 65535);
  EXPECT_EQ(tif.image.rgb[2], 65535.0f);
  EXPECT_FALSE(tif.linear);
  EXPECT_TRUE(tif.components.empty());
}

// Pixels already in memory are the same analysis image as the file they were read from: the test photograph
// smarties.png's stored integers, given as an 8-bit array, give the file's analysis (its whole image and its
// segments), its name and the words for where its curve came from aside; and "linear" is taken as said.
// A size that does not match the values is an InputError naming the array.
TEST(ImageInput, PixelsInMemoryAreTheFileTheyWereReadFrom) {
  const std::filesystem::path photo = std::filesystem::path(CHROMATRACE_SOURCE_DIR) / "tests/data/photos/smarties.png";
  const AnalysisImage file = read_analysis_image(photo);
  ASSERT_TRUE(file.encoding.integer);
  ASSERT_EQ(file.encoding.bits, 8);
  std::vector<float> stored = file.image.rgb;  // the stored integers (no black level in a plain PNG)
  const AnalysisImage memory = read_analysis_pixels("an array", file.image.width, file.image.height, stored, 8);
  EXPECT_EQ(memory.image.rgb, file.image.rgb);
  ASSERT_TRUE(memory.encoding.curve && file.encoding.curve);
  EXPECT_EQ(memory.encoding.curve->describe(), file.encoding.curve->describe());
  RegionOptions regions;
  regions.segment = true;
  auto analysed = [&](const AnalysisImage& in) {
    ImageAnalysis a = analyse_image(in, "final", select_regions(in, in.image, regions), AnalyzeOptions{}, std::nullopt, false);
    nlohmann::json j = analysis_to_json(a);
    // Set aside the input's name, and the words for where the curve came from (the file's colour space, or an
    // array's type), here and where the notes quote them.
    j["image"].erase("file");
    const std::string source = j["input"]["curve"]["source"].get<std::string>();
    j["input"]["curve"].erase("source");
    for (auto& note : j["notes"]) {
      std::string text = note.get<std::string>();
      if (const auto at = text.find(source); at != std::string::npos) text.replace(at, source.size(), "…");
      note = text;
    }
    return j;
  };
  const nlohmann::json from_memory = analysed(memory), from_file = analysed(file);
  EXPECT_EQ(from_memory, from_file) << nlohmann::json::diff(from_file, from_memory).dump();
  EXPECT_NE(from_file["regions"].size(), 1u);  // segments too, not the whole image alone
  EXPECT_FALSE(read_analysis_pixels("an array", 2, 1, {0, 0, 0, 1, 1, 1}, 0, "linear").encoding.curve->srgb);
  try {
    (void)read_analysis_pixels("an array", 3, 1, {0, 0, 0}, 8);
    ADD_FAILURE() << "a size that does not match was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "an array: 3 values for 3 x 1 pixels of R, G, B");
  }
}

TEST(ImageInput, SensorExrGivesLayersComponentsAndObjects) {
  TempDir dir;
  const SensorExr exr = scene_with_components();
  write_sensor_exr(dir.file("s.exr"), exr);
  const AnalysisImage in = read_analysis_image(dir.file("s.exr"));
  EXPECT_FALSE(in.encoding.integer);
  ASSERT_TRUE(in.linear);
  EXPECT_EQ(in.linear->rgb, exr.linear.rgb);
  ASSERT_EQ(in.components.size(), exr.components.size());
  for (std::size_t c = 0; c < in.components.size(); ++c) EXPECT_EQ(in.components[c].name, exr.components[c].first);
  EXPECT_EQ(in.object_ids, exr.ids);
  EXPECT_EQ(in.object_names.at(3), "blue");
  EXPECT_EQ(&select_layer(in, "glossy_direct"), &in.components[1].image);
  EXPECT_THROW(select_layer(in, "nonsense"), InputError);
}

TEST(ImageInput, UnreadableFilesAreInputErrorsNamingTheFile) {
  TempDir dir;
  std::ofstream(dir.file("junk.png")) << "not an image";
  for (const auto& name : {dir.file("missing.exr"), dir.file("junk.png")}) {
    try {
      read_analysis_image(name);
      FAIL() << "no error for " << name;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(name.string()), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(ImageInput, ObjectIdsMustBeWholeNumbers) {
  TempDir dir;
  SensorExr exr = scene_with_components();
  exr.components.clear();
  write_sensor_exr(dir.file("ok.exr"), exr);
  EXPECT_NO_THROW(read_analysis_image(dir.file("ok.exr")));
  exr.ids[5] = -1;  // written as −1.0
  write_sensor_exr(dir.file("bad.exr"), exr);
  EXPECT_THROW(read_analysis_image(dir.file("bad.exr")), InputError);
}

}  // namespace
}  // namespace ct::test
