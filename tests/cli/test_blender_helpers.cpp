// SPDX-License-Identifier: Apache-2.0
// The `chromatrace` subcommands the Blender add-on calls: scene-bands, export-meshes and assemble, end to end
// through the executable, with good and bad input.
#include <algorithm>
#include <limits>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/cie.h"
#include "core/colour.h"
#include "core/ply.h"
#include "core/scene.h"
#include "core/spectral_exr.h"
#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::run_chromatrace;

using test::kPaperBox;

using test::line_count;

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct BadCase {
  std::vector<std::string> args;
  std::string must_mention;
};

void expect_bad_input(const std::vector<BadCase>& cases, const fs::path& must_not_exist = {}) {
  for (const BadCase& c : cases) {
    const auto r = run_chromatrace(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.must_mention << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.must_mention), std::string::npos) << "expected \"" << c.must_mention << "\" in " << r.err;
    if (!must_not_exist.empty()) {
      EXPECT_FALSE(fs::exists(must_not_exist)) << c.must_mention;
    }
  }
}

// ---- scene-bands --------------------------------------------------------------------------------------

TEST(SceneBands, SceneGivesBandAveragesOfEveryMaterialAndLightFromCore) {
  const auto r = run_chromatrace({"scene-bands", kPaperBox, "--bands", "400:700:50", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = json::parse(r.out);
  EXPECT_EQ(report["bands"]["count"], 6);
  EXPECT_EQ(report["bands"]["edges_nm"].front(), 400.0);
  EXPECT_EQ(report["bands"]["edges_nm"].back(), 700.0);

  const Scene scene = load_scene(kPaperBox);
  const Bands bands = Bands::uniform(400, 700, 50);
  EXPECT_EQ(report["spectra"]["yellow"]["bands"].get<std::vector<double>>(),
            band_averages(scene.find_spectrum("yellow")->spectrum, bands));
  const json& sphere = report["materials"]["sphere"];
  EXPECT_EQ(sphere["type"], "dichromatic");
  EXPECT_EQ(sphere["lobe"], "ggx");
  EXPECT_EQ(sphere["roughness"], 0.15);
  EXPECT_EQ(sphere["diffuse"], report["spectra"]["yellow"]["bands"]);
  const json& lamp = report["lights"][0];
  EXPECT_EQ(lamp["name"], "ceiling_lamp");
  EXPECT_EQ(lamp["group"], "ceiling");
  EXPECT_EQ(lamp["id"], 8);
  EXPECT_EQ(lamp["radiance"].get<std::vector<double>>(), band_averages(scene.lights[0].emitted_radiance(), bands));
  EXPECT_EQ(report["objects"][5]["material"], "sphere");

  const auto text = run_chromatrace({"scene-bands", kPaperBox});  // the scene's own plan: 380:780:10
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("40 bands over 380-780 nm"), std::string::npos) << text.out;
}

TEST(SceneBands, SpectraListAndBandPlanFile) {
  test::TempDir dir;
  write_text(dir.file("spectra.json"), R"({"format": "chromatrace-spectra/1", "spectra": {
      "half": {"constant": 0.5}, "ramp": {"samples": [[400, 0], [500, 1]]}, "lamp": {"illuminant": "D65"}}})");
  write_text(dir.file("plan.json"), R"({"format": "chromatrace-bands/1", "edges_nm": [400, 450, 500, 700]})");
  const auto r = run_chromatrace({"scene-bands", dir.file("spectra.json").string(), "--bands-file",
                                  dir.file("plan.json").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = json::parse(r.out);
  EXPECT_EQ(report["bands"]["centres_nm"], json::array({425.0, 475.0, 600.0}));
  EXPECT_EQ(report["spectra"]["half"]["bands"], json::array({0.5, 0.5, 0.5}));
  // The ramp rises from 0 to 1 over 400-500 nm and is zero beyond: averages 0.25, 0.75 and 0.
  EXPECT_EQ(report["spectra"]["ramp"]["bands"], json::array({0.25, 0.75, 0.0}));
  EXPECT_EQ(report["spectra"]["ramp"]["max"], 1.0);
  EXPECT_EQ(report["spectra"]["ramp"]["max_nm"], 500.0);
  EXPECT_FALSE(report.contains("materials"));
}

// Each spectrum's colour in linear sRGB, as a reflectance under D65 and as an emission relative to D65 (what the
// add-on shows in Blender). Tolerance 1e-3 of the colour's scale: the sRGB white is D65's defining chromaticity, the CIE table's integral
// differs from it by about 3e-4; an {"rgb"} source comes back within the upsampling table's round trip (bench/README.md,
// "RGB upsampling table": under 1e-3 for these colours).
TEST(SceneBands, ColoursAsAReflectanceUnderD65AndAsAnEmissionRelativeToD65) {
  test::TempDir dir;
  write_text(dir.file("spectra.json"), R"({"format": "chromatrace-spectra/1",
      "spectra": {"white": {"constant": 1.0}, "paint": {"rgb": [0.2, 0.4, 0.6]}, "d65": {"illuminant": "D65"}},
      "radiance": {"orange": {"rgb": [0.9, 0.5, 0.1]}}})");
  const auto r = run_chromatrace({"scene-bands", dir.file("spectra.json").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json spectra = json::parse(r.out)["spectra"];
  auto expect_rgb = [](const json& got, const Vec3d& want, const char* what, double scale = 1.0) {
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(got[c].get<double>(), want[c], 1e-3 * scale) << what << " channel " << c;
  };
  expect_rgb(spectra["white"]["linear_srgb_reflected"], {1, 1, 1}, "the perfect white under D65");
  expect_rgb(spectra["paint"]["linear_srgb_reflected"], {0.2, 0.4, 0.6}, "an RGB reflectance");
  expect_rgb(spectra["orange"]["linear_srgb_emitted"], {0.9, 0.5, 0.1}, "an emitted RGB");
  // The flat spectrum emitted is illuminant E, XYZ = (1, 1, 1) at its own luminance.
  expect_rgb(spectra["white"]["linear_srgb_emitted"], xyz_to_linear_srgb({1, 1, 1}), "the flat spectrum emitted");
  // D65 emitted is grey, at its luminance over the flat spectrum 1's.
  const double y = spectrum_to_xyz(cie::illuminant("D65"))[1] /
                   spectrum_to_xyz(PiecewiseLinearSpectrum::constant(1.0))[1];
  expect_rgb(spectra["d65"]["linear_srgb_emitted"], {y, y, y}, "D65 emitted", y);
}

TEST(SceneBands, BadInputGetsExitTwoAndOneLineNamingTheField) {
  test::TempDir dir;
  write_text(dir.file("plan.json"), R"({"format": "chromatrace-bands/1", "edges_nm": [400, 450, 440]})");
  write_text(dir.file("plan_um.json"), R"({"format": "chromatrace-bands/1", "edges_nm": [0.4, 0.5, 0.6]})");
  write_text(dir.file("bad_source.json"), R"({"format": "chromatrace-spectra/1", "spectra": {"x": {"colour": 1}}})");
  write_text(dir.file("extra_key.json"), R"({"format": "chromatrace-spectra/1", "spectra": {}, "bands": "1"})");
  expect_bad_input({
      {{"scene-bands", dir.file("missing.json").string()}, "missing.json"},
      {{"scene-bands", kPaperBox, "--bands", "400:705:10"}, "--bands"},
      {{"scene-bands", kPaperBox, "--bands", "400:700:10", "--bands-file", dir.file("plan.json").string()}, "--bands-file"},
      {{"scene-bands", kPaperBox, "--bands-file", dir.file("plan.json").string()}, "plan.json: edges_nm[2]"},
      {{"scene-bands", kPaperBox, "--bands-file", dir.file("plan_um.json").string()}, "visible range"},
      {{"scene-bands", dir.file("bad_source.json").string()}, "spectra.x"},
      {{"scene-bands", dir.file("extra_key.json").string()}, "bands"},
  });
}

// ---- export-meshes ------------------------------------------------------------------------------------

TEST(ExportMeshes, WritesTheTracersTrianglesForEveryObjectAndLight) {
  test::TempDir dir;
  const auto r = run_chromatrace({"export-meshes", kPaperBox, (dir.path() / "meshes").string() + "/", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json index = json::parse(r.out);
  ASSERT_EQ(index["objects"].size(), 7u);
  ASSERT_EQ(index["lights"].size(), 1u);
  EXPECT_EQ(index["lights"][0]["id"], 8);
  EXPECT_EQ(index["objects"][5]["smooth"], true);

  const Scene scene = load_scene(kPaperBox);
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  std::vector<json> entries(index["objects"].begin(), index["objects"].end());
  entries.push_back(index["lights"][0]);
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const TriangleMesh read = read_ply(dir.path() / "meshes" / entries[i]["file"].get<std::string>());
    // Positions and triangles bit for bit (doubles survive the PLY); normals are renormalised on reading.
    EXPECT_EQ(read.positions, meshes[i].positions) << entries[i]["name"];
    EXPECT_EQ(read.triangles, meshes[i].triangles) << entries[i]["name"];
    ASSERT_EQ(read.normals.size(), meshes[i].normals.size()) << entries[i]["name"];
    for (std::size_t v = 0; v < read.normals.size(); ++v) EXPECT_LT((read.normals[v] - meshes[i].normals[v]).norm(), 1e-15);
    EXPECT_EQ(entries[i]["triangles"], meshes[i].triangles.size());
  }
}

// With --uvs every corner keeps the tracer's (u, v) (corner_uvs): a vertex on a seam or a pole is written once per
// (u, v), so the triangles are the same in space but may index more vertices.
TEST(ExportMeshes, UvsAreTheTracersCornerCoordinates) {
  test::TempDir dir;
  const auto r = run_chromatrace({"export-meshes", kPaperBox, dir.path().string(), "--uvs", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json index = json::parse(r.out);
  const Scene scene = load_scene(kPaperBox);
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const TriangleMesh read = read_ply(dir.path() / index["objects"][i]["file"].get<std::string>());
    const std::vector<std::array<Vec2, 3>> uvs = corner_uvs(scene.objects[i].shape);
    ASSERT_EQ(read.triangles.size(), meshes[i].triangles.size());
    ASSERT_EQ(read.uvs.size(), read.positions.size());
    for (std::size_t t = 0; t < read.triangles.size(); ++t)
      for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_EQ(read.positions[read.triangles[t][c]], meshes[i].positions[meshes[i].triangles[t][c]]);
        EXPECT_EQ(read.uvs[read.triangles[t][c]], uvs[t][c]) << scene.objects[i].name << " triangle " << t;
      }
    const std::size_t split = read.positions.size() - meshes[i].positions.size();
    // A quad needs no extra vertex; a tessellated sphere needs its seam's and its poles' copies.
    if (scene.objects[i].name == "sphere") {
      EXPECT_GT(split, 0u);
    }
    if (std::holds_alternative<QuadShape>(scene.objects[i].shape)) {
      EXPECT_EQ(split, 0u) << scene.objects[i].name;
    }
  }
}

TEST(ExportMeshes, BadInputGetsExitTwoAndOneLine) {
  test::TempDir dir;
  write_text(dir.file("a_file"), "x");
  expect_bad_input({
      {{"export-meshes", dir.file("missing.json").string(), dir.path().string()}, "missing.json"},
      {{"export-meshes", kPaperBox, dir.file("a_file").string()}, "a_file: exists and is not a directory"},
      {{"export-meshes", kPaperBox, (dir.path() / "no/such/dir").string()}, "does not exist"},
      {{"export-meshes", kPaperBox}, "directory"},
  });
}

// ---- assemble -----------------------------------------------------------------------------------------

// Two Cycles-like multilayer renders ("L.<pass>.<channel>") holding bands 0-2 and band 3 of a 4-band plan.
// Per pixel, channel c of group g scales the pass values by f = (1 + c) · (1 + 10 g) · (1 + x + 2y), and the
// passes make every family sum exactly: Emit f, DiffDir 2f × DiffCol 0.5, DiffInd 4f × 0.25, GlossDir f × 1,
// GlossInd 0.5f × 2, so Combined = Combined_a = 5f.
class Assemble : public ::testing::Test {
 protected:
  static constexpr int kW = 3, kH = 2;

  void SetUp() override {
    for (int g = 0; g < 2; ++g) write_group(g, 1.0f);
    manifest_ = {
        {"format", "chromatrace-assemble/1"},
        {"edges_nm", {400, 450, 500, 550, 600}},
        {"view_layer", "L"},
        {"bands",
         {{{"channel", "R"}, {"files", {{"main", "g0.exr"}}}},
          {{"channel", "G"}, {"files", {{"main", "g0.exr"}}}},
          {{"channel", "B"}, {"files", {{"main", "g0.exr"}}}},
          {{"channel", "R"}, {"files", {{"main", "g1.exr"}}}}}},
        {"total", {{{"passes", {"Combined"}}}}},
        {"components",
         {{{"name", "emission"}, {"terms", {{{"passes", {"Emit"}}}}}},
          {{"name", "diffuse_direct"}, {"terms", {{{"passes", {"DiffDir", "DiffCol"}}}}}},
          {{"name", "diffuse_indirect"}, {"terms", {{{"passes", {"DiffInd", "DiffCol2"}}}}}},
          {{"name", "glossy_direct"}, {"terms", {{{"passes", {"GlossDir"}}}}}},
          {{"name", "glossy_indirect"}, {"terms", {{{"passes", {"GlossInd", "GlossCol"}}}}}},
          {{"name", "light.a"}, {"terms", {{{"passes", {"Combined_a"}}}}}},
          {{"name", "bounce.0"}, {"terms", {{{"passes", {"Combined"}}}, {{"passes", {"Emit"}}, {"sign", -1}}}}},
          {{"name", "bounce.1"}, {"terms", {{{"passes", {"Emit"}}}}}}}},
        {"object_ids", {{"file", "g0.exr"}, {"channel", "L.IndexOB.X"}}},
        {"object_names", {{"1", "floor"}, {"2", "lamp"}}},
        {"attributes", {{"chromatrace.renderer", "test"}}}};
  }

  static float f(int g, int c, int x, int y) { return (1.0f + c) * (1.0f + 10.0f * g) * (1.0f + x + 2.0f * y); }

  void write_group(int g, float combined_factor) {
    std::vector<test::RawChannel> channels;
    const struct {
      const char* pass;
      float factor;
    } passes[] = {{"Emit", 1}, {"DiffDir", 2}, {"DiffCol", 0.5f}, {"DiffInd", 4}, {"DiffCol2", 0.25f},
                  {"GlossDir", 1}, {"GlossInd", 0.5f}, {"GlossCol", 2}, {"Combined", 5 * combined_factor},
                  {"Combined_a", 5}};
    for (const auto& p : passes)
      for (int c = 0; c < 3; ++c) {
        test::RawChannel ch{fmt_name(p.pass, "RGB"[c]), std::vector<float>(kW * kH), Imf::FLOAT};
        const bool colour = std::string(p.pass).find("Col") != std::string::npos;
        for (int y = 0; y < kH; ++y)
          for (int x = 0; x < kW; ++x) ch.values[y * kW + x] = colour ? p.factor : p.factor * f(g, c, x, y);
        channels.push_back(std::move(ch));
      }
    test::RawChannel ids{"L.IndexOB.X", {1, 1, 2, 0, 1, 1}};
    channels.push_back(ids);
    test::write_raw_exr(dir_.file(fmt::format("g{}.exr", g)), kW, kH, channels);
  }

  static std::string fmt_name(const char* pass, char channel) { return fmt::format("L.{}.{}", pass, channel); }

  fs::path write_manifest(const json& m) {
    const fs::path path = dir_.file("manifest.json");
    write_text(path, m.dump());
    return path;
  }


  test::TempDir dir_;
  json manifest_;
};

TEST_F(Assemble, FilesEveryBandAndComponentAndPassesInfoCheck) {
  const fs::path out = dir_.file("out.exr");
  const auto r = run_chromatrace({"assemble", write_manifest(manifest_).string(), "-o", out.string(), "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  SpectralExrReader reader(out);
  const SpectralExrInfo& info = reader.info();
  ASSERT_EQ(info.bands.size(), 4u);
  EXPECT_EQ(info.bands.edges(), (std::vector<double>{400, 450, 500, 550, 600}));
  EXPECT_EQ(info.object_names.at(2), "lamp");
  EXPECT_EQ(info.metadata.at("chromatrace.renderer"), "test");

  const std::vector<float> total = reader.read_layer(info.total());
  const std::vector<float> diffuse = reader.read_layer(info.layer("diffuse_direct", SpectralQuantity::S0));
  const std::vector<float> bounce0 = reader.read_layer(info.layer("bounce.0", SpectralQuantity::S0));
  const int group_of[] = {0, 0, 0, 1}, channel_of[] = {0, 1, 2, 0};
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int b = 0; b < 4; ++b) {
        const std::size_t i = static_cast<std::size_t>((y * kW + x) * 4 + b);
        const float v = f(group_of[b], channel_of[b], x, y);
        EXPECT_FLOAT_EQ(total[i], 5 * v) << x << "," << y << " band " << b;
        EXPECT_FLOAT_EQ(diffuse[i], v);
        EXPECT_FLOAT_EQ(bounce0[i], 4 * v);
      }
  std::vector<std::int32_t> ids(kW * kH);
  reader.read_object_ids(0, kH, ids);
  EXPECT_EQ(ids, (std::vector<std::int32_t>{1, 1, 2, 0, 1, 1}));

  const auto check = run_chromatrace({"info", "--check", out.string()});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

TEST_F(Assemble, GuidedBandsAreNamedInTheHeaderAndTheFileStillPassesInfoCheck) {
  // Band 3 (group 1) as rendered with few samples, guided by bands 0-2. The image is too small for any window to
  // hold the 16 lit pixels a ratio needs, so every value stays as assembled: what is checked here is the plumbing
  // (the header, the sums, the manifest's checks); core_tests and tracer_tests check the reconstruction itself.
  manifest_["guided"] = {{"bands", {3}}};
  const fs::path out = dir_.file("out.exr");
  const auto r = run_chromatrace({"assemble", write_manifest(manifest_).string(), "-o", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("1 of 4 bands guided"), std::string::npos) << r.err;
  SpectralExrReader reader(out);
  const json guided = json::parse(reader.info().metadata.at("chromatrace.guided"));
  EXPECT_EQ(guided["guided"], json::parse(R"([{"band": 3, "nm": [550.0, 600.0]}])"));
  EXPECT_EQ(guided["guides"].size(), 3u);
  EXPECT_EQ(guided["refused"], json::array());
  EXPECT_FALSE(guided.contains("adaptive"));  // fixed samples unless the manifest says otherwise
  const std::vector<float> total = reader.read_layer(reader.info().total());
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) EXPECT_FLOAT_EQ(total[static_cast<std::size_t>((y * kW + x) * 4 + 3)], 5 * f(1, 0, x, y));
  const auto check = run_chromatrace({"info", "--check", out.string()});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;

  // Guided bands rendered with Cycles' adaptive sampling: the header says so, with the threshold and the most samples.
  manifest_["guided"]["adaptive"] = {{"threshold", 0.01}, {"max_samples", 256}};
  const fs::path adaptive = dir_.file("adaptive.exr");
  ASSERT_EQ(run_chromatrace({"assemble", write_manifest(manifest_).string(), "-o", adaptive.string(), "-q"}).exit_code, 0);
  EXPECT_EQ(json::parse(SpectralExrReader(adaptive).info().metadata.at("chromatrace.guided"))["adaptive"],
            json::parse(R"({"threshold": 0.01, "max_samples": 256})"));
  // A bad guided record: one line naming the field, exit 2, no output.
  const auto refused = [&](const std::string& field, const json& value, const std::string& message) {
    json manifest = manifest_;
    manifest["guided"][field] = value;
    const auto bad = run_chromatrace({"assemble", write_manifest(manifest).string(), "-o", dir_.file("bad.exr").string()});
    EXPECT_EQ(bad.exit_code, 2) << value;
    EXPECT_EQ(line_count(bad.err), 1) << bad.err;
    EXPECT_NE(bad.err.find(message), std::string::npos) << bad.err;
    EXPECT_FALSE(fs::exists(dir_.file("bad.exr")));
  };
  manifest_["guided"].erase("adaptive");
  refused("adaptive", {{"threshold", 0}, {"max_samples", 256}}, "guided.adaptive.threshold");
  refused("adaptive", {{"threshold", 0.01}}, "guided.adaptive");
  refused("adaptive", {{"threshold", 0.01}, {"max_samples", 0}}, "guided.adaptive.max_samples");
  refused("bands", json::array(), "guided.bands: names no band");
  refused("bands", {0, 1, 2, 3}, "guided.bands: names every band");
  refused("bands", {3, 3}, "guided.bands[1]: band 3 given twice");
  refused("bands", {4}, "guided.bands[0]");
}

TEST_F(Assemble, FloatRoundingBetweenPassesIsFoldedSoInfoCheckHolds) {
  write_group(0, 1.0f + 3e-6f);  // Combined off by a few float roundings, as Cycles' separate accumulations are
  const fs::path out = dir_.file("out.exr");
  const auto r = run_chromatrace({"assemble", write_manifest(manifest_).string(), "-o", out.string(), "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto check = run_chromatrace({"info", "--check", out.string()});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

TEST_F(Assemble, ComponentsThatDoNotSumToTheTotalAreRefused) {
  write_group(1, 1.2f);
  const fs::path out = dir_.file("out.exr");
  const auto r = run_chromatrace({"assemble", write_manifest(manifest_).string(), "-o", out.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("path types sum to"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pixel (0, 0), band 3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// A NaN a renderer wrote passes no sum check (it compares false with everything): it is refused by name.
TEST_F(Assemble, ANonFiniteValueIsRefusedNamingFileChannelAndPixel) {
  std::vector<test::RawChannel> channels;
  for (const char* pass : {"Emit", "DiffDir", "DiffCol", "DiffInd", "DiffCol2", "GlossDir", "GlossInd", "GlossCol", "Combined", "Combined_a"})
    for (const char c : {'R', 'G', 'B'}) channels.push_back({fmt_name(pass, c), std::vector<float>(kW * kH, 1.0f), Imf::FLOAT});
  channels[0].values[4] = std::numeric_limits<float>::quiet_NaN();  // L.Emit.R at pixel (1, 1)
  channels.push_back({"L.IndexOB.X", {1, 1, 2, 0, 1, 1}, Imf::FLOAT});
  test::write_raw_exr(dir_.file("g1.exr"), kW, kH, channels);
  const fs::path out = dir_.file("out.exr");
  const auto r = run_chromatrace({"assemble", write_manifest(manifest_).string(), "-o", out.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("g1.exr: channel L.Emit.R: value nan at pixel (1, 1) is not finite"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Assemble, BadManifestGetsExitTwoAndOneLineNamingTheField) {
  const fs::path out = dir_.file("out.exr");
  auto with = [&](const std::string& name, auto edit) {
    json m = manifest_;
    edit(m);
    const fs::path path = dir_.file(name);
    write_text(path, m.dump());
    return path.string();
  };
  const std::string ok = write_manifest(manifest_).string();
  expect_bad_input(
      {
          {{"assemble", with("f.json", [](json& m) { m["format"] = "x"; }), "-o", out.string()}, "f.json: format"},
          {{"assemble", with("e.json", [](json& m) { m["edges_nm"] = {400, 450}; }), "-o", out.string()},
           "e.json: bands: 4 entries for 1 bands"},
          {{"assemble", with("c.json", [](json& m) { m["components"][0]["name"] = "sparkle"; }), "-o", out.string()},
           "components[0].name"},
          {{"assemble", with("p.json", [](json& m) { m["total"][0]["passes"] = {"Shine"}; }), "-o", out.string()},
           "g0.exr: no channel L.Shine.R"},
          {{"assemble", with("m.json", [](json& m) { m["bands"][3]["files"]["main"] = "gone.exr"; }), "-o", out.string()},
           "gone.exr"},
          {{"assemble", with("k.json", [](json& m) { m["total"][0]["file"] = "k1"; }), "-o", out.string()},
           "total[0].file"},
          {{"assemble", with("u.json", [](json& m) { m["extra"] = 1; }), "-o", out.string()}, "u.json: extra"},
          {{"assemble", with("n.json", [](json& m) { m["bands"][1]["files"] = {{"k1", "g0.exr"}}; }), "-o", out.string()},
           "total[0]: bands[1].files has no \"main\""},
          {{"assemble", ok, "-o", (dir_.path() / "no/dir/out.exr").string()}, "does not exist"},
          {{"assemble", (dir_.path() / "missing.json").string(), "-o", out.string()}, "missing.json"},
      },
      out);
}

TEST_F(Assemble, NeverWritesOverItsManifestOrARenderItReads) {
  const fs::path manifest = write_manifest(manifest_);
  fs::create_symlink(manifest, dir_.file("link.json"));
  fs::create_hard_link(dir_.file("g1.exr"), dir_.file("hard.exr"));
  const struct {
    fs::path output;
    fs::path input;
  } cases[] = {{manifest, manifest},
               {dir_.path() / "." / "manifest.json", manifest},
               {dir_.file("link.json"), manifest},
               {dir_.file("g0.exr"), dir_.file("g0.exr")},
               {dir_.file("hard.exr"), dir_.file("g1.exr")}};
  for (const auto& c : cases) {
    const std::string before = read_bytes(c.input);
    const auto r = run_chromatrace({"assemble", manifest.string(), "-o", c.output.string(), "--quiet"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.output.string() + ": is the same file as the input " + c.input.string()), std::string::npos)
        << r.err;
    EXPECT_EQ(read_bytes(c.input), before) << c.output;
  }
}

}  // namespace
}  // namespace ct
