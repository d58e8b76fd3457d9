// SPDX-License-Identifier: Apache-2.0
// Reading images: integer files in digital numbers, float files as stored, the sensor simulator's EXR
// layers and object ids, and one-line errors naming the file.
#include <fstream>

#include <gtest/gtest.h>

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
