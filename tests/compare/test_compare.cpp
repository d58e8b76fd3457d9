// SPDX-License-Identifier: Apache-2.0
// chromatrace compare on synthetic renders with known means and known noise: agreement, a known
// disagreement found in exactly its cells, standard errors from one render and from several seeds, nested
// band plans, and incomparable or bad input (exit 2, one line, nothing written); and the white of its ΔE00, on
// the tracer's renders of the paper box under F11.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/json_input.h"
#include "core/scene.h"
#include "core/spectral_exr.h"
#include "plan/plan.h"
#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kW = 32, kH = 32;

// Object 1 (lambert "wall") on the left half, object 2 (dichromatic "ball") on the right half.
std::int32_t object_at(int x) { return x < kW / 2 ? 1 : 2; }

struct Synthetic {
  std::string scene_name = "synthetic";
  Bands bands = Bands::uniform(380, 780, 40);
  double sigma = 0.01;  // per-pixel noise, relative to the value
  std::uint64_t seed = 1;
  double ball_diffuse_scale = 1.0;  // multiplies diffuse_direct (and so the total) on object 2
  double edge_scale = 1.0;  // multiplies diffuse_direct on the two columns where the objects meet
  int width = kW;
  double camera_x = 0.0;
  double slope = 0.001;  // relative change of every spectrum per nm about 580 nm (0: flat within each 40 nm bin)
  std::string extra;       // a third name with id 3 and no pixels, when not empty
  bool extra_is_light = false;  // and it is one of the scene's lights (else an object)
};

// Band b of object o's diffuse_direct and glossy_direct.
double diffuse_value(int o, std::size_t b) { return o == 1 ? 0.2 + 0.01 * double(b) : 0.1 + 0.02 * double(b); }
double glossy_value(int o, std::size_t b) { return o == 1 ? 0.0 : 0.05 + 0.001 * double(b); }

void write_render(const fs::path& file, const Synthetic& s) {
  SpectralExrLayout layout;
  layout.width = s.width;
  layout.height = kH;
  layout.bands = s.bands;
  layout.components = {"diffuse_direct", "glossy_direct"};
  layout.object_ids = true;
  layout.object_names = {{1, "wall"}, {2, "ball"}};
  json scene = {{"format", "chromatrace-scene/1"},
                {"name", s.scene_name},
                {"materials", {{"wall", {{"type", "lambert"}}}, {"ball", {{"type", "dichromatic"}}}}},
                {"objects", {{{"name", "wall"}, {"material", "wall"}}, {{"name", "ball"}, {"material", "ball"}}}}};
  if (!s.extra.empty()) {
    layout.object_names[3] = s.extra;
    scene[s.extra_is_light ? "lights" : "objects"].push_back({{"name", s.extra}, {"material", "wall"}});
  }
  layout.attributes["chromatrace.scene"] = scene.dump();
  layout.attributes["chromatrace.camera"] =
      json{{"position", {s.camera_x, -3.5, 1}}, {"look_at", {s.camera_x, 0, 1}}, {"up", {0, 0, 1}},
           {"horizontal_fov_deg", 40}, {"vertical_fov_deg", 40}}
          .dump();
  layout.attributes["chromatrace.seed"] = std::to_string(s.seed);
  layout.attributes["chromatrace.renderer"] = "synthetic";
  const std::size_t nb = s.bands.size(), n = std::size_t(s.width) * kH;
  std::vector<float> total(n * nb), diffuse(n * nb), glossy(n * nb);
  std::vector<std::int32_t> ids(n);
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (std::size_t p = 0; p < n; ++p) {
    const int o = object_at(int(p % std::size_t(s.width)) * kW / s.width);
    ids[p] = o;
    for (std::size_t b = 0; b < nb; ++b) {
      // The value of the band as the average of 10 nm sub-bands that differ, so coarse = mean of fine.
      const double c = s.bands.centre(b);
      const double slope = 1.0 + s.slope * (c - 580.0);
      double d = diffuse_value(o, std::size_t((c - 380) / 40)) * slope * (1 + s.sigma * noise(rng));
      if (o == 2) d *= s.ball_diffuse_scale;
      if (const int x = int(p % std::size_t(s.width)); x == s.width / 2 - 1 || x == s.width / 2) d *= s.edge_scale;
      const double g = glossy_value(o, std::size_t((c - 380) / 40)) * slope * (1 + s.sigma * noise(rng));
      diffuse[p * nb + b] = float(d);
      glossy[p * nb + b] = float(g);
      total[p * nb + b] = float(d + g);
    }
  }
  SpectralExrWriter writer(file, layout);
  SpectralRowBlock block;
  block.rows = kH;
  block.total = total;
  block.components = {diffuse, glossy};
  block.object_ids = ids;
  writer.write_rows(block);
  writer.finish();
}

class Compare : public ::testing::Test {
 protected:
  fs::path render(const std::string& name, const Synthetic& s) {
    const fs::path file = dir_.file(name);
    write_render(file, s);
    return file;
  }
  test::CommandResult run(std::vector<std::string> args) {
    args.insert(args.begin(), "compare");
    return test::run_chromatrace(args);
  }
  json result(const std::string& out) { return json::parse(std::ifstream(dir_.file(out) / "compare.json")); }
  test::TempDir dir_;
};

const json* find_cell(const json& doc, const std::string& object, const std::string& component, int band) {
  for (const json& c : doc["cells"])
    if (c["object"] == object && c["component"] == component && c["band"] == band) return &c;
  return nullptr;
}

TEST_F(Compare, SameExpectationAgreesWithHonestStandardErrors) {
  Synthetic a, b;
  b.seed = 2;
  const auto r = run({render("a.exr", a).string(), render("b.exr", b).string(), "-o", dir_.file("out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("AGREE"), std::string::npos) << r.err;
  const json doc = result("out");
  EXPECT_EQ(doc["format"], "chromatrace-compare/1");
  EXPECT_TRUE(doc["verdict"]["agree"]);
  EXPECT_EQ(doc["verdict"]["failed"], 0);
  // 3 regions (image, wall, ball) × 3 layers × 10 bands.
  EXPECT_EQ(doc["cells"].size(), 90u);
  EXPECT_EQ(doc["object_id_mismatch_pixels"], 0);
  // The standard error from neighbouring pixels is the known σ/√n (within 15 %: 512 pixels, ~1000 pairs).
  const json* c = find_cell(doc, "wall", "diffuse_direct", 3);
  ASSERT_NE(c, nullptr);
  const double expected = 0.01 * (*c)["mean_a"].get<double>() / std::sqrt(512.0);
  EXPECT_NEAR((*c)["se_a"].get<double>() / expected, 1.0, 0.15);
  EXPECT_EQ((*c)["pixels"], 512);
  EXPECT_EQ((*c)["tolerance"], 0.01);
  EXPECT_EQ((*find_cell(doc, "ball", "total", 0))["tolerance"], 0.02);
  // z-scores are standard normal: none beyond 4.5 among 90 cells.
  for (const json& cell : doc["cells"])
    if (!cell["z"].is_null()) {
      EXPECT_LT(std::abs(cell["z"].get<double>()), 4.5) << cell.dump();
    }
  // Glossy is exactly 0 on the wall in both: passes with no ratio.
  const json* g = find_cell(doc, "wall", "glossy_direct", 0);
  EXPECT_TRUE((*g)["ratio"].is_null());
  EXPECT_TRUE((*g)["pass"]);
  for (const char* f : {"compare.json", "compare.png", "compare.html"}) EXPECT_TRUE(fs::exists(dir_.file("out") / f));
  std::ifstream html(dir_.file("out") / "compare.html");
  const std::string text((std::istreambuf_iterator<char>(html)), {});
  EXPECT_NE(text.find("data:image/png;base64,"), std::string::npos);
}

TEST_F(Compare, KnownDisagreementIsFoundInExactlyItsCells) {
  Synthetic a, b;
  b.seed = 2;
  b.ball_diffuse_scale = 1.05;  // 5 % more diffuse light on the ball: beyond 2 % + 4 SE (SE ≈ 0.06 %)
  const auto r = run({render("a.exr", a).string(), render("b.exr", b).string(), "-o", dir_.file("out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;  // disagreement is a result, not an error
  EXPECT_NE(r.err.find("DISAGREE"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ball"), std::string::npos);
  const json doc = result("out");
  EXPECT_FALSE(doc["verdict"]["agree"]);
  for (const json& cell : doc["cells"]) {
    const bool offending = cell["object"] == "ball" && (cell["component"] == "diffuse_direct" || cell["component"] == "total");
    const bool image = cell["object"] == "(image)" && cell["component"] == "diffuse_direct";
    if (offending) {
      EXPECT_FALSE(cell["pass"]) << cell.dump();
      if (cell["component"] == "diffuse_direct") {
        EXPECT_NEAR(cell["ratio"].get<double>(), 1 / 1.05, 0.003);
      }
    } else if (!image && cell["object"] != "(image)") {
      EXPECT_TRUE(cell["pass"]) << cell.dump();
    }
  }
  // A fixed tolerance of 10 % accepts the same pair.
  const auto loose = run({dir_.file("a.exr").string(), dir_.file("b.exr").string(), "-o", dir_.file("loose").string(),
                          "--tolerance", "10%"});
  ASSERT_EQ(loose.exit_code, 0) << loose.err;
  EXPECT_TRUE(result("loose")["verdict"]["agree"]);
}

TEST_F(Compare, SeveralSeedsGiveTheStandardErrorFromTheirSpread) {
  static const char* const kNamesA[] = {"a0.exr", "a1.exr", "a2.exr", "a3.exr", "a4.exr", "a5.exr"};
  static const char* const kNamesB[] = {"b0.exr", "b1.exr", "b2.exr", "b3.exr", "b4.exr", "b5.exr"};
  Synthetic s;
  std::string a, b;
  for (int i = 0; i < 6; ++i) {
    s.seed = 10 + std::uint64_t(i);
    if (i) a.push_back(',');
    a.append(render(kNamesA[i], s).string());
    s.seed = 20 + std::uint64_t(i);
    if (i) b.push_back(',');
    b.append(render(kNamesB[i], s).string());
  }
  const auto r = run({a, b, "-o", dir_.file("out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = result("out");
  EXPECT_TRUE(doc["verdict"]["agree"]);
  EXPECT_EQ(doc["a"]["files"].size(), 6u);
  // SE of the mean of 6 means of 512 pixels: σ·m/√(512·6), estimated from 6 values (so within a factor 2).
  const json* c = find_cell(doc, "wall", "diffuse_direct", 5);
  const double expected = 0.01 * (*c)["mean_a"].get<double>() / std::sqrt(512.0 * 6);
  EXPECT_GT((*c)["se_a"].get<double>(), 0.4 * expected);
  EXPECT_LT((*c)["se_a"].get<double>(), 2.0 * expected);
}

TEST_F(Compare, NestedBandPlansAreComparedOnTheCoarserOne) {
  Synthetic a, b;
  a.bands = Bands::uniform(380, 780, 10);  // each 40 nm band of B is the average of four of A's
  b.seed = 2;
  b.sigma = a.sigma = 0.0;
  const auto r = run({render("a.exr", a).string(), render("b.exr", b).string(), "-o", dir_.file("out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = result("out");
  EXPECT_EQ(doc["bands"]["edges_nm"].size(), 11u);
  // Linear within each coarse band, so the fine bands average exactly to the coarse value.
  for (const json& cell : doc["cells"])
    if (!cell["ratio"].is_null()) {
      EXPECT_NEAR(cell["ratio"].get<double>(), 1.0, 1e-5) << cell.dump();
    }
}

TEST_F(Compare, IncomparableInputsExit2NamingTheFileAndWhatDiffers) {
  Synthetic a;
  const std::string fa = render("a.exr", a).string();
  struct Case {
    std::string name;
    Synthetic b;
    std::string expect;
  };
  std::vector<Case> cases(4);
  cases[0].name = "size.exr";
  cases[0].b.width = 64;
  cases[0].expect = "different sizes";
  cases[1].name = "scene.exr";
  cases[1].b.scene_name = "other";
  cases[1].expect = "different scenes";
  cases[2].name = "camera.exr";
  cases[2].b.camera_x = 0.5;
  cases[2].expect = "chromatrace.camera: position.x";
  cases[3].name = "bands.exr";
  cases[3].b.bands = Bands::uniform(400, 700, 30);
  cases[3].expect = "do not nest";
  for (const Case& c : cases) {
    const std::string fb = render(c.name, c.b).string();
    const auto r = run({fa, fb, "-o", dir_.file("out_" + c.name).string()});
    EXPECT_EQ(r.exit_code, 2) << c.name;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(fb), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_.file("out_" + c.name))) << "nothing written for " << c.name;
  }
  // Bad input: a missing file, a bad tolerance, an unknown camera.
  const auto missing = run({fa, dir_.file("nope.exr").string(), "-o", dir_.file("o1").string()});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("nope.exr: cannot open"), std::string::npos) << missing.err;
  const auto tol = run({fa, fa, "-o", dir_.file("o2").string(), "--tolerance", "lots"});
  EXPECT_EQ(tol.exit_code, 2);
  EXPECT_NE(tol.err.find("--tolerance"), std::string::npos) << tol.err;
  const auto cam = run({fa, fa, "-o", dir_.file("o3").string(), "--camera", "pinhole"});
  EXPECT_EQ(cam.exit_code, 2);
  EXPECT_NE(cam.err.find("--camera"), std::string::npos) << cam.err;
  for (const char* o : {"o1", "o2", "o3"}) EXPECT_FALSE(fs::exists(dir_.file(o)));
}

// Cycles gives Blender's light objects no id; the scene file exported from the .blend has them as lights, which
// the tracer's render names after the objects. Such ids of B's scene's lights are compared (they hold no pixels),
// any other id A lacks is another scene.
TEST_F(Compare, IdsThatOnlyBsSceneLightsHaveAreComparable) {
  Synthetic a, lamp, chair;
  lamp.extra = chair.extra = "lamp";
  lamp.extra_is_light = true;
  lamp.seed = chair.seed = 2;
  const std::string fa = render("a.exr", a).string(), fl = render("lamp.exr", lamp).string();
  const auto r = run({fa, fl, "-o", dir_.file("out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(result("out")["verdict"]["agree"]);
  const std::string fc = render("chair.exr", chair).string();
  const auto refused = run({fa, fc, "-o", dir_.file("out2").string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find(fc + ": attribute chromatrace.objects: more objects than in " + fa), std::string::npos)
      << refused.err;
  // Nor the other way round: A's lights are not B's to lack.
  const auto reversed = run({fl, fa, "-o", dir_.file("out3").string()});
  EXPECT_EQ(reversed.exit_code, 2);
  EXPECT_NE(reversed.err.find("id 3 is no object"), std::string::npos) << reversed.err;
}

TEST_F(Compare, IdenticalRendersHaveZeroDeltaE) {
  Synthetic a;
  const std::string fa = render("a.exr", a).string();
  const auto r = run({fa, fa, "-o", dir_.file("out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = result("out");
  EXPECT_EQ(doc["image"]["delta_e00"]["max"], 0.0);
  EXPECT_EQ(doc["image"]["camera"], "cie1931");
  // A 5 % brighter ball is a visible, bounded colour difference there and none on the wall.
  Synthetic b;
  b.ball_diffuse_scale = 1.05;
  b.sigma = a.sigma;
  const auto r2 = run({fa, render("b.exr", b).string(), "-o", dir_.file("out2").string(), "--camera", "nikon_d850"});
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  const json d2 = result("out2");
  EXPECT_GT(d2["image"]["delta_e00"]["p95"].get<double>(), 0.3);
  EXPECT_LT(d2["image"]["delta_e00"]["max"].get<double>(), 10.0);
  // Each object's mean ΔE00 over its pixels: none on the wall, the ball's above the image's (which the wall dilutes).
  std::map<std::string, double> by_object;
  for (const json& o : d2["objects"]) by_object[o["object"].get<std::string>()] = o["delta_e00_mean"].get<double>();
  EXPECT_EQ(by_object.at("wall"), 0.0);
  EXPECT_EQ(by_object.at("(image)"), d2["image"]["delta_e00"]["mean"].get<double>());
  EXPECT_GT(by_object.at("ball"), by_object.at("(image)"));
  EXPECT_GT(by_object.at("(image)"), 0.0);

  // With --pixels interior an object's mean leaves out its edge pixels, as its cells do: a difference only in the
  // two columns where the objects meet is none inside either, and there with the edges matched.
  Synthetic edges;
  edges.edge_scale = 1.05;
  edges.sigma = a.sigma;
  const std::string fe = render("edges.exr", edges).string();
  for (const std::string pixels : {"interior", "matched"}) {
    const auto r4 = run({fa, fe, "-o", dir_.file("out-" + pixels).string(), "--pixels", pixels});
    ASSERT_EQ(r4.exit_code, 0) << r4.err;
    for (const json& o : result("out-" + pixels)["objects"]) {
      if (o["object_id"].get<int>() < 0) continue;
      if (pixels == "interior")
        EXPECT_EQ(o["delta_e00_mean"].get<double>(), 0.0) << o["object"];
      else
        EXPECT_GT(o["delta_e00_mean"].get<double>(), 0.0) << o["object"];
    }
  }

  // A camera's curves from a file under a hostile folder name: its path reaches compare.html as text, not as a tag.
  const fs::path folder = dir_.file("cam<img src=x onerror=alert(1)>");
  fs::create_directory(folder);
  std::ofstream(folder / "c.csv") << "wavelength_nm,r,g,b\n300,1,0.5,0.2\n900,1,0.5,0.2\n";
  const auto r3 = run({fa, fa, "-o", dir_.file("out3").string(), "--camera", (folder / "c.csv").string()});
  ASSERT_EQ(r3.exit_code, 0) << r3.err;
  std::ifstream page(dir_.file("out3") / "compare.html");
  const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  EXPECT_EQ(html.find("<img src=x"), std::string::npos);
  EXPECT_NE(html.find("cam&lt;img src=x onerror=alert(1)&gt;"), std::string::npos);
}

// Noiseless renders whose ball differs by 0.5 %, inside its 2 % tolerance: its cells have no standard error, so
// their z is infinite and they pass on the tolerance alone. The verdict agrees and quotes the largest finite |z| (the
// whole image's, whose pixels differ among themselves), never an infinite one.
TEST_F(Compare, CellsExactOnBothSidesPassOnTheToleranceAndQuoteNoInfiniteZ) {
  Synthetic a;
  a.sigma = 0;
  Synthetic b = a;
  b.ball_diffuse_scale = 1.005;
  const auto r = run({render("a.exr", a).string(), render("b.exr", b).string(), "-o", dir_.file("out").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("AGREE: all"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; largest |z| "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("inf"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace ct

namespace ct {
namespace {

// --colour own: each side's colour over its own bands. A fine plan nested in a coarse one gives the same colour
// exactly when the spectra are flat within each coarse band, and a different one when they slope (the coarse
// plan's colour error), which --colour common (both on the coarse plan) does not see.
TEST_F(Compare, OwnColoursCountTheCoarserPlansColourError) {
  for (const double slope : {0.0, 0.001}) {
    Synthetic a, b;
    a.bands = Bands::uniform(380, 780, 10);
    a.sigma = b.sigma = 0.0;
    a.slope = b.slope = slope;
    const std::string fa = render(fmt::format("a{}.exr", slope), a).string();
    const std::string fb = render(fmt::format("b{}.exr", slope), b).string();
    const std::string own = fmt::format("own{}", slope), common = fmt::format("common{}", slope);
    ASSERT_EQ(run({fa, fb, "-o", dir_.file(own).string(), "--colour", "own"}).exit_code, 0);
    ASSERT_EQ(run({fa, fb, "-o", dir_.file(common).string()}).exit_code, 0);
    const json o = result(own), c = result(common);
    EXPECT_EQ(o["image"]["colour"], "own");
    EXPECT_EQ(c["image"]["colour"], "common");
    // Single-precision band values round colours to well under 10⁻³ ΔE00; a real difference is far above that.
    constexpr double kRounding = 1e-3;
    EXPECT_LT(c["image"]["delta_e00"]["max"].get<double>(), kRounding) << slope;
    if (slope == 0.0)
      EXPECT_LT(o["image"]["delta_e00"]["max"].get<double>(), kRounding);
    else
      EXPECT_GT(o["image"]["delta_e00"]["mean"].get<double>(), 10 * kRounding);
  }
  const auto bad = run({dir_.file("a0.exr").string(), dir_.file("b0.exr").string(), "-o", dir_.file("x").string(),
                        "--colour", "mine"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--colour"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_.file("x")));
}

}  // namespace
}  // namespace ct

namespace ct {
namespace {

// The image level's white is the scene's light (CompareOptions::white), the white plan predicts under: two tracer
// renders of the paper box lit by F11 (its seeds 1 and 2), whose ΔE00 between them compare measures exactly as
// plan::measure_delta_e does (its white from the scene's light at the level of its reference, here A); under
// --white d65 another, the renders' colours being no longer those of a light its observer has adapted to; and a
// render whose header holds no scene with a light is compared under D65, said with the reason.
TEST_F(Compare, TheWhiteIsTheScenesLightAsPlanMeasures) {
  Json doc = read_json(test::kPaperBox);
  doc["spectra"]["lamp"] = {{"illuminant", "F11"}};
  for (auto& [name, spectrum] : doc["spectra"].items())
    if (spectrum.contains("csv"))
      spectrum["csv"] = (fs::path(test::kPaperBox).parent_path() / spectrum["csv"].get<std::string>()).lexically_normal().string();
  const fs::path scene_file = dir_.file("box-f11.json");
  std::ofstream(scene_file) << doc.dump(1);
  std::vector<std::string> renders;
  for (int seed : {1, 2}) {
    renders.push_back(dir_.file(fmt::format("box-f11-{}.exr", seed)).string());
    const test::CommandResult r =
        test::run_chromatrace({"render", scene_file.string(), "-o", renders.back(), "--resolution", "24x24", "--bands",
                               "400:700:30", "--spp", "16", "--seed", std::to_string(seed), "-q"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ASSERT_EQ(run({renders[0], renders[1], "-o", dir_.file("scene").string(), "--colour", "own"}).exit_code, 0);
  ASSERT_EQ(run({renders[0], renders[1], "-o", dir_.file("d65").string(), "--colour", "own", "--white", "d65"}).exit_code,
            0);
  const json scene = result("scene"), d65 = result("d65");
  EXPECT_EQ(scene["image"]["white"], "the scene's light (A's chromatrace.scene)");
  EXPECT_EQ(d65["image"]["white"], "D65");
  std::stringstream page;
  page << std::ifstream(dir_.file("scene") / "compare.html").rdbuf();
  EXPECT_NE(page.str().find("white: the scene&#39;s light (A&#39;s chromatrace.scene)"), std::string::npos);  // said to its reader
  const double measured = plan::measure_delta_e(renders[1], renders[0], load_scene(scene_file)).mean;
  // The same pixels, observer, white and formula: equal but for the order of floating-point sums.
  EXPECT_NEAR(scene["image"]["delta_e00"]["mean"].get<double>(), measured, 1e-9 * measured);
  EXPECT_GT(std::abs(d65["image"]["delta_e00"]["mean"].get<double>() - measured), 0.02 * measured);

  Synthetic s;  // its scene has neither lights nor the fields a scene file needs
  const std::string fa = render("synthetic-a.exr", s).string(), fb = render("synthetic-b.exr", s).string();
  ASSERT_EQ(run({fa, fb, "-o", dir_.file("synthetic").string()}).exit_code, 0);
  const std::string said = result("synthetic")["image"]["white"].get<std::string>();
  EXPECT_EQ(said.rfind("D65: no scene's light in either header (A: ", 0), 0u) << said;
  const auto bad = run({fa, fb, "-o", dir_.file("x").string(), "--white", "d50"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--white"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace ct
