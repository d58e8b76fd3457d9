// SPDX-License-Identifier: Apache-2.0
// chromatrace analyze end to end: outputs, regions, and bad input (unreadable image, empty, one-pixel,
// all-black and all-NaN regions) answered with a reason, never a crash.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "analyzer/image_input.h"
#include "core/colour.h"
#include "core/file_io.h"
#include "tests/analyzer/synthetic.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

nlohmann::json analysis(const std::filesystem::path& dir) { return nlohmann::json::parse(read_file(dir / "analysis.json")); }

const nlohmann::json* region_named(const nlohmann::json& a, const std::string& name) {
  for (const auto& r : a["regions"])
    if (r["name"] == name) return &r;
  return nullptr;
}

TEST(AnalyzeCommand, WritesJsonPlotsHistogramsAndReport) {
  TempDir dir;
  write_sensor_exr(dir.file("scene.exr"), scene_with_components());
  const auto out = dir.file("out");
  const CommandResult r = run_chromatrace({"analyze", dir.file("scene.exr").string(), "-o", out.string(), "--illuminant", "1,0.9,0.75", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json a = analysis(out);
  EXPECT_EQ(a["format"], "chromatrace-analysis/1");
  ASSERT_EQ(a["regions"].size(), 5u);  // the image and four objects
  EXPECT_EQ(a["regions"][3]["name"], "object 3 (blue)");
  EXPECT_EQ(a["regions"][3]["explanation"]["families"][0]["family"], "path types");
  EXPECT_LT(a["illuminant"]["estimate"]["error_deg"].get<double>(), 3.0);
  EXPECT_EQ(a["illuminant"]["statistical"][0]["method"], "grey world");
  EXPECT_TRUE(a["illuminant"].contains("inverse_intensity_chromaticity"));
  EXPECT_TRUE(a["illuminant"]["statistical"][0]["error_deg"].is_number());
  for (int i = 0; i < 5; ++i) {
    const std::string stem = "region-0" + std::to_string(i);
    EXPECT_TRUE(std::filesystem::is_regular_file(out / "plots" / (stem + ".png")));
    EXPECT_TRUE(std::filesystem::is_regular_file(out / "plots" / (stem + "-density.png")));
    EXPECT_TRUE(std::filesystem::is_regular_file(out / "plots" / (stem + "-components.png")));
    EXPECT_TRUE(std::filesystem::is_regular_file(out / "histograms" / (stem + ".json")));
  }
  const std::string html = read_file(out / "report.html");
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);  // self-contained
  // No temporary files left behind.
  for (const auto& e : std::filesystem::recursive_directory_iterator(out)) EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos);
}

TEST(AnalyzeCommand, ReadsEightBitImagesWithRegionsFromRectanglesAndSegments) {
  TempDir dir;
  write_rgb(dir.file("scene.png"), dichromatic_scene(Vec3(1, 0.85, 0.6)).image, 8);
  const auto out = dir.file("out");
  const CommandResult r = run_chromatrace({"analyze", dir.file("scene.png").string(), "-o", out.string(), "--rect", "0,0,96,96", "--segment",
                                           "--no-plots", "--no-report", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json a = analysis(out);
  EXPECT_EQ(a["image"]["bits"], 8);
  EXPECT_EQ(a["image"]["full_scale"], 255);
  const nlohmann::json* rect = region_named(a, "rect 0,0 96x96");
  ASSERT_TRUE(rect);
  EXPECT_EQ((*rect)["pixels"], 96 * 96);
  int segments = 0;
  for (const auto& region : a["regions"]) segments += region["source"] == "segment";
  EXPECT_EQ(segments, 4) << a["regions"].dump(1);  // one per sphere; the black background is left out
  EXPECT_FALSE(std::filesystem::exists(out / "report.html"));
}

// What R, G, B are is decided (and said) before any fit through black: an sRGB picture and its linearised copy,
// made by oiiotool, analysed with --input-transfer auto, give the same classes in linear light and the same
// directions within 1° (the sRGB file's 16-bit codes keep the linear values to far better than that).
TEST(AnalyzeCommand, AnSrgbPictureAndItsLinearCopyAgree) {
  TempDir dir;
  const Scene scene = dichromatic_scene(Vec3(1, 0.85, 0.6));
  RgbImage encoded = scene.image, labels = scene.image;
  for (float& v : encoded.rgb) v = static_cast<float>(srgb_encode(std::clamp(static_cast<double>(v), 0.0, 1.0)));
  for (std::size_t p = 0; p < scene.ids.size(); ++p)
    for (std::size_t c = 0; c < 3; ++c) labels.rgb[p * 3 + c] = static_cast<float>(scene.ids[p]) / 255.0f;
  write_rgb(dir.file("scene.png"), encoded, 16);
  write_rgb(dir.file("labels.png"), labels, 8);
  const std::string convert = fmt::format("oiiotool {} --iscolorspace sRGB --colorconvert sRGB linear -d float -o {}",
                                          dir.file("scene.png").string(), dir.file("linear.exr").string());
  ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
  std::map<std::string, nlohmann::json> a;
  for (const std::string file : {"scene.png", "linear.exr"}) {
    const auto out = dir.file(file + ".out");
    const CommandResult r = run_chromatrace({"analyze", dir.file(file).string(), "-o", out.string(), "--labels",
                                             dir.file("labels.png").string(), "--no-plots", "--no-report"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    a[file] = analysis(out);
    // Said on stderr and in analysis.json.
    EXPECT_NE(r.err.find(file == "scene.png" ? "encoded by the sRGB curve" : "taken as linear light"), std::string::npos) << r.err;
  }
  EXPECT_EQ(a["scene.png"]["input"]["curve"]["srgb"], true);
  EXPECT_EQ(a["scene.png"]["input"]["curve"]["source"], "the file's colour space (oiio:ColorSpace sRGB)");
  EXPECT_EQ(a["linear.exr"]["input"]["curve"]["linearised"], false);
  const auto angle = [](const nlohmann::json& u, const nlohmann::json& v) {
    const Vec3 x(u[0], u[1], u[2]), y(v[0], v[1], v[2]);
    return std::acos(std::min(1.0, std::abs(x.normalized().dot(y.normalized())))) * 180 / std::numbers::pi;
  };
  const nlohmann::json &encoded_regions = a["scene.png"]["regions"], &linear_regions = a["linear.exr"]["regions"];
  ASSERT_EQ(encoded_regions.size(), linear_regions.size());
  for (std::size_t i = 1; i < linear_regions.size(); ++i) {  // the objects (the whole image mixes them)
    const nlohmann::json &light = encoded_regions[i]["linear_light"], &shape = linear_regions[i]["shape"];
    ASSERT_TRUE(light.is_object()) << encoded_regions[i]["name"];
    EXPECT_EQ(light["class"], shape["class"]) << linear_regions[i]["name"];
    EXPECT_LT(angle(light["axes"][0], shape["axes"][0]), 1.0) << linear_regions[i]["name"];
    EXPECT_LT(angle(light["dichromatic_plane"]["normal"], shape["dichromatic_plane"]["normal"]), 1.0) << linear_regions[i]["name"];
  }
  // Files of unknown origin, read as photographs: the dichromatic planes are the known answer, whichever estimate the
  // photographs' rule chooses.
  EXPECT_LT(angle(a["scene.png"]["illuminant"]["dichromatic_planes"]["rgb"], a["linear.exr"]["illuminant"]["dichromatic_planes"]["rgb"]), 1.0);
  EXPECT_LT(angle(a["linear.exr"]["illuminant"]["dichromatic_planes"]["rgb"], std::vector<double>{1, 0.85, 0.6}), 1.0);
  EXPECT_LT(angle(a["scene.png"]["illuminant"]["estimate"]["rgb"], a["linear.exr"]["illuminant"]["estimate"]["rgb"]), 1.0);
}

// --input-transfer declares what the file holds; anything else is refused by name.
TEST(AnalyzeCommand, InputTransferIsDeclaredOrRefused) {
  EXPECT_FALSE(analyzer::parse_input_transfer("auto"));
  EXPECT_TRUE(analyzer::parse_input_transfer("linear")->linear());
  EXPECT_TRUE(analyzer::parse_input_transfer("srgb")->srgb);
  EXPECT_NEAR(analyzer::parse_input_transfer("gamma=2.2")->gamma, 1 / 2.2, 1e-15);
  TempDir dir;
  write_sensor_exr(dir.file("line.exr"), {matte_line(), matte_line(), {}, {}, {}});
  for (const std::string bad : {"gamma=0", "gamma=x", "rec709", ""}) {
    const CommandResult r = run_chromatrace({"analyze", dir.file("line.exr").string(), "-o", dir.file("o").string(),
                                             "--input-transfer", bad});
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.err.find("--input-transfer: \"" + bad + "\" is not auto, linear, srgb or gamma=G"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("o")));
  }
  // A 16-bit file that names no colour space is a picture: sRGB, and said so.
  write_rgb(dir.file("plain.tif"), matte_line(), 16);
  const CommandResult r = run_chromatrace({"analyze", dir.file("plain.tif").string(), "-o", dir.file("t").string(), "--no-plots", "--no-report"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json tif = analysis(dir.file("t"));
  EXPECT_EQ(tif["input"]["curve"]["srgb"], true) << tif["input"].dump();
  const CommandResult declared = run_chromatrace({"analyze", dir.file("plain.tif").string(), "-o", dir.file("d").string(),
                                                  "--input-transfer", "linear", "--no-plots", "--no-report"});
  ASSERT_EQ(declared.exit_code, 0) << declared.err;
  EXPECT_EQ(analysis(dir.file("d"))["input"]["curve"]["source"], "--input-transfer linear");
}

TEST(AnalyzeCommand, LabelAndMaskImagesGiveRegions) {
  TempDir dir;
  const Scene scene = dichromatic_scene(Vec3(1, 0.85, 0.6));
  write_rgb(dir.file("scene.png"), scene.image, 8);
  RgbImage labels = scene.image, mask = scene.image;
  for (std::size_t p = 0; p < scene.ids.size(); ++p)
    for (std::size_t c = 0; c < 3; ++c) {
      labels.rgb[p * 3 + c] = static_cast<float>(scene.ids[p]) / 255.0f;  // stored as the digital number of the id
      mask.rgb[p * 3 + c] = scene.ids[p] == 2 ? 1.0f : 0.0f;
    }
  write_rgb(dir.file("labels.png"), labels, 8);
  write_rgb(dir.file("green.png"), mask, 8);
  const auto out = dir.file("out");
  const CommandResult r = run_chromatrace({"analyze", dir.file("scene.png").string(), "-o", out.string(), "--labels", dir.file("labels.png").string(),
                                           "--mask", dir.file("green.png").string(), "--no-plots", "--no-report", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json a = analysis(out);
  ASSERT_EQ(a["regions"].size(), 6u);  // image, labels 1–4, mask
  EXPECT_EQ(a["regions"][2]["name"], "label 2");
  EXPECT_EQ(a["regions"][5]["name"], "mask green.png");
  EXPECT_EQ(a["regions"][5]["pixels"], a["regions"][2]["pixels"]);
  EXPECT_EQ(a["regions"][5]["shape"]["mean"], a["regions"][2]["shape"]["mean"]);
}

TEST(AnalyzeCommand, DegenerateRegionsSayWhyNoShapeWasMeasured) {
  TempDir dir;
  const RgbImage black = make_image(16, 16, [](double, double) -> Vec3 { return Vec3::Zero(); });
  // NaN on the left half: a region there has no valid pixel (an image with none at all is refused, below).
  const RgbImage nan = make_image(16, 16, [](double u, double) -> Vec3 { return u < 0.5 ? Vec3::Constant(std::nan("")) : Vec3(0.2, 0.3, 0.4); });
  write_sensor_exr(dir.file("black.exr"), {black, black, {}, {}, {}});
  write_sensor_exr(dir.file("nan.exr"), {nan, nan, {}, {}, {}});
  write_sensor_exr(dir.file("line.exr"), {matte_line(), matte_line(), {}, {}, {}});
  struct Case {
    std::string file;
    std::vector<std::string> extra;
    std::string region, reason;
  };
  const Case cases[] = {
      {"black.exr", {}, "image", "all pixels are black"},
      {"nan.exr", {"--rect", "0,0,8,16"}, "rect 0,0 8x16", "every pixel of the region is NaN or infinite"},
      {"line.exr", {"--rect", "500,500,10,10"}, "rect 500,500 10x10", "the region is empty"},
      {"line.exr", {"--rect", "3,4,1,1"}, "rect 3,4 1x1", "1 valid pixel: a shape needs at least 10"},
  };
  for (const Case& c : cases) {
    const auto out = dir.file(c.file + c.region);
    std::vector<std::string> args{"analyze", dir.file(c.file).string(), "-o", out.string(), "-q"};
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    const CommandResult r = run_chromatrace(args);
    ASSERT_EQ(r.exit_code, 0) << c.file << ": " << r.err;
    const nlohmann::json a = analysis(out);
    const nlohmann::json* region = region_named(a, c.region);
    ASSERT_TRUE(region) << c.region;
    EXPECT_EQ((*region)["shape"]["class"], "none");
    EXPECT_NE((*region)["shape"]["reason"].get<std::string>().find(c.reason), std::string::npos) << (*region)["shape"]["reason"];
    EXPECT_TRUE(std::filesystem::is_regular_file(out / "report.html"));
  }
}

// Pixels no light made are left out and said: transparent ones (alpha 0), negative values in a file that is not
// a camera's; an image with no valid pixel at all is refused (exit 2), naming what was wrong with its pixels.
TEST(AnalyzeCommand, TransparentNegativeAndNonFinitePixelsAreLeftOutAndCounted) {
  TempDir dir;
  const int w = 32, h = 16;
  std::vector<float> rgba;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double t = 0.05 + 0.9 * x / (w - 1.0);
      const Vec3 c = t * kBody;
      const bool negative = y == 0 && x < 3;  // a ringing artefact of a resampled HDR image, say
      rgba.insert(rgba.end(), {negative ? -0.01f : float(c[0]), float(c[1]), float(c[2]), y < 4 ? 0.0f : 1.0f});
    }
  OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::FLOAT);
  spec.alpha_channel = 3;
  auto writer = OIIO::ImageOutput::create(dir.file("rgba.exr").string());
  ASSERT_TRUE(writer && writer->open(dir.file("rgba.exr").string(), spec) && writer->write_image(OIIO::TypeDesc::FLOAT, rgba.data()) &&
              writer->close());
  const CommandResult r = run_chromatrace({"analyze", dir.file("rgba.exr").string(), "-o", dir.file("o").string(), "--no-plots", "--no-report", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json a = analysis(dir.file("o"));
  EXPECT_EQ(a["regions"][0]["valid_pixels"], w * (h - 4));  // rows 0–3 transparent, the negative pixels among them
  EXPECT_EQ(a["regions"][0]["shape"]["class"], "linear");  // a line of the body colour: no "clipped at 0"
  const std::string notes = a["notes"].dump();
  EXPECT_NE(notes.find("alpha channel A: 128 fully transparent pixels left out"), std::string::npos) << notes;

  // Negative values outside the transparent rows: left out and counted.
  for (int x = 0; x < 3; ++x) rgba[static_cast<std::size_t>((8 * w + x) * 4)] = -0.01f;
  spec.nchannels = 3;
  spec.alpha_channel = -1;
  spec.channelnames = {"R", "G", "B"};
  std::vector<float> rgb;
  for (std::size_t p = 0; p < rgba.size() / 4; ++p) rgb.insert(rgb.end(), {rgba[p * 4], rgba[p * 4 + 1], rgba[p * 4 + 2]});
  writer = OIIO::ImageOutput::create(dir.file("negative.exr").string());
  ASSERT_TRUE(writer && writer->open(dir.file("negative.exr").string(), spec) && writer->write_image(OIIO::TypeDesc::FLOAT, rgb.data()) &&
              writer->close());
  const CommandResult n = run_chromatrace({"analyze", dir.file("negative.exr").string(), "-o", dir.file("n").string(), "--no-plots", "--no-report", "-q"});
  ASSERT_EQ(n.exit_code, 0) << n.err;
  const nlohmann::json b = analysis(dir.file("n"));
  EXPECT_EQ(b["regions"][0]["valid_pixels"], w * h - 6);
  EXPECT_NE(b["notes"].dump().find("6 pixels with a negative value left out"), std::string::npos) << b["notes"].dump();
  EXPECT_EQ(b["regions"][0]["shape"]["clipping"]["fraction"], 0.0);

  // Nothing valid: exit 2, one line, nothing written.
  const RgbImage all_nan = make_image(8, 8, [](double, double) -> Vec3 { return Vec3::Constant(std::nan("")); });
  write_sensor_exr(dir.file("nan.exr"), {all_nan, all_nan, {}, {}, {}});
  const CommandResult bad = run_chromatrace({"analyze", dir.file("nan.exr").string(), "-o", dir.file("x").string()});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("nan.exr: no valid pixel: 0 transparent, 0 negative, 64 NaN or infinite"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("x")));
}

// The last line lists what was written, and only that: no report.html under --no-report, no plots/ under
// --no-plots.
TEST(AnalyzeCommand, TheLastLineNamesTheFilesWritten) {
  TempDir dir;
  write_sensor_exr(dir.file("line.exr"), {matte_line(), matte_line(), {}, {}, {}});
  const auto last_line = [](const std::string& err) {
    const std::size_t end = err.find_last_not_of('\n'), start = err.rfind('\n', end);
    return err.substr(start == std::string::npos ? 0 : start + 1, end - (start == std::string::npos ? 0 : start + 1) + 1);
  };
  const std::string all = dir.file("all").string(), bare = dir.file("bare").string();
  const CommandResult r = run_chromatrace({"analyze", dir.file("line.exr").string(), "-o", all});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(last_line(r.err), all + ": analysis.json, histograms/, plots/, report.html");
  const CommandResult b = run_chromatrace({"analyze", dir.file("line.exr").string(), "-o", bare, "--no-report", "--no-plots"});
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(last_line(b.err), bare + ": analysis.json, histograms/");
  EXPECT_FALSE(std::filesystem::exists(dir.file("bare") / "report.html"));
  EXPECT_FALSE(std::filesystem::exists(dir.file("bare") / "plots"));
}

// A file of several images (a multi-page TIFF here; an animated GIF's frames alike) is analysed on its first, and
// says so: on the terminal and in analysis.json's notes.
TEST(AnalyzeCommand, AFileOfSeveralImagesSaysWhichWasAnalysed) {
  TempDir dir;
  const std::string file = dir.file("pages.tif").string();
  OIIO::ImageSpec first(32, 16, 3, OIIO::TypeDesc::UINT8), second(8, 8, 3, OIIO::TypeDesc::UINT8);
  const OIIO::ImageSpec specs[] = {first, second};
  std::vector<std::uint8_t> a(32 * 16 * 3), b(8 * 8 * 3, 200);
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = static_cast<std::uint8_t>(40 + (i * 7) % 150);
  auto out = OIIO::ImageOutput::create(file);
  ASSERT_TRUE(out && out->supports("multiimage"));
  ASSERT_TRUE(out->open(file, 2, specs));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, a.data()));
  ASSERT_TRUE(out->open(file, second, OIIO::ImageOutput::AppendSubimage));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, b.data()));
  ASSERT_TRUE(out->close());
  const CommandResult r = run_chromatrace({"analyze", file, "-o", dir.file("o").string(), "--no-plots", "--no-report"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string note = "the file holds 2 images (tiff); the first, 32 × 16, was analysed";
  EXPECT_NE(r.err.find(file + ": note: " + note), std::string::npos) << r.err;
  const nlohmann::json j = analysis(dir.file("o"));
  EXPECT_EQ(j["image"]["width"], 32);
  EXPECT_NE(std::find(j["notes"].begin(), j["notes"].end(), note), j["notes"].end()) << j["notes"].dump();
  // One image: no such note.
  OIIO::ImageSpec single(32, 16, 3, OIIO::TypeDesc::UINT8);
  auto one = OIIO::ImageOutput::create(dir.file("one.tif").string());
  ASSERT_TRUE(one && one->open(dir.file("one.tif").string(), single) && one->write_image(OIIO::TypeDesc::UINT8, a.data()) && one->close());
  const CommandResult s = run_chromatrace({"analyze", dir.file("one.tif").string(), "-o", dir.file("p").string(), "--no-plots", "--no-report"});
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_EQ(s.err.find("images ("), std::string::npos) << s.err;
}

TEST(AnalyzeCommand, BadInputIsOneLineAndExitTwo) {
  TempDir dir;
  std::ofstream(dir.file("junk.png")) << "not an image";
  write_sensor_exr(dir.file("line.exr"), {matte_line(), matte_line(), {}, {}, {}});
  const std::string line = dir.file("line.exr").string(), out = dir.file("out").string();
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"analyze", dir.file("missing.png").string(), "-o", out}, "missing.png: cannot open file"},
      {{"analyze", dir.file("junk.png").string(), "-o", out}, "junk.png: cannot read image"},
      {{"analyze", line, "-o", dir.file("no/such/dir").string()}, "does not exist"},
      {{"analyze", line, "-o", out, "--bins", "1"}, "--bins: must be in [2, 1024]"},
      {{"analyze", line, "-o", out, "--rect", "1,2,3"}, "--rect: expected x,y,width,height"},
      {{"analyze", line, "-o", out, "--layer", "glossy_direct"}, "--layer: no layer \"glossy_direct\""},
      {{"analyze", line, "-o", out, "--labels", "object_id"}, "no object_id channel"},
      {{"analyze", line, "-o", out, "--mask", dir.file("junk.png").string()}, "junk.png: cannot read image"},
      {{"analyze", line, "-o", out, "--illuminant", "1,x,2"}, "--illuminant: expected R,G,B"},
  };
  for (const auto& [args, message] : cases) {
    const CommandResult r = run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 2) << args[1];
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace ct::test
