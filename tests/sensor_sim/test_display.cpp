// SPDX-License-Identifier: Apache-2.0
// Automatic exposure keyed on the surfaces, the camera's numbers in the output's metadata, and the display
// layer (docs/sensor.md): known answers on synthetic spectral images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/cie.h"
#include "core/colour.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/rgb_to_spectrum.h"
#include "core/spectral_exr.h"
#include "sensor_sim/display.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

// What each pixel of a synthetic scene is: an emitter seen directly (its radiance in the `emission` layer), a
// surface (in `diffuse_direct`), and its object id.
struct Pixel {
  std::vector<double> radiance;  // band values
  bool emitter = false;
  std::int32_t id = 0;
};

// Writes the scene as a spectral EXR: the total, and with `components` the emission and diffuse_direct layers
// (summing to it) and object ids named by `names`.
void write_scene(const fs::path& path, const Bands& bands, int width, int height,
                 const std::function<Pixel(int x, int y)>& pixel, bool components,
                 const std::map<std::int32_t, std::string>& names = {},
                 const std::map<std::string, std::string>& attributes = {}) {
  SpectralExrLayout layout;
  layout.width = width;
  layout.height = height;
  layout.bands = bands;
  layout.attributes = attributes;
  if (components) layout.components = {"emission", "diffuse_direct"};
  layout.object_ids = !names.empty();
  layout.object_names = names;
  std::vector<float> total, emission, diffuse;
  std::vector<std::int32_t> ids;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Pixel p = pixel(x, y);
      for (const double v : p.radiance) {
        total.push_back(static_cast<float>(v));
        emission.push_back(p.emitter ? static_cast<float>(v) : 0.0f);
        diffuse.push_back(p.emitter ? 0.0f : static_cast<float>(v));
      }
      ids.push_back(p.id);
    }
  SpectralExrWriter writer(path, layout);
  SpectralRowBlock block;
  block.rows = height;
  block.total = total;
  if (components) block.components = {emission, diffuse};
  if (layout.object_ids) block.object_ids = ids;
  writer.write_rows(block);
  writer.finish();
}

std::vector<double> scaled(std::vector<double> v, double k) {
  for (double& x : v) x *= k;
  return v;
}

std::vector<double> lit(const std::vector<double>& light, const std::vector<double>& reflectance, double k) {
  std::vector<double> v(light.size());
  for (std::size_t b = 0; b < v.size(); ++b) v[b] = light[b] * reflectance[b] * k;
  return v;
}

double max_of(const test::RgbLayer& layer, int x, int y) {
  return std::max({layer.at(x, y, 0), layer.at(x, y, 1), layer.at(x, y, 2)});
}

// ---- Automatic exposure -------------------------------------------------------------------------------------

// A 20 × 10 image: 4 emitter pixels (2 %, more than the 1 % above the 99th percentile) of radiance `emitter`
// times a flat spectrum, and 196 surface pixels whose flat radiance ramps from 1/196 to 1 W·m⁻²·sr⁻¹·nm⁻¹.
// With the emitters left out, the 99th percentile (nearest rank below: index ⌊0.99·195⌋ = 193) is the surface
// of radiance 194/196, whatever the emitters' brightness.
constexpr int kW = 20, kH = 10;
bool is_emitter(int x, int y) { return y == 0 && x < 4; }
int surface_index(int x, int y) { return y * kW + x - 4; }  // 0 … 195 over the surfaces

void write_exposure_scene(const fs::path& path, double emitter, bool components, bool named_light) {
  const Bands bands = Bands::uniform(400, 700, 30);
  std::map<std::int32_t, std::string> names;
  std::map<std::string, std::string> attributes;
  if (named_light) {
    names = {{1, "wall"}, {2, "lamp"}};
    attributes["chromatrace.scene"] = R"({"lights": [{"name": "lamp"}], "objects": [{"name": "wall"}]})";
  }
  write_scene(
      path, bands, kW, kH,
      [&](int x, int y) {
        Pixel p;
        p.emitter = is_emitter(x, y);
        p.id = p.emitter ? 2 : 1;
        const double value = p.emitter ? emitter : (surface_index(x, y) + 1) / 196.0;
        p.radiance.assign(bands.size(), value);
        return p;
      },
      components, names, attributes);
}

// Full well 10 000 e⁻ and a 12-bit ADC of gain 0.4 DN/e⁻ and black level 64: saturation is the full well
// (K·10 000 + 64 = 4064 < 4095), the white level 4064 DN. No noise: every number is exact.
Json exposure_config(double level) {
  return {{"exposure", {{"time_s", "auto"}, {"auto_level", level}}},
          {"full_well", {{"enabled", true}, {"electrons", 10000}}},
          {"adc", {{"enabled", true}, {"gain_dn_per_e", 0.4}, {"black_level_dn", 64}, {"bits", 12}}}};
}

TEST(AutoExposure, IsKeyedOnTheSurfacesNotOnEmittersInView) {
  test::TempDir dir;
  const int px = (193 + 4) % kW, py = (193 + 4) / kW;  // the surface of index 193
  ASSERT_EQ(surface_index(px, py), 193);
  std::vector<double> times;
  for (const double emitter : {1e2, 1e5}) {
    const fs::path in = dir.file(fmt::format("scene{}.exr", emitter)), out = dir.file(fmt::format("out{}.exr", emitter));
    write_exposure_scene(in, emitter, true, false);
    const auto report = test::run_sensor(in, out, test::config_of(exposure_config(0.9)));
    times.push_back(report.exposure_s);
    // The surface percentile at 0.9 of saturation (float rounding of the stored signal: 2⁻²⁴ relative).
    const test::RgbLayer linear = test::read_rgb(out, "linear");
    EXPECT_NEAR(max_of(linear, px, py), 0.9 * 10000.0, 9000.0 * 1e-6) << emitter;
    // The emitters clip: they read the white level, K·full well + black.
    const test::RgbLayer raw = test::read_rgb(out);
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(raw.at(x, 0, c), 4064.0f) << emitter;
    EXPECT_TRUE(std::any_of(report.notes.begin(), report.notes.end(), [](const std::string& n) {
      return n.find("(4 emitter pixels left out) at 0.9 of saturation") != std::string::npos;
    }));
  }
  EXPECT_NEAR(times[1] / times[0], 1.0, 1e-12);  // whatever the emitters' brightness

  // Left in, the brighter emitter sets the time: the percentile pixel is one of them, at 0.9 of saturation.
  Json all = exposure_config(0.9);
  all["exposure"]["auto_exclude_emitters"] = false;
  test::run_sensor(dir.file("scene100000.exr"), dir.file("all.exr"), test::config_of(all));
  const test::RgbLayer linear = test::read_rgb(dir.file("all.exr"), "linear");
  EXPECT_NEAR(max_of(linear, 0, 0), 9000.0, 9000.0 * 1e-6);
  EXPECT_NEAR(max_of(linear, px, py), 9000.0 * (194.0 / 196.0) / 1e5, 1e-6);
}

// Without an emission layer, an object id that the scene's lights name marks the emitters.
TEST(AutoExposure, ObjectIdsOfTheScenesLightsAreEmitters) {
  test::TempDir dir;
  write_exposure_scene(dir.file("named.exr"), 1e5, false, true);
  write_exposure_scene(dir.file("layers.exr"), 1e5, true, false);
  const auto named = test::run_sensor(dir.file("named.exr"), dir.file("a.exr"), test::config_of(exposure_config(0.5)));
  const auto layers = test::run_sensor(dir.file("layers.exr"), dir.file("b.exr"), test::config_of(exposure_config(0.5)));
  EXPECT_NEAR(named.exposure_s / layers.exposure_s, 1.0, 1e-12);
  EXPECT_NEAR(max_of(test::read_rgb(dir.file("a.exr"), "linear"), 17, 9), 5000.0, 5000.0 * 1e-6);
}

// ---- The camera's numbers in the metadata -------------------------------------------------------------------

TEST(CameraMetadata, ExrAndTiffCarryBlackWhiteBitsNoiseAndAdc) {
  test::TempDir dir;
  write_exposure_scene(dir.file("in.exr"), 1e3, true, false);
  Json patch = {{"preset", "canon_eos_5d_mkiii"}, {"exposure", {{"time_s", "auto"}}}};
  test::run_sensor(dir.file("in.exr"), dir.file("raw.exr"), test::config_of(patch));
  test::run_sensor(dir.file("in.exr"), dir.file("raw.tif"), test::config_of(patch));
  // White level: min(ADC top code 16383, black 2048 + K·full well = 2048 + 0.2118·67684 = 16383.47).
  for (const char* file : {"raw.exr", "raw.tif"}) {
    auto in = OIIO::ImageInput::open(dir.file(file).string());
    ASSERT_TRUE(in) << file;
    const OIIO::ImageSpec& spec = in->spec();
    const nlohmann::json description =
        nlohmann::json::parse(spec.get_string_attribute("ImageDescription", "{}"), nullptr, false);
    const auto number = [&](const char* key) {
      if (const OIIO::ParamValue* p = spec.find_attribute(key)) {
        if (p->type() == OIIO::TypeDesc::DOUBLE) return *static_cast<const double*>(p->data());
        if (p->type() == OIIO::TypeDesc::INT) return static_cast<double>(p->get_int());
        return static_cast<double>(p->get_float());
      }
      return description.contains(key) ? description[key].get<double>() : std::nan("");
    };
    EXPECT_EQ(number("chromatrace.black_level"), 2048.0) << file;
    EXPECT_EQ(number("chromatrace.white_level"), 16383.0) << file;
    EXPECT_EQ(number("chromatrace.bits"), 14.0) << file;
    EXPECT_EQ(number("chromatrace.noise"), 1.0) << file;
    EXPECT_EQ(number("chromatrace.adc"), 1.0) << file;
    EXPECT_NEAR(number("chromatrace.read_noise"), 0.2118 * 33.0, 1e-12) << file;
  }
  // A rendered 8-bit PNG stores codes: its levels are in codes too, black 0 and white 255.
  patch["rendering"] = {{"enabled", true}, {"curve", "srgb"}};
  test::run_sensor(dir.file("in.exr"), dir.file("photo.png"), test::config_of(patch));
  auto png = OIIO::ImageInput::open(dir.file("photo.png").string());
  ASSERT_TRUE(png);
  const nlohmann::json description = nlohmann::json::parse(png->spec().get_string_attribute("ImageDescription"));
  EXPECT_EQ(description["chromatrace.black_level"], 0.0);
  EXPECT_EQ(description["chromatrace.white_level"], 255.0);
}

// ---- The display layer --------------------------------------------------------------------------------------

// A 10 × 10 image: rows 0–4 a perfect white, rows 5–9 the Cornell box's red wall, both lit by `light` (band
// values) at 1/π of the light's scale; with `emitter`, pixels (0, 9) and (1, 9) see the light itself,
// 1000 times brighter. 98 or 100 surface pixels, half or more white: the 99th percentile is the white.
struct DisplayScene {
  Bands bands;
  std::vector<double> light;
};

void write_display_scene(const fs::path& path, const DisplayScene& s, bool emitter) {
  const PiecewiseLinearSpectrum red =
      read_csv(fs::path(CHROMATRACE_SOURCE_DIR) / "scenes" / "spectra" / "cornell_box.csv").spectrum("red");
  const std::vector<double> white(s.bands.size(), 1.0), wall = band_averages(red, s.bands);
  write_scene(
      path, s.bands, 10, 10,
      [&](int x, int y) {
        Pixel p;
        p.emitter = emitter && y == 9 && x < 2;
        p.radiance = p.emitter ? scaled(s.light, 1e3) : lit(s.light, y < 5 ? white : wall, 1.0 / std::numbers::pi);
        return p;
      },
      emitter);
}

DisplayScene lit_by(const std::string& illuminant, const Bands& bands) {
  return {bands, scaled(band_averages(cie::illuminant(illuminant), bands), 0.01)};
}

// The white comes out neutral and at the display level; the red wall red. Bounds: the white's camera signal is
// its illuminant's response c_w times a number, stored as float (relative error 2⁻²⁴ per channel); the white
// balance and the white-preserving matrix map c_w to (1, 1, 1) exactly up to double rounding, so the linear
// display channels agree within a few 1e-8 relative, and after the sRGB curve (slope 0.51 at 0.9) within 1e-7.
// The layer is stored as half: values in [0.5, 1) are 2⁻¹¹ apart, so each channel lies within 2⁻¹² (rounding)
// + 1e-6 of the sRGB encoding of 0.9, and the channels within one step 2⁻¹¹ of each other.
constexpr double kHalfStep = 1.0 / 2048.0;  // spacing of half floats in [0.5, 1)
void expect_white_and_red(const fs::path& out, const std::string& what) {
  const test::RgbLayer d = test::read_rgb(out, "display");
  const double encoded_level = srgb_encode(0.9);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(d.at(3, 2, c), encoded_level, kHalfStep / 2 + 1e-6) << what << " channel " << c;
  EXPECT_LE(std::abs(d.at(3, 2, 0) - d.at(3, 2, 1)), kHalfStep) << what;
  EXPECT_LE(std::abs(d.at(3, 2, 2) - d.at(3, 2, 1)), kHalfStep) << what;
  EXPECT_GT(d.at(5, 7, 0), d.at(5, 7, 1) + 0.2) << what;
  EXPECT_GT(d.at(5, 7, 0), d.at(5, 7, 2) + 0.2) << what;
}

TEST(Display, WhiteBalancesOnTheEmitterInViewWithACameraMatrix) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(380, 780, 10);
  const Json patch = {{"preset", "canon_eos_5d_mkiii"}, {"exposure", {{"time_s", "auto"}}}};
  for (const std::string illuminant : {"D65", "A", "F11"}) {
    const fs::path in = dir.file(illuminant + ".exr"), out = dir.file(illuminant + "_out.exr");
    write_display_scene(in, lit_by(illuminant, bands), true);
    test::run_sensor(in, out, test::config_of(patch));
    expect_white_and_red(out, illuminant);
    // The emitter, far above the surfaces, is white.
    const test::RgbLayer d = test::read_rgb(out, "display");
    for (int c = 0; c < 3; ++c) EXPECT_EQ(d.at(0, 9, c), 1.0f) << illuminant;
    SpectralExrReader reader(out);
    EXPECT_NE(reader.info().metadata.at("chromatrace.display").find("the brightest emitter in view"), std::string::npos);
  }
}

// The white comes from the scene's lights or from what the file says is white, never from a surface's pixels
// where the environment shows through. A floor (id 1, white, top half) and a red wall (id 2) lit by `surfaces`,
// two floor pixels at the edge that are mostly a bright blue sky (emission layer), and, when `lamp` is given,
// a lamp (id 3) of that spectrum in the bottom row. chromatrace.scene names the lamp as a light.
void write_edge_scene(const fs::path& path, const Bands& bands, const std::vector<double>& surfaces,
                      const std::vector<double>* lamp, const std::map<std::string, std::string>& extra = {}) {
  const PiecewiseLinearSpectrum red =
      read_csv(fs::path(CHROMATRACE_SOURCE_DIR) / "scenes" / "spectra" / "cornell_box.csv").spectrum("red");
  const std::vector<double> white(bands.size(), 1.0), wall = band_averages(red, bands);
  const std::vector<double> sky = scaled(band_averages(cie::daylight(20000), bands), 0.5);
  std::map<std::string, std::string> attributes = extra;
  attributes["chromatrace.scene"] = R"({"lights": [{"name": "lamp"}]})";
  write_scene(
      path, bands, 10, 10,
      [&](int x, int y) {
        Pixel p;
        p.id = y < 5 ? 1 : 2;
        if (y == 0 && x >= 8) {  // the floor's far edge, where the sky shows
          p.emitter = true;
          p.radiance = sky;
        } else if (lamp && y == 9 && x < 2) {
          p.emitter = true;
          p.id = 3;
          p.radiance = scaled(*lamp, 1e3);
        } else {
          p.radiance = lit(surfaces, y < 5 ? white : wall, 1.0 / std::numbers::pi);
        }
        return p;
      },
      true, {{1, "floor"}, {2, "wall"}, {3, "lamp"}}, attributes);
}

TEST(Display, WhiteComesFromTheScenesLightsNeverFromASurfacesEdge) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(380, 780, 10);
  const Json patch = {{"preset", "canon_eos_5d_mkiii"}, {"exposure", {{"time_s", "auto"}}}};
  const std::vector<double> d65 = scaled(band_averages(cie::illuminant("D65"), bands), 0.01);
  const std::vector<double> a = scaled(band_averages(cie::illuminant("A"), bands), 0.01);
  const auto white_balance = [](const fs::path& out) {
    SpectralExrReader reader(out);
    return Json::parse(reader.info().metadata.at("chromatrace.display"))["white_balance"].get<std::string>();
  };
  // No light in view: the sky at the floor's edge is not the white; D65 is.
  write_edge_scene(dir.file("edge.exr"), bands, d65, nullptr);
  test::run_sensor(dir.file("edge.exr"), dir.file("edge_out.exr"), test::config_of(patch));
  expect_white_and_red(dir.file("edge_out.exr"), "sky at an edge");
  EXPECT_EQ(white_balance(dir.file("edge_out.exr")), "illuminant D65 (no emitter in view)");
  // The scene's lamp in view is the white (the sky's pixels stay left out).
  write_edge_scene(dir.file("lamp.exr"), bands, a, &a);
  test::run_sensor(dir.file("lamp.exr"), dir.file("lamp_out.exr"), test::config_of(patch));
  expect_white_and_red(dir.file("lamp_out.exr"), "lamp A in view");
  EXPECT_EQ(white_balance(dir.file("lamp_out.exr")).rfind("the brightest emitter in view, object 3 (lamp)", 0), 0u)
      << white_balance(dir.file("lamp_out.exr"));
  // What the file says is white comes first: a D65-lit scene with an A lamp in view, from the Blender add-on.
  write_edge_scene(dir.file("said.exr"), bands, d65, &a, {{"chromatrace.white", "D65"}});
  test::run_sensor(dir.file("said.exr"), dir.file("said_out.exr"), test::config_of(patch));
  expect_white_and_red(dir.file("said_out.exr"), "chromatrace.white D65");
  EXPECT_EQ(white_balance(dir.file("said_out.exr")), "illuminant D65, the white of the scene's colours (chromatrace.white)");
  // A white that is no illuminant's name is an error naming the file and the attribute.
  write_edge_scene(dir.file("bad.exr"), bands, d65, nullptr, {{"chromatrace.white", "D66"}});
  try {
    test::run_sensor(dir.file("bad.exr"), dir.file("bad_out.exr"), test::config_of(patch));
    ADD_FAILURE() << "chromatrace.white D66 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.exr: chromatrace.white: "), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.file("bad_out.exr")));
}

// No emitter in view: D65. A named illuminant overrides the emitter.
TEST(Display, WithoutAnEmitterBalancesForD65OrTheNamedIlluminant) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(380, 780, 10);
  write_display_scene(dir.file("d65.exr"), lit_by("D65", bands), false);
  test::run_sensor(dir.file("d65.exr"), dir.file("d65_out.exr"),
                   test::config_of({{"preset", "canon_eos_5d_mkiii"}, {"exposure", {{"time_s", 0.01}}}}));
  expect_white_and_red(dir.file("d65_out.exr"), "D65, no emitter");

  write_display_scene(dir.file("a.exr"), lit_by("A", bands), true);
  const Json patch = {{"preset", "smartphone"},
                      {"exposure", {{"time_s", "auto"}}},
                      {"display", {{"white_balance", "A"}}}};
  test::run_sensor(dir.file("a.exr"), dir.file("a_out.exr"), test::config_of(patch));
  expect_white_and_red(dir.file("a_out.exr"), "A by name");
}

// The display layer changes nothing else: R, G, B and the linear layers are the same bits with it or without.
TEST(Display, LeavesTheRawImageAlone) {
  test::TempDir dir;
  write_display_scene(dir.file("in.exr"), lit_by("D65", Bands::uniform(380, 780, 10)), true);
  Json patch = {{"preset", "canon_eos_5d_mkiii"}, {"exposure", {{"time_s", "auto"}}}};
  const auto with = test::run_sensor(dir.file("in.exr"), dir.file("with.exr"), test::config_of(patch));
  patch["display"] = {{"enabled", false}};
  const auto without = test::run_sensor(dir.file("in.exr"), dir.file("without.exr"), test::config_of(patch));
  EXPECT_EQ(with.exposure_s, without.exposure_s);
  for (const std::string layer : {"", "linear", "emission"})
    EXPECT_EQ(test::read_rgb(dir.file("with.exr"), layer).values, test::read_rgb(dir.file("without.exr"), layer).values)
        << layer;
  SpectralExrReader reader(dir.file("without.exr"));
  for (const ExrChannel& c : reader.info().channels) EXPECT_FALSE(c.name.starts_with("display.")) << c.name;
}

// The display is the camera's picture: exposure.scale over-exposes it as it over-exposes the raw numbers (4× the
// linear display value where nothing clips, and white where it does), while the exposure time itself is
// normalised away.
TEST(Display, ShowsTheOverExposureAskedFor) {
  test::TempDir dir;
  write_display_scene(dir.file("in.exr"), lit_by("D65", Bands::uniform(380, 780, 10)), true);
  Json patch = {{"preset", "ideal"}, {"exposure", {{"time_s", 0.01}}}};
  test::run_sensor(dir.file("in.exr"), dir.file("one.exr"), test::config_of(patch));
  patch["exposure"]["time_s"] = 0.04;
  test::run_sensor(dir.file("in.exr"), dir.file("longer.exr"), test::config_of(patch));
  patch["exposure"] = {{"time_s", 0.01}, {"scale", 4.0}};
  test::run_sensor(dir.file("in.exr"), dir.file("four.exr"), test::config_of(patch));
  const test::RgbLayer one = test::read_rgb(dir.file("one.exr"), "display");
  const test::RgbLayer longer = test::read_rgb(dir.file("longer.exr"), "display");
  const test::RgbLayer four = test::read_rgb(dir.file("four.exr"), "display");
  std::size_t compared = 0, clipped = 0;
  for (std::size_t i = 0; i < one.values.size(); ++i) {
    EXPECT_NEAR(longer.values[i], one.values[i], 1e-3) << i;  // a longer time alone: the same picture
    const double a = srgb_decode(one.values[i]), b = srgb_decode(four.values[i]);
    if (4 * a < 0.95 && a > 0.02) {  // half storage: ~2.4e-4 of the encoded value, well under 1 % of these
      EXPECT_NEAR(b / a, 4.0, 0.04) << i;
      ++compared;
    } else if (4 * a > 1.05) {
      EXPECT_NEAR(four.values[i], 1.0, 1e-3) << i;
      ++clipped;
    }
  }
  EXPECT_GT(compared, 0u);
  EXPECT_GT(clipped, 0u);
}

// For the CIE camera the fitted matrix is exact: the display reproduces a reflectance's sRGB colour under D65.
// Errors: 1 nm bands integrate the CIE functions against band averages (~1e-6); the matrix keeps sRGB white
// (the chromaticity-defined D65 white) while the targets are relative to the tabulated D65 white, ~1e-4 apart;
// the half storage rounds the encoded value by up to 2⁻¹² ≈ 2.4e-4, which the decoding's slope (below 1.6 for
// encoded values under 0.8) and the division by 0.9 turn into at most 4.4e-4 of linear value. 1e-3 bounds the
// sum (~5.5e-4).
TEST(Display, MatrixIsExactForTheCieCamera) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(360, 830, 1);
  const std::vector<double> d65 = band_averages(cie::illuminant("D65"), bands);
  const PiecewiseLinearSpectrum patch = rgb_to_spectrum({0.6, 0.25, 0.1});
  const std::vector<double> white(bands.size(), 1.0), colour = band_averages(patch, bands);
  test::write_radiance(dir.file("in.exr"), bands, 10, 10, [&](int, int y, std::size_t b) {
    return static_cast<float>(d65[b] * (y < 6 ? white[b] : colour[b]) * 0.01);
  });
  test::run_sensor(dir.file("in.exr"), dir.file("out.exr"), test::config_of({{"exposure", {{"time_s", "auto"}}}}));
  const test::RgbLayer d = test::read_rgb(dir.file("out.exr"), "display");
  const Vec3d xyz = reflectance_to_xyz(patch, cie::illuminant("D65"));
  const Vec3d expected = xyz_to_linear_srgb(xyz);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(srgb_decode(d.at(4, 8, c)) / 0.9, expected[static_cast<std::size_t>(c)], 1e-3) << c;
    EXPECT_NEAR(d.at(4, 2, c), srgb_encode(0.9), kHalfStep / 2 + 1e-6) << c;
  }

  // The matrix itself: with the CIE camera, white-balanced X, Y, Z map to X, Y, Z (up to the white point).
  const sensor::SensorConfig config = test::config_of(Json::object());
  const auto weights = sensor::photon_response(bands, config.response.curves, config.response.basis, 1.0,
                                               PiecewiseLinearSpectrum::constant(1.0));
  const Eigen::Matrix3d m = sensor::camera_to_xyz(weights, bands, d65);
  const Eigen::Vector3d c_w = sensor::white_response(weights, d65);
  // x = c ⊘ c_w = XYZ ⊘ XYZ_w, so M = diag(XYZ_w) with Y_w = 1, and c_w ∝ XYZ_w.
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m(r, k), r == k ? c_w[r] / c_w[1] : 0.0, 1e-3) << r << "," << k;
}

}  // namespace
}  // namespace ct
