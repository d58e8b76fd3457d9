// SPDX-License-Identifier: Apache-2.0
// The EXR words every part shares (core/exr_vocabulary.h) and the one atomic EXR output (core/exr_output.h).
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfInputFile.h>

#include "core/error.h"
#include "core/exr_output.h"
#include "core/exr_vocabulary.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

TEST(ExrVocabulary, ObjectIdsAreWholeNumbersAFloatHoldsExactly) {
  EXPECT_TRUE(exr::is_object_id(0));
  EXPECT_TRUE(exr::is_object_id(16777216));  // 2^24: the last integer a float holds with its neighbours
  EXPECT_FALSE(exr::is_object_id(16777217));
  EXPECT_FALSE(exr::is_object_id(-1));
  EXPECT_FALSE(exr::is_object_id(1.5));
  EXPECT_FALSE(exr::is_object_id(std::nan("")));
}

TEST(ExrVocabulary, ObjectNamesRoundTripAndBadOnesAreNamed) {
  const std::map<std::int32_t, std::string> names = {{0, "sky"}, {7, "sphere"}, {16777216, "last"}};
  EXPECT_EQ(exr::object_names_text(names), R"({"0":"sky","16777216":"last","7":"sphere"})");
  EXPECT_EQ(exr::parse_object_names(exr::object_names_text(names), "f"), names);
  const std::pair<const char*, const char*> bad[] = {
      {"[1]", "f.exr: attribute chromatrace.objects: not a JSON object from object id to name"},
      {"{\"a\": \"x\"}", "f.exr: attribute chromatrace.objects: key \"a\" is not an object id (a whole number in [0, 16777216])"},
      {"{\"-1\": \"x\"}", "key \"-1\" is not an object id"},
      {"{\"1.5\": \"x\"}", "key \"1.5\" is not an object id"},
      {"{\"16777217\": \"x\"}", "key \"16777217\" is not an object id"},
      {"{\"3\": 4}", "f.exr: attribute chromatrace.objects: object 3: name must be a string"},
  };
  for (const auto& [text, message] : bad) {
    try {
      exr::parse_object_names(text, "f.exr: attribute chromatrace.objects");
      ADD_FAILURE() << text << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

TEST(ExrVocabulary, ComponentListsAreCommaSeparated) {
  EXPECT_EQ(exr::component_list_text({"diffuse_direct", "light.key"}), "diffuse_direct,light.key");
  EXPECT_EQ(exr::parse_component_list("diffuse_direct, light.key,,bounce.2 "),
            (std::vector<std::string>{"diffuse_direct", "light.key", "bounce.2"}));
  EXPECT_TRUE(exr::parse_component_list("").empty());
}

Imf::Header one_channel_header(int width, int height) {
  Imf::Header header(width, height);
  header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
  return header;
}

TEST(AtomicExrOutput, OnlyAFinishedFileAppears) {
  TempDir dir;
  const auto target = dir.file("out.exr");
  std::vector<float> rows(4 * 2, 0.5f);
  Imf::FrameBuffer frame;
  frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, rows.data(), Imath::Box2i({0, 0}, {3, 1}), sizeof(float), 4 * sizeof(float)));
  {
    AtomicExrOutput out(target, one_channel_header(4, 2));
    out.write_rows(frame, 0, 2);
  }  // destroyed unfinished: nothing at the target, no temporary left
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  AtomicExrOutput out(target, one_channel_header(4, 2));
  out.write_rows(frame, 0, 2);
  EXPECT_FALSE(std::filesystem::exists(target));
  out.finish();
  ASSERT_TRUE(std::filesystem::exists(target));
  Imf::InputFile in(target.c_str());
  EXPECT_EQ(in.header().dataWindow().max.x, 3);
  EXPECT_THROW(out.finish(), std::logic_error);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(AtomicExrOutput, AMissingDirectoryIsAnInputError) {
  TempDir dir;
  EXPECT_THROW(AtomicExrOutput(dir.file("no/such/dir.exr"), one_channel_header(1, 1)), InputError);
}

}  // namespace
}  // namespace ct::test
