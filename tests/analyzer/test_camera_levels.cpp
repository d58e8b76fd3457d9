// SPDX-License-Identifier: Apache-2.0
// What the camera did, as the analyzer reads it (docs/analyze.md, "Input"): the black level subtracted before
// any fit through black, clipping levels from the white level, wholly clipped regions, analysis.json's
// "input", and the display layer as the report's image.
#include <cmath>
#include <numbers>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "analyzer/analysis.h"
#include "analyzer/analysis_json.h"
#include "analyzer/clipping.h"
#include "analyzer/cluster_shape.h"
#include "analyzer/report.h"
#include "core/error.h"
#include "core/file_io.h"
#include "tests/analyzer/synthetic.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

namespace fs = std::filesystem;
using namespace ct::analyzer;

// Writes R, G, B (plus object_id, display.R/G/B when given) as a float EXR with numeric attributes, as the
// sensor simulator does.
void write_camera_exr(const fs::path& file, const RgbImage& image, const std::vector<std::int32_t>& ids,
                      const std::map<std::string, double>& numbers, const RgbImage* display = nullptr,
                      const std::string& objects = R"({"1": "shaded", "2": "blown"})") {
  std::vector<std::string> names = {"R", "G", "B"};
  if (!ids.empty()) names.push_back("object_id");
  if (display) names.insert(names.end(), {"display.R", "display.G", "display.B"});
  OIIO::ImageSpec spec(image.width, image.height, static_cast<int>(names.size()), OIIO::TypeDesc::FLOAT);
  spec.channelnames = names;
  for (const auto& [key, value] : numbers) spec.attribute(key, OIIO::TypeDesc::DOUBLE, &value);
  if (!ids.empty()) spec.attribute("chromatrace.objects", objects);
  std::vector<float> pixels;
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    for (std::size_t c = 0; c < 3; ++c) pixels.push_back(image.rgb[p * 3 + c]);
    if (!ids.empty()) pixels.push_back(static_cast<float>(ids[p]));
    if (display)
      for (std::size_t c = 0; c < 3; ++c) pixels.push_back(display->rgb[p * 3 + c]);
  }
  auto out = OIIO::ImageOutput::create(file.string());
  ASSERT_TRUE(out && out->open(file.string(), spec)) << OIIO::geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  ASSERT_TRUE(out->close());
}

const RegionAnalysis* region_named(const ImageAnalysis& a, const std::string& name) {
  for (const RegionAnalysis& r : a.results)
    if (r.name == name) return &r;
  return nullptr;
}

ImageAnalysis analyse(const AnalysisImage& input) {
  const RgbImage& layer = select_layer(input, "final");
  return analyse_image(input, "final", select_regions(input, layer, {}), AnalyzeOptions{}, std::nullopt, false);
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(std::abs(a.normalized().dot(b.normalized())), 0.0, 1.0)) * 180.0 / std::numbers::pi;
}

// A 14-bit raw image: black level 2048, white level 16383. The left half (object 1) a matte line
// black + m·(6000, 4000, 2500) with m from 0.05 to 1; the right half (object 2) blown out, every pixel at the
// white level in all three channels.
struct RawScene {
  RgbImage image;
  std::vector<std::int32_t> ids;
};
RawScene raw_scene() {
  RawScene s;
  s.image = make_image(40, 20, [](double u, double v) -> Vec3 {
    if (u > 0.5) return Vec3::Constant(16383);
    const double m = 0.05 + 0.95 * (0.5 * u / 0.5 + 0.5 * v);
    return Vec3::Constant(2048) + m * Vec3(6000, 4000, 2500);
  });
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 40; ++x) s.ids.push_back(x / 39.0 > 0.5 ? 2 : 1);
  return s;
}

const std::map<std::string, double> kCanon = {{"chromatrace.black_level", 2048},
                                              {"chromatrace.white_level", 16383},
                                              {"chromatrace.dark_signal", 0.25},
                                              {"chromatrace.read_noise", 0},
                                              {"chromatrace.bits", 14},
                                              {"chromatrace.noise", 0},
                                              {"chromatrace.adc", 1}};

// (a) A region at the white level everywhere is wholly clipped — in all three channels, so no other channel
// "keeps changing" on its faces, which once kept them from counting.
TEST(CameraLevels, ARegionAtTheWhiteLevelIsWhollyClipped) {
  TempDir dir;
  const RawScene s = raw_scene();
  write_camera_exr(dir.file("raw.exr"), s.image, s.ids, kCanon);
  const AnalysisImage input = read_analysis_image(dir.file("raw.exr"));
  EXPECT_EQ(input.encoding.metadata, "attributes");
  ASSERT_TRUE(input.encoding.black_level && input.encoding.white_level);
  EXPECT_EQ(*input.encoding.black_level, 2048);
  EXPECT_TRUE(input.encoding.black_subtracted);
  EXPECT_EQ(input.image.rgb[0], s.image.rgb[0] - 2048.0f);  // R of pixel (0, 0), black taken off
  const ImageAnalysis a = analyse(input);
  for (const double level : a.context.high_levels) EXPECT_EQ(level, 16383.0 - 2048.0);  // not the channel maxima
  const RegionAnalysis* blown = region_named(a, "object 2 (blown)");
  ASSERT_TRUE(blown);
  EXPECT_EQ(blown->shape.clipping.fraction, 1.0);
  EXPECT_EQ(blown->shape.shape, ShapeClass::Clipped);
  EXPECT_EQ(blown->shape.clipping.faces.size(), 3u);
  const RegionAnalysis* shaded = region_named(a, "object 1 (shaded)");
  ASSERT_TRUE(shaded);
  EXPECT_EQ(shaded->shape.clipping.fraction, 0.0);
  EXPECT_EQ(shaded->shape.shape, ShapeClass::Linear);
  // With the black level off, the line passes through black: its direction is (6000, 4000, 2500).
  ASSERT_TRUE(shaded->shape.line);
  EXPECT_LT(angle_deg(shaded->shape.line->direction, Vec3(6000, 4000, 2500)), 0.01);
  EXPECT_LT(shaded->shape.line->point.cross(shaded->shape.line->direction).norm(), 1.0);  // ≤ 1 DN from black

  // analysis.json says so: the black level, that it was subtracted, the shift it and the dark current cause,
  // the white level and the clipping level.
  const nlohmann::json j = analysis_to_json(a);
  const nlohmann::json& in = j["input"];
  EXPECT_EQ(in["black_level"], nlohmann::json({2048.0, 2048.0, 2048.0}));
  EXPECT_EQ(in["subtracted"], true);
  EXPECT_EQ(in["shift"], nlohmann::json({2048.25, 2048.25, 2048.25}));
  EXPECT_EQ(in["remaining_shift"], nlohmann::json({0.25, 0.25, 0.25}));
  EXPECT_DOUBLE_EQ(in["shift_length"].get<double>(), 2048.25 * std::sqrt(3.0));
  EXPECT_EQ(in["white_level"], 16383.0);
  EXPECT_EQ(in["clipping_level"], 16383.0 - 2048.0);
  EXPECT_EQ(in["bits"], 14);
  EXPECT_EQ(j["clipping_levels_source"], "white level");
  // The wholly clipped region's shape statistics were never measured: null, not zero; its unclipped part has
  // no pixel, so no class.
  const nlohmann::json& blown_shape = j["regions"][static_cast<std::size_t>(blown - a.results.data())]["shape"];
  EXPECT_EQ(blown_shape["class"], "clipped");
  for (const char* key : {"noise_sigma", "linearity", "planarity", "scattering", "significant_axes"})
    EXPECT_TRUE(blown_shape[key].is_null()) << key << ": " << blown_shape[key];
  EXPECT_EQ(blown_shape["unclipped_class"], "none");
}

// The rule itself: known levels count every sample on them; estimated ones (channel maxima) still need the
// other channels to change, so a uniform patch is a point, not a clipped cluster.
TEST(CameraLevels, KnownLevelsCountEverySampleOnThem) {
  const std::vector<float> flat(300, 5.0f);
  EXPECT_EQ(find_clipping(flat, {5, 5, 5}, ClippingRules{true, {0, 0, 0}}).fraction, 1.0);
  EXPECT_EQ(find_clipping(flat, {5, 5, 5}, ClippingRules{false, {0, 0, 0}}).fraction, 0.0);
  // The shape analysis applies the rules its context carries.
  ShapeContext known;
  known.high_levels = {5, 5, 5};
  known.clipping = ClippingRules{true, {0, 0, 0}};
  EXPECT_EQ(analyse_shape(flat, known).clipping.fraction, 1.0);
  ShapeContext estimated = known;
  estimated.clipping.known_high = false;
  EXPECT_EQ(analyse_shape(flat, estimated).clipping.fraction, 0.0);
  // Below black after subtraction is noise, not clipping: the low face is the ADC's code 0, at −black.
  std::vector<float> dark;
  for (int i = 0; i < 100; ++i) dark.insert(dark.end(), {float(i % 7) - 3.0f, 100.0f + 20.0f * i, 50.0f + 10.0f * i});
  EXPECT_GT(find_clipping(dark, {1e4, 1e4, 1e4}, ClippingRules{true, {0, 0, 0}}).fraction, 0.3);
  EXPECT_EQ(find_clipping(dark, {1e4, 1e4, 1e4}, ClippingRules{true, {-2048, -2048, -2048}}).fraction, 0.0);
}

// A lower face is judged against the other channels' own values on it, not the image's levels: in an HDR image
// whose flame sets the levels at 500, a dim region whose green is 0 in 30 % of its pixels while red runs from 0.001
// to 0.05 lies on green's lower face; a uniform patch whose green is 0 is a colour, not a face.
TEST(CameraLevels, ALowerFaceIsJudgedOnItsOwnValues) {
  std::vector<float> dim;
  for (int i = 0; i < 100; ++i) dim.insert(dim.end(), {0.001f + 0.0005f * float(i), i % 10 < 3 ? 0.0f : 0.0002f * float(i), 0.0f + 0.0001f * float(i)});
  const Clipping c = find_clipping(dim, {500, 500, 500}, ClippingRules{false, {0, 0, 0}});
  ASSERT_EQ(c.faces.size(), 1u);
  EXPECT_EQ(c.faces.front().channel, 1);
  EXPECT_FALSE(c.faces.front().high);
  EXPECT_NEAR(c.fraction, 0.3, 1e-12);
  std::vector<float> uniform;
  for (int i = 0; i < 100; ++i) uniform.insert(uniform.end(), {0.03f, 0.0f, 0.01f});
  EXPECT_EQ(find_clipping(uniform, {500, 500, 500}, ClippingRules{false, {0, 0, 0}}).fraction, 0.0);
}

// An integer file's full scale is a known limit too: a 16-bit patch at 65535 is wholly clipped.
TEST(CameraLevels, AnIntegerFilesFullScaleIsKnown) {
  TempDir dir;
  write_rgb(dir.file("white.tif"), make_image(16, 16, [](double, double) { return Vec3(1, 1, 1); }), 16);
  const AnalysisImage input = read_analysis_image(dir.file("white.tif"));
  EXPECT_FALSE(input.encoding.black_level);
  const ImageAnalysis a = analyse(input);
  EXPECT_EQ(a.results[0].shape.clipping.fraction, 1.0);
  EXPECT_EQ(a.results[0].shape.shape, ShapeClass::Clipped);
}

// (b) A raw 14-bit image with black level 2048 is analysed as the same picture taken with black level 0: both
// through the real renderer and sensor simulator (noise on, the same seed), so they differ by the black level,
// and by the clamping at code 0 and at the top code that a black level changes. Same classes, and every
// direction (principal axes, line, body line, dichromatic plane) within 0.5°.
TEST(CameraLevels, RawWithBlackLevelIsAnalysedAsWithout) {
  TempDir dir;
  const fs::path scene = fs::path(CHROMATRACE_SOURCE_DIR) / "scenes" / "paper" / "box.json";
  const auto render = run_chromatrace({"render", scene.string(), "-o", dir.file("box.exr").string(), "--resolution",
                                       "64x64", "--spp", "32", "--quiet"});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const std::vector<std::string> sensor = {"sensor", dir.file("box.exr").string(), "--preset", "canon_eos_5d_mkiii",
                                           "--exposure-s", "auto", "--quiet", "-o"};
  auto with = sensor, without = sensor;
  with.push_back(dir.file("black2048.exr").string());
  without.insert(without.end(), {dir.file("black0.tif").string(), "--set", "adc.black_level_dn=0"});
  ASSERT_EQ(run_chromatrace(with).exit_code, 0);
  ASSERT_EQ(run_chromatrace(without).exit_code, 0);

  const AnalysisImage raw = read_analysis_image(dir.file("black2048.exr"));
  const AnalysisImage zero = read_analysis_image(dir.file("black0.tif"));  // a TIFF: metadata in ImageDescription
  ASSERT_EQ(raw.encoding.black_level.value_or(-1), 2048.0);
  ASSERT_EQ(zero.encoding.black_level.value_or(-1), 0.0);
  EXPECT_EQ(zero.encoding.metadata, "ImageDescription");
  AnalysisImage zero_with_ids = zero;  // the TIFF holds R, G, B only: the regions come from the EXR's object ids
  zero_with_ids.object_ids = raw.object_ids;
  zero_with_ids.object_names = raw.object_names;
  const ImageAnalysis a = analyse(raw), b = analyse(zero_with_ids);
  ASSERT_EQ(a.results.size(), 9u);  // the image and 8 objects
  ASSERT_EQ(b.results.size(), a.results.size());
  const auto directions = [](const ClusterShape& s) {
    std::vector<std::pair<std::string, Vec3>> d;
    const ClusterShape& own = s.unclipped.empty() ? s : s.unclipped.front();
    if (own.samples >= 10) d.emplace_back("axis 1", own.moments.axes.col(0));
    if (own.line) d.emplace_back("line", own.line->direction);
    // A volume has no body line: the robust line found among samples spread in all three directions turns with
    // one sample more or less inside its tolerance (the image's noise, which clamping at code 0 changes a little).
    if (own.body_only && own.shape != ShapeClass::Volume) d.emplace_back("body line", own.body_only->line.direction);
    if (own.black_plane) d.emplace_back("dichromatic plane", own.black_plane->normal);
    return d;
  };
  std::size_t compared = 0;
  for (std::size_t i = 0; i < a.results.size(); ++i) {
    const ClusterShape &sa = a.results[i].shape, &sb = b.results[i].shape;
    EXPECT_EQ(sa.shape, sb.shape) << a.results[i].name;
    const auto da = directions(sa), db = directions(sb);
    ASSERT_EQ(da.size(), db.size()) << a.results[i].name;
    for (std::size_t k = 0; k < da.size(); ++k, ++compared)
      EXPECT_LT(angle_deg(da[k].second, db[k].second), 0.5) << a.results[i].name << ": " << da[k].first;
  }
  EXPECT_GT(compared, 15u) << compared;  // 9 regions: each axis 1 and dichromatic plane, and the lines their classes use

  // Without the metadata the black level stays in: fits through black tilt by far more than 0.5°.
  AnalysisImage unaware = raw;
  for (float& v : unaware.image.rgb) v += 2048.0f;
  unaware.encoding = ImageEncoding{};
  const ImageAnalysis c = analyse(unaware);
  double worst = 0;
  for (std::size_t i = 0; i < c.results.size(); ++i)
    if (c.results[i].shape.black_plane && b.results[i].shape.black_plane)
      worst = std::max(worst, angle_deg(c.results[i].shape.black_plane->normal, b.results[i].shape.black_plane->normal));
  EXPECT_GT(worst, 5.0);
}

// The report shows the display layer, as stored, when the file has one.
TEST(CameraLevels, ReportShowsTheDisplayLayer) {
  TempDir dir;
  const RawScene s = raw_scene();
  const RgbImage display = make_image(40, 20, [](double u, double) { return u < 0.5 ? Vec3(0.8, 0.2, 0.1) : Vec3(1, 1, 1); });
  write_camera_exr(dir.file("raw.exr"), s.image, s.ids, kCanon, &display);
  const AnalysisImage input = read_analysis_image(dir.file("raw.exr"));
  ASSERT_TRUE(input.display);
  EXPECT_TRUE(input.components.empty());  // display is no light-path component
  const std::string html = report_html(input, analyse(input), 100);
  const std::string marker = "data:image/png;base64,";
  const std::size_t at = html.find(marker) + marker.size();
  const std::string b64 = html.substr(at, html.find('"', at) - at);
  std::vector<std::uint8_t> bytes;
  std::uint32_t buffer = 0;
  int bits = 0;
  for (const char ch : b64) {
    const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char* pos = std::strchr(table, ch);
    if (ch == '=' || pos == nullptr) break;
    buffer = (buffer << 6) | static_cast<std::uint32_t>(pos - table);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes.push_back(static_cast<std::uint8_t>((buffer >> bits) & 0xff));
    }
  }
  const cv::Mat png = cv::imdecode(bytes, cv::IMREAD_COLOR);
  ASSERT_EQ(png.cols, 40);
  const cv::Vec3b left = png.at<cv::Vec3b>(10, 5);  // BGR, 8-bit codes of the stored values
  EXPECT_EQ(left[2], 204);                          // round(255 · 0.8)
  EXPECT_EQ(left[1], 51);
  EXPECT_EQ(left[0], 26);
}

// The response curve's inverse, against its definition: stored = full_scale · k·n^γ, odd-symmetric.
TEST(ToneCurve, DecodeInvertsTheCurve) {
  const ToneCurve power{0.45, 1.2, false};
  for (const double n : {0.0, 0.01, 0.18, 0.5, 1.0}) {
    EXPECT_NEAR(power.decode(1.2 * std::pow(n, 0.45), 1.0), n, 1e-12);
    EXPECT_NEAR(power.decode(255 * 1.2 * std::pow(n, 0.45), 255.0), 255 * n, 1e-9);
    EXPECT_NEAR(power.decode(-1.2 * std::pow(n, 0.45), 1.0), -n, 1e-12);
  }
  const ToneCurve srgb{1, 1, true};
  EXPECT_NEAR(srgb.decode(0.5, 1.0), 0.214041140, 1e-8);  // IEC 61966-2-1: ((0.5 + 0.055) / 1.055)^2.4
  EXPECT_NEAR(srgb.decode(0.04045 * 255, 255.0), 255 * 0.04045 / 12.92, 1e-9);  // the linear toe's end
  EXPECT_TRUE(ToneCurve{}.linear());
  EXPECT_FALSE(power.linear());
}

// Three objects, encoded with I' = I^0.45 and the curve named in the file: a dichromatic L (its plane passes
// through black, but a power curve keeps only lines through black straight), a matte line offset from black
// (an ambient term), and a matte line through black. The curve bends the first two — gamma, their class in
// linear light beside it — and leaves the third a line (the paper's remark).
TEST(ToneCurve, AKnownCurveBendsWhatDoesNotPassThroughBlack) {
  TempDir dir;
  const double gamma = 0.45;
  const Vec3 ambient = 0.08 * Vec3(0.3, 0.5, 0.9);
  const RgbImage light = make_image(96, 64, [&](double u, double v) -> Vec3 {
    const double t = 0.05 + 0.95 * v;
    if (u < 1 / 3.0) return t < 0.85 ? Vec3(0.8 * t / 0.85 * kBody) : Vec3(0.8 * kBody + 0.6 * (t - 0.85) / 0.15 * kIlluminant);
    if (u < 2 / 3.0) return ambient + 0.8 * t * kBody;
    return 0.8 * t * kBody;
  });
  RgbImage stored = light;
  for (float& x : stored.rgb) x = static_cast<float>(std::pow(x, gamma));
  std::vector<std::int32_t> ids;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 96; ++x) ids.push_back(1 + 3 * x / 96);
  const std::string names = R"({"1": "dichromatic", "2": "offset", "3": "through_black"})";
  write_camera_exr(dir.file("encoded.exr"), stored, ids,
                   {{"chromatrace.black_level", 0}, {"chromatrace.curve_gamma", gamma}, {"chromatrace.curve_k", 1}},
                   nullptr, names);
  const AnalysisImage input = read_analysis_image(dir.file("encoded.exr"));
  ASSERT_TRUE(input.encoding.curve);
  EXPECT_EQ(input.encoding.curve->gamma, gamma);
  const ImageAnalysis a = analyse(input);
  const auto classes = [&](const std::string& name) {
    const RegionAnalysis* r = region_named(a, name);
    return r ? std::pair(r->shape.shape, r->linear_light ? r->linear_light->shape : ShapeClass::None)
             : std::pair(ShapeClass::None, ShapeClass::None);
  };
  EXPECT_EQ(classes("object 1 (dichromatic)"), std::pair(ShapeClass::Gamma, ShapeClass::L));
  EXPECT_EQ(classes("object 2 (offset)"), std::pair(ShapeClass::Gamma, ShapeClass::Linear));
  EXPECT_EQ(classes("object 3 (through_black)"), std::pair(ShapeClass::Linear, ShapeClass::Linear));
  // The illuminant is estimated in linear light: from the L's highlight, the true illuminant colour.
  EXPECT_LT(angle_deg(a.illuminant.best().rgb, kIlluminant), 1.0) << a.illuminant.best().method;
  const nlohmann::json j = analysis_to_json(a);
  EXPECT_EQ(j["input"]["curve"]["gamma"], gamma);
  EXPECT_EQ(j["regions"][1]["linear_light"]["class"], "L");

  // The same numbers with no curve named are taken as light: no region is judged in linear light.
  write_camera_exr(dir.file("unnamed.exr"), stored, ids, {{"chromatrace.black_level", 0}}, nullptr, names);
  const ImageAnalysis as_light = analyse(read_analysis_image(dir.file("unnamed.exr")));
  for (const RegionAnalysis& r : as_light.results) EXPECT_FALSE(r.linear_light) << r.name;
}

// A curve that cannot be undone is refused by name.
TEST(ToneCurve, ANonPositiveGammaIsRefused) {
  TempDir dir;
  const RgbImage image = make_image(8, 8, [](double u, double v) { return Vec3(u, v, 0.5); });
  write_camera_exr(dir.file("bad.exr"), image, {}, {{"chromatrace.curve_gamma", -0.45}});
  try {
    read_analysis_image(dir.file("bad.exr"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.exr: chromatrace.curve_gamma"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ct::test
