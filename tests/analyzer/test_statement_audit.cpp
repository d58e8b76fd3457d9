// SPDX-License-Identifier: Apache-2.0
// The statement audit (statement_audit.h) sees each kind of false sentence: for every kind, a region whose numbers
// make the sentence true passes, and the same sentence over numbers that make it false fails — the false sentences
// an earlier analyzer wrote on photographs (a blue body colour for a white cup, a direction with a negative
// component, "surface reflection of the light's colour" 35° from it, a "point" structured beyond its noise, γ at the
// end of its search, a clipping sentence about the wrong pixels or none about a sheen, "as the model has it" of a
// plane 4935 × as thick as its noise). Then the analyzer itself, on images made for each premise, writes what the
// audit finds true.
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "analyzer/analysis.h"
#include "analyzer/analysis_json.h"
#include "core/file_io.h"
#include "tests/analyzer/statement_audit.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

using nlohmann::json;

// One region in an analysis.json of the fields the audit reads: a chosen light (1, 1, 1) known to ±1°, 8-bit
// limits, the default criteria. Its interpretation says `statements` and nothing else.
struct Case {
  json shape = {{"class", "linear"}, {"samples", 1000}};
  json statements = json::array();
  std::string process_kind = "process.thickened";
  json process_claims = json::array();
  json gamma = nullptr;
  json interpretation_extra = json::object();
  std::vector<float> pixels = {100, 100, 100};

  Case& say(const std::string& kind, const std::string& text, std::vector<std::string> claims = {}) {
    statements.push_back({{"kind", kind}, {"text", text}, {"claims", claims}});
    return *this;
  }

  json analysis() const {
    std::string text = "linear in linear light: a process.";
    for (const json& s : statements) text.append(" ").append(s["text"].get_ref<const std::string&>());
    json in = {{"text", text}, {"process", "a process"}, {"process_kind", process_kind}, {"process_claims", process_claims},
               {"statements", statements}, {"body_colour", nullptr}, {"mean_colour", nullptr}};
    for (const auto& [k, v] : interpretation_extra.items()) in[k] = v;
    return {{"criteria", {{"min_line_angle_deg", 3.0}, {"noise_factor", 3.0}, {"clipped_fraction", 0.02}, {"black_faces_fraction", 0.5}}},
            {"clipping_levels", {255, 255, 255}},
            {"clipping_low_levels", {0, 0, 0}},
            {"illuminant",
             {{"estimate", {{"rgb", {1, 1, 1}}, {"reliable", true}, {"uncertainty_deg", 1.0}}},
              {"dichromatic_planes", {{"rgb", {1, 1, 1}}, {"reliable", true}, {"uncertainty_deg", 1.0}}},
              {"highlight_lines", nullptr}}},
            {"regions", {{{"name", "region"}, {"shape", shape}, {"linear_light", nullptr}, {"gamma_against_declared", gamma}, {"interpretation", in}}}}};
  }

  std::vector<std::string> audit() const {
    return audit_statements(analysis(), [this](std::size_t) { return pixels; });
  }
};

// A line of 1000 inliers from `from` to `to`, spread evenly, 0.001 off it (rms).
json line(const std::vector<double>& from, const std::vector<double>& to) {
  const Eigen::Vector3d a(from[0], from[1], from[2]), b(to[0], to[1], to[2]);
  const Eigen::Vector3d d = (b - a).normalized(), mid = (a + b) / 2;
  const double half = (b - a).norm() / 2;
  return {{"point", {mid[0], mid[1], mid[2]}}, {"direction", {d[0], d[1], d[2]}}, {"t_min", -half}, {"t_max", half}, {"inliers", 1000}, {"rms", 0.001}};
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += x + "\n";
  return s;
}

// A white cup whose line does not pass black: its direction is no body colour.
TEST(StatementAudit, ABodyColourOnlyOfALineThatReachesBlack) {
  Case through;
  through.shape["line"] = line({0.02, 0.02, 0.02}, {0.9, 0.85, 0.8});  // points at black within 0.1°
  through.say("body_colour", "Body colour (0.596, 0.562, 0.573).", {"reaches_black"});
  EXPECT_TRUE(through.audit().empty()) << joined(through.audit());

  Case cup = through;
  cup.shape["line"] = line({0.85, 0.80, 0.60}, {0.95, 0.93, 0.95});  // the white cup: a short line far from black
  EXPECT_FALSE(cup.audit().empty()) << "a body colour of a line that misses black passed";
  Case cup_said_so;
  cup_said_so.shape = cup.shape;
  cup_said_so.say("no_body_colour", "Its line does not reach black.", {"misses_black"});
  EXPECT_TRUE(cup_said_so.audit().empty()) << joined(cup_said_so.audit());
  // … and withheld where it should have been written.
  Case withheld;
  withheld.shape = through.shape;
  EXPECT_FALSE(withheld.audit().empty()) << "a line through black without its body colour passed";
  // A body colour statement must carry its premise.
  Case unclaimed = through;
  unclaimed.statements[0]["claims"] = json::array();
  EXPECT_FALSE(unclaimed.audit().empty());
}

TEST(StatementAudit, NoQuotedDirectionHasANegativeComponent) {
  Case positive;
  positive.say("highlight.no_light", "Its highlight branch points along (0.509, 0.733, 0.452).");
  EXPECT_TRUE(positive.audit().empty()) << joined(positive.audit());
  Case negative;
  negative.say("highlight.no_light", "Its highlight branch points along (0.509, -0.733, 0.452).");
  EXPECT_FALSE(negative.audit().empty());
}

// The wooden table: a branch 35° ± 9.9° from the light called surface reflection of the light's colour.
TEST(StatementAudit, SurfaceReflectionOfTheLightsColourOnlyWithinTwoSigma) {
  auto branch = [](double angle_deg) {
    Case c;
    c.shape["class"] = "P";
    const double a = angle_deg * M_PI / 180;
    // (1, 1, 1)/√3 turned by `angle` towards red's side of the grey axis.
    const Eigen::Vector3d grey = Eigen::Vector3d::Ones().normalized(), across = Eigen::Vector3d(2, -1, -1).normalized();
    const Eigen::Vector3d d = std::cos(a) * grey + std::sin(a) * across;
    c.shape["highlight_branch"] = {{"direction", {d[0], d[1], d[2]}}, {"uncertainty_deg", 9.9}, {"samples", 500}};
    return c;
  };
  Case near = branch(15);  // within 2·√(9.9² + 1²) = 19.9°
  near.say("highlight.light", "Its highlight branch is the light's.", {"light_highlight"});
  EXPECT_TRUE(near.audit().empty()) << joined(near.audit());
  Case far = branch(35);
  far.say("highlight.light", "Its highlight branch is the light's.", {"light_highlight"});
  EXPECT_FALSE(far.audit().empty()) << "35° ± 9.9° passed as the light's colour";
  far.process_kind = "process.light_highlight";
  far.process_claims = json::array({"light_highlight"});
  far.statements = json::array();
  EXPECT_FALSE(far.audit().empty()) << "a process of the light's highlight 35° ± 9.9° from it passed";
  Case said_so = branch(35);
  said_so.say("highlight.not_light", "It is not the light's colour.", {"not_light_highlight"});
  said_so.process_kind = "process.highlight";
  said_so.process_claims = json::array({"not_light_highlight"});
  EXPECT_TRUE(said_so.audit().empty()) << joined(said_so.audit());
}

// A point: every axis within noise, not only the first.
TEST(StatementAudit, APointOnlyWhenEveryAxisIsWithinNoise) {
  Case point;
  point.shape["class"] = "point";
  point.shape["sigma"] = {0.010, 0.004, 0.001};
  point.shape["noise_sigma"] = {0.005, 0.002, 0.001};
  point.process_kind = "process.point";
  point.process_claims = json::array({"within_noise"});
  EXPECT_TRUE(point.audit().empty()) << joined(point.audit());
  Case structured = point;
  structured.shape["noise_sigma"] = {0.005, 0.0006, 0.001};  // σ2 6.5 × its noise, σ1 within
  EXPECT_FALSE(structured.audit().empty()) << "a point structured along its second axis passed";
}

TEST(StatementAudit, GammaOnlyWhereTheFitIsAMeasurement) {
  Case measured;
  measured.gamma = {{"fitted_gamma", 0.45}, {"gamma_se", 0.01}};
  measured.say("gamma.measured", "Its values fit γ = 0.450 ± 0.010.", {"gamma_measured"});
  EXPECT_TRUE(measured.audit().empty()) << joined(measured.audit());
  for (const double bound : {0.2, 5.0}) {
    Case at_bound = measured;
    at_bound.gamma = {{"fitted_gamma", bound}, {"gamma_se", 0.0004}};
    EXPECT_FALSE(at_bound.audit().empty()) << "γ = " << bound << " at the search's end passed as measured";
    Case said_so;
    said_so.gamma = at_bound.gamma;
    said_so.say("gamma.not_measured", "Its values do not measure γ.", {"gamma_not_measured"});
    EXPECT_TRUE(said_so.audit().empty()) << joined(said_so.audit());
  }
  Case withheld;
  withheld.gamma = measured.gamma;
  EXPECT_FALSE(withheld.audit().empty()) << "a measured γ left unsaid passed";
}

// The sunlit orange bowl: B at black on bright pixels, and a sheen at R = 255 too small for a face.
TEST(StatementAudit, ClippingSentencesAreAboutThePixelsThatExist) {
  Case bowl;
  for (int i = 0; i < 100; ++i) bowl.pixels.insert(bowl.pixels.end(), {179.0f, 60.0f, 0.0f});
  bowl.pixels.insert(bowl.pixels.end(), {255.0f, 120.0f, 20.0f});  // the sheen
  bowl.say("clipping.faces", "98 % of its pixels are clipped: B low at 0 (98 %).");
  bowl.say("clipping.few", "Clipped, though too few to flatten a face: 1 pixel (0.98 %) with R at its top.");
  bowl.say("at_black.dim", "98 % of its pixels have B at black, and they are dim.", {"at_black_dim"});
  ASSERT_EQ(bowl.audit().size(), 1u) << joined(bowl.audit());
  EXPECT_NE(bowl.audit()[0].find("premise 'at_black_dim' is false"), std::string::npos) << "bright pixels at black called dim passed";
  Case bright = bowl;
  bright.statements = json::array();
  bright.say("clipping.faces", "98 % of its pixels are clipped: B low at 0 (98 %).");
  bright.say("at_black.bright", "98 % of its pixels have B at black although they are bright.", {"at_black_bright"});
  EXPECT_FALSE(bright.audit().empty()) << "the sheen's pixel at R's top, named nowhere, passed";
  bright.say("clipping.few", "Clipped, though too few to flatten a face: 1 pixel (0.98 %) with R at its top.");
  EXPECT_TRUE(bright.audit().empty()) << joined(bright.audit());
  Case none;
  none.say("clipping.none", "No pixel of it lies on a clipping level.", {"nothing_clipped"});
  EXPECT_TRUE(none.audit().empty()) << joined(none.audit());
  none.pixels = bowl.pixels;
  EXPECT_FALSE(none.audit().empty()) << "'no pixel on a clipping level' of clipped pixels passed";
  Case dim;
  for (int i = 0; i < 100; ++i) dim.pixels.insert(dim.pixels.end(), {20.0f, 5.0f, 0.0f});
  dim.say("clipping.faces", "99 % of its pixels are clipped: B low at 0 (99 %).");
  dim.say("at_black.dim", "Its pixels have B at black, and they are dim.", {"at_black_dim"});
  EXPECT_TRUE(dim.audit().empty()) << joined(dim.audit());
}

TEST(StatementAudit, AsTheModelHasItNeverOfAPlaneFarOffIt) {
  Case flat;
  flat.shape["class"] = "planar";
  flat.shape["significant_axes"] = 2;
  flat.shape["sigma"] = {0.2, 0.05, 0.001};
  flat.shape["noise_sigma"] = {0.001, 0.001, 0.001};
  flat.shape["plane"] = {{"normal", {0, 0, 1}}};
  const Eigen::Vector3d n = Eigen::Vector3d(1, -1, 0).normalized();  // holds (1, 1, 1)
  flat.shape["dichromatic_plane"] = {{"normal", {n[0], n[1], n[2]}}, {"rms", 0.002}};
  flat.say("plane.model", "A plane as the dichromatic model has it.", {"on_model_plane"});
  flat.say("thickness.flat", "Flat within its noise.", {"flat"});
  EXPECT_TRUE(flat.audit().empty()) << joined(flat.audit());
  Case thick = flat;
  thick.shape["sigma"] = {0.2, 0.05, 0.004935};
  thick.shape["noise_sigma"] = {1e-6, 1e-6, 1e-6};  // 4935 × as thick as its noise off the plane …
  thick.shape["dichromatic_plane"]["rms"] = 2e-6;   // … and within it of the plane through black
  thick.statements = json::array();
  thick.say("plane.model", "A plane as the dichromatic model has it.", {"on_model_plane"});
  ASSERT_EQ(thick.audit().size(), 1u) << joined(thick.audit());
  EXPECT_NE(thick.audit()[0].find("premise 'on_model_plane' is false"), std::string::npos)
      << "'as the model has it' of a plane 4935 × as thick as its noise passed";
  Case shifted = flat;  // flat, but its plane misses black: the white cup's
  shifted.shape["dichromatic_plane"]["rms"] = 0.02;
  shifted.statements = json::array();
  shifted.say("plane.model", "A plane as the dichromatic model has it.", {"on_model_plane"});
  EXPECT_FALSE(shifted.audit().empty()) << "'as the model has it' of a flat cluster 20 × its noise off the plane through black passed";
}

// The analyzer on images made for the premises: what it writes, the audit finds true, and the sentences are the
// ones the premises call for.
std::vector<std::string> audit_image(const analyzer::AnalysisImage& image, const analyzer::ImageAnalysis& a) {
  const json j = json::parse(analyzer::analysis_to_json(a).dump());
  const analyzer::RgbImage& layer = analyzer::select_layer(image, a.layer);
  return audit_statements(j, [&](std::size_t r) {
    std::vector<float> rgb;
    for (const std::uint32_t p : a.regions[r].pixels)
      for (int c = 0; c < 3; ++c) rgb.push_back(layer.rgb[p * 3 + static_cast<std::size_t>(c)]);
    return rgb;
  });
}

analyzer::AnalysisImage float_image(int w, int h, const std::function<Eigen::Vector3d(int, int)>& colour) {
  analyzer::AnalysisImage in;
  in.image.width = w, in.image.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3d c = colour(x, y);
      for (int k = 0; k < 3; ++k) in.image.rgb.push_back(static_cast<float>(c[k]));
    }
  return in;
}

bool says(const analyzer::Interpretation& in, const std::string& kind) {
  return std::any_of(in.findings.begin(), in.findings.end(), [&](const analyzer::Statement& s) { return s.kind == kind; });
}

TEST(StatementAudit, TheAnalyzerQuotesABodyColourOnlyOfALineThroughBlack) {
  // Shading of one colour from near black to bright, with a little noise; and the same with an offset of another
  // colour on every pixel (a white cup under a blue ambient).
  std::uint64_t state = 7;
  auto noise = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5) * 0.002;
  };
  const Eigen::Vector3d body(0.8, 0.5, 0.3);
  for (const bool offset : {false, true}) {
    SCOPED_TRACE(offset ? "offset" : "through black");
    const analyzer::AnalysisImage in = float_image(64, 64, [&](int x, int) {
      const double shade = 0.05 + 0.9 * x / 63.0;
      Eigen::Vector3d c = shade * body + Eigen::Vector3d(noise(), noise(), noise());
      if (offset) c += Eigen::Vector3d(0.1, 0.2, 0.5);
      return c;
    });
    const analyzer::ImageAnalysis a = analyzer::analyse_image(in, "", {analyzer::whole_image_region(64, 64)}, {}, std::nullopt, false);
    const analyzer::Interpretation& i = a.interpretations.at(0);
    EXPECT_EQ(says(i, "body_colour"), !offset) << analyzer::interpretation_text(i);
    EXPECT_EQ(says(i, "no_body_colour"), offset) << analyzer::interpretation_text(i);
    EXPECT_EQ(i.body_colour.has_value(), !offset);
    const std::vector<std::string> wrong = audit_image(in, a);
    EXPECT_TRUE(wrong.empty()) << joined(wrong);
  }
}

// Every variant of `chromatrace paper`, as the README runs it: each region's sentences audited against its camera
// image (the layer analysed, the object ids its regions are made of).
TEST(StatementAudit, PaperStatementsAreTrue) {
  TempDir dir;
  const std::filesystem::path out = dir.file("paper");
  // Every variant, at 96 × 96 rather than the default 128 × 128 (CI time): the audit holds whatever the classes are.
  const CommandResult r = run_chromatrace({"paper", "-o", out.string(), "--resolution", "96x96", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json series = json::parse(read_file(out / "series.json"));
  std::size_t variants = 0, regions = 0, statements = 0;
  for (const json& v : series["variants"]) {
    const std::string name = v["name"];
    SCOPED_TRACE(name);
    const json a = json::parse(read_file(out / name / "analysis" / "analysis.json"));
    const analyzer::AnalysisImage image = analyzer::read_analysis_image(out / name / "camera.exr");
    const analyzer::RgbImage& layer = analyzer::select_layer(image, a["image"]["layer"].get<std::string>());
    const std::vector<std::string> wrong = audit_statements(a, [&](std::size_t k) {
      const json& region = a["regions"][k];
      const bool whole = region["source"] == "image";
      const std::int64_t label = region["label"].is_number() ? region["label"].get<std::int64_t>() : -1;
      std::vector<float> rgb;
      if (!whole && (label < 0 || image.object_ids.empty())) {
        ADD_FAILURE() << "region " << region["name"] << ": no pixels to audit";
        return rgb;
      }
      for (std::size_t p = 0; p < layer.pixel_count(); ++p) {
        if (!whole && image.object_ids[p] != label) continue;
        const float* c = &layer.rgb[p * 3];
        if (std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2])) rgb.insert(rgb.end(), c, c + 3);
      }
      return rgb;
    });
    for (const std::string& w : wrong) ADD_FAILURE() << name << ": " << w;
    ++variants;
    regions += a["regions"].size();
    for (const json& region : a["regions"]) statements += region["interpretation"]["statements"].size();
  }
  EXPECT_GE(variants, 13u);
  std::cerr << variants << " variants, " << regions << " regions, " << statements << " statements audited\n";
}

}  // namespace
}  // namespace ct::test
