// SPDX-License-Identifier: Apache-2.0
// Assembly of a spectral EXR from band-multiplexed renders (core/assembly.h): the manifest read into its
// typed form, the summing families, and the per-pixel reconciliation of each family with the total, on
// hand-computed numbers (binary fractions, so that every expected value is exact).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/assembly.h"
#include "core/error.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

// ---- summing_families -----------------------------------------------------------------------------

TEST(AssemblyFamilies, PathTypesLightGroupsAndBouncesInThatOrder) {
  const std::vector<std::string> components = {"bounce.0",       "light.a",       "emission",      "diffuse_direct",
                                               "diffuse_indirect", "glossy_direct", "glossy_indirect", "light.b",
                                               "bounce.1"};
  const std::vector<SummingFamily> families = summing_families(components);
  ASSERT_EQ(families.size(), 3u);
  EXPECT_EQ(families[0].name, "path types");
  EXPECT_EQ(families[0].members, (std::vector<std::size_t>{2, 3, 4, 5, 6}));
  EXPECT_EQ(families[1].name, "light groups");
  EXPECT_EQ(families[1].members, (std::vector<std::size_t>{1, 7}));
  EXPECT_EQ(families[2].name, "bounces");
  EXPECT_EQ(families[2].members, (std::vector<std::size_t>{0, 8}));
}

TEST(AssemblyFamilies, IncompletePathTypesAreNoFamily) {
  // Without glossy_indirect the path types cannot add up to the total, so nothing is held to it.
  const std::vector<SummingFamily> families =
      summing_families({"emission", "diffuse_direct", "diffuse_indirect", "glossy_direct", "light.a"});
  ASSERT_EQ(families.size(), 1u);
  EXPECT_EQ(families[0].name, "light groups");
  EXPECT_TRUE(summing_families({}).empty());
}

// ---- reconcile_families ---------------------------------------------------------------------------

SummingFamily family(std::vector<std::size_t> members) { return {"test family", std::move(members)}; }

TEST(AssemblyReconcile, FamilyThatSumsToTheTotalIsUnchanged) {
  std::vector<double> v = {1.0, 2.0, 2.0};
  const std::vector<SummingFamily> families = {family({0, 1, 2})};
  EXPECT_FALSE(reconcile_families(5.0, v, families, 1e-4));
  EXPECT_EQ(v, (std::vector<double>{1.0, 2.0, 2.0}));
}

TEST(AssemblyReconcile, ResidualGoesToTheLargestMember) {
  // total 10.25, sum 10: residual +0.25 is within 0.02 · (10.25 + 10) = 0.405, and lands on the 6.
  const std::vector<SummingFamily> families = {family({0, 1, 2})};
  std::vector<double> v = {1.0, 6.0, 3.0};
  EXPECT_FALSE(reconcile_families(10.25, v, families, 0.02));
  EXPECT_EQ(v, (std::vector<double>{1.0, 6.25, 3.0}));
  v = {1.0, 6.0, 3.0};
  EXPECT_FALSE(reconcile_families(9.75, v, families, 0.02));
  EXPECT_EQ(v, (std::vector<double>{1.0, 5.75, 3.0}));
}

TEST(AssemblyReconcile, LargestIsByMagnitudeAndTheFirstOfEquals) {
  // Bounce components are differences of renders and may be negative: -5 is the largest here.
  // total -1.5, sum -2: residual +0.5 within 0.1 · (1.5 + 8) = 0.95.
  const std::vector<SummingFamily> families = {family({0, 1, 2})};
  std::vector<double> v = {2.0, -5.0, 1.0};
  EXPECT_FALSE(reconcile_families(-1.5, v, families, 0.1));
  EXPECT_EQ(v, (std::vector<double>{2.0, -4.5, 1.0}));

  std::vector<double> tie = {3.0, 3.0};
  EXPECT_FALSE(reconcile_families(6.5, tie, std::vector<SummingFamily>{family({0, 1})}, 0.1));
  EXPECT_EQ(tie, (std::vector<double>{3.5, 3.0}));
}

TEST(AssemblyReconcile, MoreThanToleranceTimesMagnitudeIsAMismatch) {
  // Residual 0.25 against tolerance · 20.25: refused at 0.01 (0.2025), accepted at 0.0125 (0.253125).
  const std::vector<SummingFamily> families = {family({0, 1, 2})};
  std::vector<double> v = {1.0, 6.0, 3.0};
  const std::optional<FamilyMismatch> mismatch = reconcile_families(10.25, v, families, 0.01);
  ASSERT_TRUE(mismatch);
  EXPECT_EQ(mismatch->family, 0u);
  EXPECT_EQ(mismatch->sum, 10.0);
  v = {1.0, 6.0, 3.0};
  EXPECT_FALSE(reconcile_families(10.25, v, families, 0.0125));
  EXPECT_EQ(v[1], 6.25);
}

TEST(AssemblyReconcile, EachFamilyOnItsOwnAndTheFirstMismatchIsReported) {
  const std::vector<SummingFamily> families = {family({0, 1}), family({2, 3})};
  // Total 4: {1, 3} sums exactly; {2, 2.25} misses by 0.25 and is reconciled on its own largest member.
  std::vector<double> v = {1.0, 3.0, 2.0, 2.25, 7.0};
  EXPECT_FALSE(reconcile_families(4.0, v, families, 0.1));
  EXPECT_EQ(v, (std::vector<double>{1.0, 3.0, 2.0, 2.0, 7.0}));  // component 4 is in no family: untouched

  // With tolerance 0.01 the second family (off by 0.25 of magnitude 8.25) is refused, with its sum.
  v = {1.0, 3.0, 2.0, 2.25, 7.0};
  std::optional<FamilyMismatch> mismatch = reconcile_families(4.0, v, families, 0.01);
  ASSERT_TRUE(mismatch);
  EXPECT_EQ(mismatch->family, 1u);
  EXPECT_EQ(mismatch->sum, 4.25);

  // When both miss, the first is the one reported.
  v = {1.0, 2.0, 2.0, 2.25, 7.0};
  mismatch = reconcile_families(4.0, v, families, 0.01);
  ASSERT_TRUE(mismatch);
  EXPECT_EQ(mismatch->family, 0u);
  EXPECT_EQ(mismatch->sum, 3.0);
}

TEST(AssemblyReconcile, SingleMemberBecomesTheTotal) {
  // total 2.5, member 2.25: residual 0.25 within 0.1 · 4.75.
  std::vector<double> v = {2.25};
  EXPECT_FALSE(reconcile_families(2.5, v, std::vector<SummingFamily>{family({0})}, 0.1));
  EXPECT_EQ(v[0], 2.5);
}

TEST(AssemblyReconcile, ZeroTotal) {
  const std::vector<SummingFamily> families = {family({0, 1})};
  // Black pixels pass even with tolerance 0, and members that cancel are left as they are.
  std::vector<double> v = {0.0, 0.0};
  EXPECT_FALSE(reconcile_families(0.0, v, families, 0.0));
  EXPECT_EQ(v, (std::vector<double>{0.0, 0.0}));
  v = {1.0, -1.0};
  EXPECT_FALSE(reconcile_families(0.0, v, families, 1e-4));
  EXPECT_EQ(v, (std::vector<double>{1.0, -1.0}));
  // A component where the total is black is refused: its residual is all of its magnitude.
  v = {1e-3, 0.0};
  const std::optional<FamilyMismatch> mismatch = reconcile_families(0.0, v, families, 1e-4);
  ASSERT_TRUE(mismatch);
  EXPECT_EQ(mismatch->sum, 1e-3);
  // Below the absolute floor of 1e-30 a residual is rounding whatever its relative size.
  v = {1e-31, 0.0};
  EXPECT_FALSE(reconcile_families(0.0, v, families, 1e-4));
  EXPECT_EQ(v, (std::vector<double>{0.0, 0.0}));
}

TEST(AssemblyReconcile, NaNIsNotRefusedButCarriedIntoTheLargestMember) {
  // A NaN residual fails no comparison, so it is added where a residual would go.
  const std::vector<SummingFamily> families = {family({0, 1})};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> v = {1.0, 2.0};
  EXPECT_FALSE(reconcile_families(nan, v, families, 1e-4));
  EXPECT_EQ(v[0], 1.0);
  EXPECT_TRUE(std::isnan(v[1]));
  // A NaN member never compares larger, so the first member, here the NaN itself, takes the residual.
  v = {nan, 2.0};
  EXPECT_FALSE(reconcile_families(2.0, v, families, 1e-4));
  EXPECT_TRUE(std::isnan(v[0]));
  EXPECT_EQ(v[1], 2.0);
}

// ---- read_assembly_manifest -----------------------------------------------------------------------

std::filesystem::path write_manifest(const test::TempDir& dir, const std::string& text) {
  const std::filesystem::path path = dir.file("manifest.json");
  std::ofstream(path) << text;
  return path;
}

// Two bands in R and G of one render, bounce.1 from a second render ("k1") of each band.
const char* const kManifest = R"({
  "format": "chromatrace-assemble/1", "edges_nm": [400, 500, 600], "view_layer": "L",
  "bands": [{"channel": "R", "files": {"main": "g0.exr", "k1": "sub/../k1.exr"}},
            {"channel": "G", "files": {"main": "g0.exr", "k1": "k1.exr"}}],
  "total": [{"passes": ["Combined"]}],
  "components": [{"name": "diffuse_direct", "terms": [{"passes": ["DiffDir", "DiffCol"]}]},
                 {"name": "bounce.1", "terms": [{"passes": ["Combined"]},
                                                {"file": "k1", "passes": ["Combined"], "sign": -1}]}],
  "object_ids": {"file": "ids.exr", "channel": "L.IndexOB.X"}, "object_names": {"3": "floor"},
  "attributes": {"chromatrace.renderer": "test"}
})";

TEST(AssemblyManifest, ResolvesFilesAndChannelsEachOnce) {
  test::TempDir dir;
  const AssemblyManifest m = read_assembly_manifest(write_manifest(dir, kManifest));
  EXPECT_EQ(m.bands.edges(), (std::vector<double>{400, 500, 600}));
  ASSERT_EQ(m.inputs.size(), 3u);
  EXPECT_EQ(m.inputs[0].path, dir.file("g0.exr"));
  EXPECT_EQ(m.inputs[1].path, dir.file("k1.exr"));  // "sub/../k1.exr" is the same file
  EXPECT_EQ(m.inputs[2].path, dir.file("ids.exr"));
  EXPECT_EQ(m.inputs[0].channels, (std::vector<std::string>{"L.Combined.R", "L.Combined.G", "L.DiffDir.R",
                                                            "L.DiffCol.R", "L.DiffDir.G", "L.DiffCol.G"}));
  EXPECT_EQ(m.inputs[1].channels, (std::vector<std::string>{"L.Combined.R", "L.Combined.G"}));

  ASSERT_EQ(m.total.size(), 2u);
  ASSERT_EQ(m.total[1].size(), 1u);
  EXPECT_EQ(m.total[1][0].input, 0u);
  EXPECT_EQ(m.total[1][0].channels, (std::vector<std::size_t>{1}));
  EXPECT_EQ(m.total[1][0].sign, 1.0);

  EXPECT_EQ(m.components, (std::vector<std::string>{"diffuse_direct", "bounce.1"}));
  const PassSum& bounce_g = m.component_sums[1][1];  // Combined − Combined(k1) in band 1
  ASSERT_EQ(bounce_g.size(), 2u);
  EXPECT_EQ(bounce_g[1].input, 1u);
  EXPECT_EQ(bounce_g[1].channels, (std::vector<std::size_t>{1}));
  EXPECT_EQ(bounce_g[1].sign, -1.0);
  EXPECT_EQ(m.component_sums[0][1][0].channels, (std::vector<std::size_t>{4, 5}));

  ASSERT_TRUE(m.object_ids);
  EXPECT_EQ(m.object_ids->input, 2u);
  EXPECT_EQ(m.inputs[2].channels[m.object_ids->channel], "L.IndexOB.X");
  EXPECT_EQ(m.object_names.at(3), "floor");
  EXPECT_EQ(m.attributes.at("chromatrace.renderer"), "test");
  EXPECT_EQ(m.sum_tolerance, 1e-4);  // the default
}

std::string error_of(const std::string& text) {
  test::TempDir dir;
  const std::filesystem::path path = write_manifest(dir, text);
  try {
    read_assembly_manifest(path);
  } catch (const InputError& e) {
    std::string message = e.what();
    const std::string prefix = path.string() + ": ";
    return message.starts_with(prefix) ? message.substr(prefix.size()) : "(no file name) " + message;
  }
  return "";
}

std::string with(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(AssemblyManifest, BadFieldIsOneLineNamingFileAndField) {
  EXPECT_EQ(error_of(with(kManifest, "\"diffuse_direct\"", "\"sparkle\"")),
            "components[0].name: \"sparkle\" is not one of emission, diffuse_direct, diffuse_indirect, glossy_direct, "
            "glossy_indirect, transmission_direct, transmission_indirect, light.<group>, bounce.<k>");
  EXPECT_EQ(error_of(with(kManifest, "\"sign\": -1", "\"sign\": 0")),
            "components[1].terms[1].sign: must be 1 or -1, got 0");
  EXPECT_EQ(error_of(with(kManifest, "[400, 500, 600]", "[400, 500]")),
            "bands: 2 entries for 1 bands (edges_nm has 2 edges)");
  EXPECT_EQ(error_of(with(kManifest, "\"k1\": \"k1.exr\"", "\"k2\": \"k1.exr\"")),
            "components[1].terms[1].file: bands[1].files has no \"k1\"");
  EXPECT_EQ(error_of(with(kManifest, "\"chromatrace.renderer\"", "\"renderer\"")),
            "attributes.renderer: attribute \"renderer\" must be named chromatrace.<key>");
}

}  // namespace
}  // namespace ct
