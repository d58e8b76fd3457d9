// SPDX-License-Identifier: Apache-2.0
// `chromatrace prepare-texture`: per-band-group textures for Cycles, end to end through the executable. The
// texel values must be the band averages of the tracer's own per-texel spectra (core/texture.h).
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/colour.h"
#include "core/error.h"
#include "core/rgb_to_spectrum.h"
#include "core/spectrum.h"
#include "core/texture.h"
#include "tests/core/image_fixtures.h"
#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::run_chromatrace;

using test::line_count;

class PrepareTexture : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("ct-prep-{}-{}", ::getpid(), counter_++);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Float pixels for .exr, 8-bit (values 0..255 given as floats / 255) otherwise; rows from the top.
  fs::path write_image(const std::string& name, int width, int height, const std::vector<float>& pixels,
                       int channels = 3) const {
    return test::write_test_image(dir_ / name, width, height, pixels, channels);
  }

  static std::vector<float> read_rgb(const fs::path& path, int& width, int& height) {
    auto in = OIIO::ImageInput::open(path.string());
    EXPECT_TRUE(in) << path;
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::FLOAT);
    width = spec.width;
    height = spec.height;
    std::vector<float> pixels(static_cast<std::size_t>(width * height * 3));
    EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
    return pixels;
  }

  json run_json(const std::vector<std::string>& args) const {
    std::vector<std::string> all = {"prepare-texture"};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"-o", (dir_ / "cache").string(), "--json"});
    const auto r = run_chromatrace(all);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.exit_code == 0 ? json::parse(r.out) : json();
  }

  fs::path dir_;
  static inline int counter_ = 0;
};

TEST_F(PrepareTexture, GroupTexelsAreTheTracersBandAverages) {
  // 2×2 sRGB-encoded 8-bit colours, rows from the top.
  const std::vector<int> bytes = {255, 0, 0, 0, 128, 255, 200, 180, 20, 64, 64, 64};
  std::vector<float> pixels;
  for (const int b : bytes) pixels.push_back(static_cast<float>(b) / 255.0f);
  const fs::path png = write_image("colours.png", 2, 2, pixels);

  const json summary = run_json({png.string(), "--bands", "400:470:10", "--kind", "reflectance"});
  ASSERT_TRUE(summary.is_object());
  EXPECT_FALSE(summary["cached"].get<bool>());
  EXPECT_EQ(summary["colour_space"], "sRGB");
  EXPECT_EQ(summary["texels"], 4);
  EXPECT_EQ(summary["distinct_colours"], 4);
  // 7 bands, 3 to a render, interleaved so that each render spans the spectrum: [0,3,6], [1,4], [2,5].
  ASSERT_EQ(summary["groups"].size(), 3u);
  EXPECT_EQ(summary["groups"][0]["bands"], json::array({0, 3, 6}));
  EXPECT_EQ(summary["groups"][1]["bands"], json::array({1, 4}));
  EXPECT_EQ(summary["groups"][2]["bands"], json::array({2, 5}));
  const std::vector<std::vector<std::size_t>> members = {{0, 3, 6}, {1, 4}, {2, 5}};

  const Bands bands = Bands::parse("400:470:10");
  const ImageTexture texture = read_image_texture(png, "colours.png", std::nullopt, TextureUse::Reflectance, 1.0);
  for (std::size_t g = 0; g < 3; ++g) {
    int w = 0, h = 0;
    const std::vector<float> out = read_rgb(summary["groups"][g]["file"].get<std::string>(), w, h);
    ASSERT_EQ(w, 2);
    ASSERT_EQ(h, 2);
    for (std::size_t t = 0; t < 4; ++t) {
      // The texel as the tracer decodes it (OpenImageIO's 8-bit to float conversion, the sRGB curve).
      const std::array<double, 3> rgb = texture.texel(t);
      for (std::size_t c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], srgb_decode(pixels[3 * t + c]), 1e-6);
      const std::vector<double> expected =
          band_averages(texel_spectrum(rgb, TextureUse::Reflectance).tabulated(), bands);
      for (std::size_t c = 0; c < 3; ++c) {
        const float want = c < members[g].size() ? static_cast<float>(expected[members[g][c]]) : 0.0f;
        EXPECT_EQ(out[3 * t + c], want) << "group " << g << " texel " << t << " channel " << c;
      }
    }
  }
}

// A grey reflectance is flat; an emitted grey is that grey times the colour space's white, D65 of unit luminance
// (rgb_white_at), band by band. Bound: the float the band value is stored as (2⁻²⁴ relative) and the
// double rounding of the band average (1e-15).
TEST_F(PrepareTexture, GreyIsFlatOrTheWhitesSpectrum) {
  const fs::path grey = write_image("grey.exr", 4, 2, std::vector<float>(4 * 2 * 3, 0.5f));
  const Bands bands = Bands::parse("400:700:20");
  const std::vector<double> white = band_averages(rgb_to_emission_spectrum({1.0, 1.0, 1.0}), bands);
  for (const std::string kind : {"reflectance", "radiance"}) {
    const json summary = run_json({grey.string(), "--bands", "400:700:20", "--kind", kind});
    ASSERT_TRUE(summary.is_object());
    EXPECT_EQ(summary["colour_space"], "linear");
    EXPECT_EQ(summary["distinct_colours"], 1);
    ASSERT_EQ(summary["groups"].size(), 5u);
    for (std::size_t group = 0; group < 5; ++group) {
      int w = 0, h = 0;
      const std::string file = summary["groups"][group]["file"].get<std::string>();
      const std::vector<float> out = read_rgb(file, w, h);
      for (std::size_t i = 0; i < out.size(); ++i) {
        // 15 bands in 5 renders: render g holds bands g, g + 5, g + 10.
        const double want = kind == "reflectance" ? 0.5 : 0.5 * white[group + 5 * (i % 3)];
        EXPECT_NEAR(out[i], want, 1e-7 * want) << kind << " " << file << " channel " << i % 3;
      }
    }
  }
}

// The one-band fallback: each render holds one band in all three channels, the band of a three-band group's R, G or B.
TEST_F(PrepareTexture, ReplicatePutsTheOneBandInEveryChannel) {
  const fs::path png = write_image("two.png", 2, 1, {1.0f, 0.0f, 0.0f, 0.2f, 0.6f, 0.9f});
  const json three = run_json({png.string(), "--bands", "400:460:20", "--kind", "reflectance"});
  const json one = run_json({png.string(), "--bands", "400:460:20", "--kind", "reflectance", "--bands-per-render", "1",
                             "--replicate"});
  ASSERT_TRUE(three.is_object() && one.is_object());
  EXPECT_TRUE(one["replicate"].get<bool>());
  EXPECT_NE(one["hash"], three["hash"]);
  ASSERT_EQ(three["groups"].size(), 1u);
  ASSERT_EQ(one["groups"].size(), 3u);
  int w = 0, h = 0;
  const std::vector<float> grouped = read_rgb(three["groups"][0]["file"].get<std::string>(), w, h);
  for (std::size_t band = 0; band < 3; ++band) {
    const std::vector<float> single = read_rgb(one["groups"][band]["file"].get<std::string>(), w, h);
    ASSERT_EQ(single.size(), 6u);
    for (std::size_t t = 0; t < 2; ++t)
      for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(single[3 * t + c], grouped[3 * t + band]) << band << " " << t << " " << c;
  }
}

// A texture's "scale" multiplies every texel's spectrum, so every band average scales with it exactly (in float).
TEST_F(PrepareTexture, ScaleMultipliesEveryBand) {
  const fs::path png = write_image("scaled.png", 2, 1, {0.8f, 0.3f, 0.1f, 0.1f, 0.5f, 0.7f});
  const json plain = run_json({png.string(), "--bands", "400:700:100", "--kind", "reflectance"});
  const json half = run_json({png.string(), "--bands", "400:700:100", "--kind", "reflectance", "--scale", "0.5"});
  ASSERT_TRUE(plain.is_object() && half.is_object());
  EXPECT_NE(plain["hash"], half["hash"]);
  int w = 0, h = 0;
  const std::vector<float> a = read_rgb(plain["groups"][0]["file"].get<std::string>(), w, h);
  const std::vector<float> b = read_rgb(half["groups"][0]["file"].get<std::string>(), w, h);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(b[i], 0.5f * a[i], 1e-6f * a[i]) << i;
}

TEST_F(PrepareTexture, CachesByContent) {
  const fs::path png = write_image("c.png", 3, 2, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f,
                                                   1.0f, 0.0f, 0.5f, 0.2f, 0.2f, 0.2f, 0.9f, 0.1f, 0.1f});
  const json first = run_json({png.string(), "--bands", "400:500:20", "--kind", "reflectance"});
  ASSERT_TRUE(first.is_object());
  EXPECT_FALSE(first["cached"].get<bool>());
  std::vector<fs::file_time_type> times;
  for (const json& g : first["groups"]) times.push_back(fs::last_write_time(g["file"].get<std::string>()));
  const auto count_files = [&] {
    return std::distance(fs::directory_iterator(dir_ / "cache"), fs::directory_iterator());
  };
  const auto files_before = count_files();
  EXPECT_EQ(files_before, 3);  // two groups and the manifest

  const auto again = run_chromatrace({"prepare-texture", png.string(), "--bands", "400:500:20", "--kind",
                                      "reflectance", "-o", (dir_ / "cache").string(), "--json"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const json second = json::parse(again.out);
  EXPECT_TRUE(second["cached"].get<bool>());
  EXPECT_NE(again.err.find("cached"), std::string::npos) << again.err;
  EXPECT_EQ(second["hash"], first["hash"]);
  EXPECT_EQ(second["distinct_colours"], first["distinct_colours"]);
  EXPECT_EQ(second["groups"], first["groups"]);
  for (std::size_t g = 0; g < times.size(); ++g)
    EXPECT_EQ(fs::last_write_time(first["groups"][g]["file"].get<std::string>()), times[g]);
  EXPECT_EQ(count_files(), files_before);

  const auto quiet = run_chromatrace({"prepare-texture", png.string(), "--bands", "400:500:20", "--kind",
                                      "reflectance", "-o", (dir_ / "cache").string(), "--quiet"});
  EXPECT_EQ(quiet.exit_code, 0);
  EXPECT_EQ(quiet.err, "");

  // Another band plan, group size, kind or colour space is another hash.
  const json plan = run_json({png.string(), "--bands", "400:500:25", "--kind", "reflectance"});
  const json per_render = run_json({png.string(), "--bands", "400:500:20", "--kind", "reflectance", "--bands-per-render", "2"});
  const json kind = run_json({png.string(), "--bands", "400:500:20", "--kind", "radiance"});
  const json space = run_json({png.string(), "--bands", "400:500:20", "--kind", "reflectance", "--colour-space", "linear"});
  for (const json* other : {&plan, &per_render, &kind, &space}) {
    EXPECT_FALSE((*other)["cached"].get<bool>());
    EXPECT_NE((*other)["hash"], first["hash"]);
  }
  EXPECT_EQ(per_render["groups"].size(), 3u);
  // Naming the default colour space is the same request as leaving it to the file's type.
  EXPECT_EQ(run_json({png.string(), "--bands", "400:500:20", "--kind", "reflectance", "--colour-space", "sRGB"})["cached"], true);
}

TEST_F(PrepareTexture, ReflectanceAboveOneIsRefusedNamingTheTexel) {
  std::vector<float> pixels(2 * 2 * 3, 0.25f);
  pixels[3 * 1 + 1] = 1.5f;  // texel (1, 0), green
  const fs::path hot = write_image("hot.exr", 2, 2, pixels);
  const auto r = run_chromatrace({"prepare-texture", hot.string(), "--bands", "400:700:10", "--kind", "reflectance",
                                  "-o", (dir_ / "cache").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(hot.string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("texel (1, 0)"), std::string::npos) << r.err;
  EXPECT_TRUE(!fs::exists(dir_ / "cache") || fs::is_empty(dir_ / "cache"));
  // The same image is a valid radiance (an HDRI may exceed 1).
  EXPECT_EQ(run_json({hot.string(), "--bands", "400:700:10", "--kind", "radiance"})["texels"], 4);
}

TEST_F(PrepareTexture, BadInputIsOneLineExitTwo) {
  const fs::path png = write_image("ok.png", 1, 1, {0.5f, 0.5f, 0.5f});
  const std::string out = (dir_ / "cache").string();
  struct Case {
    std::vector<std::string> args;
    std::string must_mention;
  };
  const std::vector<Case> cases = {
      {{(dir_ / "missing.png").string(), "--bands", "400:700:10", "--kind", "reflectance"}, "missing.png: cannot open file"},
      {{(dir_ / "missing.exr").string(), "--bands", "400:700:10", "--kind", "radiance", "--colour-space", "linear"},
       "missing.exr: cannot open file"},
      {{png.string(), "--bands", "400:700:10", "--kind", "albedo"}, "--kind"},
      {{png.string(), "--bands", "400:700:7", "--kind", "reflectance"}, "--bands"},
      {{png.string(), "--bands", "400:700:10", "--kind", "reflectance", "--colour-space", "ACES"}, "--colour-space"},
      {{png.string(), "--bands", "400:700:10", "--kind", "reflectance", "--bands-per-render", "4"}, "--bands-per-render"},
      {{png.string(), "--bands-file", (dir_ / "no-plan.json").string(), "--kind", "reflectance"}, "no-plan.json"},
      {{png.string(), "--kind", "reflectance"}, "--bands"},
      {{png.string(), "--bands", "400:700:10", "--kind", "reflectance", "--replicate"}, "--replicate"},
      {{png.string(), "--bands", "400:700:10", "--kind", "reflectance", "--scale", "-1"}, "--scale"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"prepare-texture"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    args.insert(args.end(), {"-o", out});
    const auto r = run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 2) << c.must_mention << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.must_mention), std::string::npos) << r.err;
  }
}

TEST_F(PrepareTexture, AlphaIsIgnoredAndSaid) {
  const fs::path rgba = write_image("rgba.png", 1, 1, {0.5f, 0.25f, 0.75f, 0.0f}, 4);
  const auto r = run_chromatrace({"prepare-texture", rgba.string(), "--bands", "400:700:100", "--kind", "reflectance",
                                  "-o", (dir_ / "cache").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("alpha channel ignored"), std::string::npos) << r.err;
  EXPECT_TRUE(json::parse(r.out)["alpha_ignored"].get<bool>());
}

// A real HDRI's capture noise: negative texels no deeper than the image's dark end (the 10th percentile of its
// positive channel values) and together under 1e-4 of its light are set to zero and counted, in prepare-texture
// and in the tracer's reader alike; a negative deeper than the dark end, or many that together carry light, is
// refused naming the deepest texel. The image: 100 texels of a dim ramp 0.01..1 in each channel, so the dark end
// is the ramp's 10th percentile.
TEST_F(PrepareTexture, CaptureNoiseIsZeroedAndNegativeLightRefused) {
  std::vector<float> ramp;
  for (int i = 0; i < 100; ++i)
    for (int c = 0; c < 3; ++c) ramp.push_back(0.01f * static_cast<float>(i + 1));
  std::vector<float> noisy = ramp, deep = ramp, many = ramp;
  noisy[3 * 7 + 2] = -0.004f;  // 0.004 / 151.5 = 2.6e-5 of the light
  noisy[3 * 42 + 0] = -0.001f;
  deep[3 * 13 + 1] = -0.5f;  // deeper than the dark end
  for (int i = 0; i < 60; ++i) many[3 * i + 1] = -0.05f;  // each within it, together 0.02 of the light
  const fs::path noisy_exr = write_image("noisy.exr", 10, 10, noisy), deep_exr = write_image("deep.exr", 10, 10, deep),
                 many_exr = write_image("many.exr", 10, 10, many);

  const auto r = run_chromatrace({"prepare-texture", noisy_exr.string(), "--kind", "radiance", "--bands", "400:700:100",
                                  "-o", (dir_ / "cache").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json summary = json::parse(r.out);
  EXPECT_EQ(summary["negative_texels"]["zeroed"], 2);
  EXPECT_FLOAT_EQ(summary["negative_texels"]["largest"].get<float>(), 0.004f);
  const float dark_end = 0.01f * 11;  // the 30-th of 300 positive values, sorted, counting from 0
  EXPECT_FLOAT_EQ(summary["negative_texels"]["threshold"].get<float>(), dark_end);
  EXPECT_NE(r.err.find("2 negative channel values (capture noise"), std::string::npos) << r.err;
  const ImageTexture texture = read_image_texture(noisy_exr, "noisy.exr", std::nullopt, TextureUse::Radiance, 1.0);
  EXPECT_EQ(texture.negatives.count, 2u);
  EXPECT_EQ(texture.rgb[3 * 7 + 2], 0.0f);
  EXPECT_EQ(texture.rgb[3 * 7 + 1], ramp[3 * 7 + 1]);

  for (const auto& [image, texel] : {std::pair{deep_exr, std::string("texel (3, 1)")},
                                     std::pair{many_exr, std::string("texel (0, 0)")}}) {
    const auto refused = run_chromatrace({"prepare-texture", image.string(), "--kind", "radiance", "--bands",
                                          "400:700:100", "-o", (dir_ / "refused").string()});
    EXPECT_EQ(refused.exit_code, 2) << refused.err;
    EXPECT_EQ(line_count(refused.err), 1) << refused.err;
    EXPECT_NE(refused.err.find(image.string() + ": "), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("carry light that cannot be"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find(texel), std::string::npos) << refused.err;
    EXPECT_THROW(read_image_texture(image, "x.exr", std::nullopt, TextureUse::Radiance, 1.0), InputError);
  }
}

// A full disk part way (a tmpfs, in a mount namespace of its own, with room for about three of the ten group files):
// the command fails naming the file it could not write, and leaves no group file without its manifest, nor the
// cache directory it made.
TEST_F(PrepareTexture, AFullDiskLeavesNoGroupWithoutItsManifest) {
  std::vector<float> pixels(64 * 64 * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<float>((i * 7919) % 251) / 251.0f;  // no long runs
  const fs::path image = write_image("noisy.exr", 64, 64, pixels);
  const json whole = run_json({image.string(), "--bands", "400:700:10", "--kind", "reflectance"});
  ASSERT_EQ(whole["groups"].size(), 10u);
  const std::uintmax_t group = fs::file_size(whole["groups"][0]["file"].get<std::string>());
  const std::uintmax_t room = (3 * group + 4095) / 4096 * 4096;
  const fs::path disk = dir_ / "disk";
  fs::create_directory(disk);
  const std::string command =
      fmt::format("mount -t tmpfs -o size={} tmpfs '{}' || {{ echo mount-failed; exit 0; }}; '{}' prepare-texture '{}' --bands 400:700:10 "
                  "--kind reflectance -o '{}/cache' --quiet; echo exit=$?; ls -A '{}'",
                  room, disk.string(), CHROMATRACE_EXE, image.string(), disk.string(), disk.string());
  const auto r = test::run_program("/usr/bin/unshare", {"-m", "sh", "-c", command});
  if (r.out.find("mount-failed") != std::string::npos) GTEST_SKIP() << "no mount namespace here (unshare -m and a tmpfs need CAP_SYS_ADMIN)";
  EXPECT_EQ(r.out, "exit=1\n") << r.out << r.err;  // nothing listed: no cache directory
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace ct
