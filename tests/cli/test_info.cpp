// SPDX-License-Identifier: Apache-2.0
// `chromatrace info` end to end, through the real executable.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::run_chromatrace;

const fs::path kSamples = fs::path(CHROMATRACE_TEST_DATA) / "spectral_exr_samples";
const fs::path kD65 = kSamples / "spectral-exr_D65_emissive.exr";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Bad input: exit 2 and exactly one line on stderr, naming the file and whatever else is expected.
void expect_bad_input(const test::CommandResult& result, const std::vector<std::string>& parts) {
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  for (const std::string& part : parts) EXPECT_TRUE(contains(result.err, part)) << result.err << "\nlacks: " << part;
}

TEST(InfoCommand, DescribesTheD65Sample) {
  const test::CommandResult result = run_chromatrace({"info", kD65.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;
  EXPECT_TRUE(contains(result.out, "90 bands")) << result.out;
  EXPECT_TRUE(contains(result.out, "spectral emissive")) << result.out;
  EXPECT_TRUE(contains(result.out, "W.m^-2.sr^-1")) << result.out;
}

TEST(InfoCommand, JsonSaysEmissiveWithNinetyBands) {
  const test::CommandResult result = run_chromatrace({"info", "--json", kD65.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json info = nlohmann::json::parse(result.out);
  EXPECT_EQ(info["kind"], "spectral emissive");
  EXPECT_EQ(info["emissive"], true);
  EXPECT_EQ(info["reflective"], false);
  EXPECT_EQ(info["bands"]["count"], 90);
  EXPECT_EQ(info["bands"]["centres_nm"][36], 560.0);
  // The single pixel is D65 itself: 100 at 560 nm.
  EXPECT_EQ(info["statistics"]["mean"][36], 100.0);
  EXPECT_TRUE(info["non_finite"].empty());
}

TEST(InfoCommand, NamesTheKindOfEachSample) {
  const test::CommandResult macbeth =
      run_chromatrace({"info", "--json", (kSamples / "spectral-exr_Macbeth_reflective.exr").string()});
  ASSERT_EQ(macbeth.exit_code, 0) << macbeth.err;
  EXPECT_EQ(nlohmann::json::parse(macbeth.out)["kind"], "spectral reflective");
  const test::CommandResult polarised = run_chromatrace(
      {"info", "--threads", "2", "--quiet", (kSamples / "colour_Polarised_emissive_stokes.exr").string()});
  ASSERT_EQ(polarised.exit_code, 0) << polarised.err;
  EXPECT_TRUE(contains(polarised.out, "spectral emissive, polarised")) << polarised.out;
  EXPECT_TRUE(contains(polarised.out, "polarisationHandedness = right")) << polarised.out;
}

TEST(InfoCommand, CheckPassesWhenComponentsSum) {
  test::TempDir dir;
  const fs::path path = dir.file("sums.exr");
  test::write_image(path, test::make_component_image(12, 10, 4), 10);
  const test::CommandResult result = run_chromatrace({"info", "--check", path.string()});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;
  EXPECT_TRUE(contains(result.out, "7 components sum to the total")) << result.out;
  EXPECT_TRUE(contains(result.out, "object_id; names: 1 floor, 2 sphere, 10 lamp")) << result.out;
}

TEST(InfoCommand, CheckFailsOnAnAlteredComponent) {
  test::TempDir dir;
  const fs::path path = dir.file("altered.exr");
  test::ComponentImage image = test::make_component_image(12, 10, 4);
  image.components[5][(7 * 12 + 9) * image.layout.bands.size() + 1] += 0.01f;  // transmission_direct
  test::write_image(path, image, 10);
  expect_bad_input(run_chromatrace({"info", "--check", path.string()}),
                   {path.string(), "channel S0.421,250000nm", "pixel (9, 7)", "path types"});
  // Without --check the file is only described.
  EXPECT_EQ(run_chromatrace({"info", path.string()}).exit_code, 0);
}

TEST(InfoCommand, TruncatedFile) {
  test::TempDir dir;
  const fs::path whole = dir.file("whole.exr");
  test::write_image(whole, test::make_component_image(30, 30, 8), 30);
  for (std::size_t cut : {std::size_t{20}, fs::file_size(whole) / 2, fs::file_size(whole) - 1}) {
    const fs::path truncated = dir.file("cut-" + std::to_string(cut) + ".exr");
    test::write_truncated_copy(whole, truncated, cut);
    expect_bad_input(run_chromatrace({"info", truncated.string()}), {truncated.string()});
  }
}

TEST(InfoCommand, RgbFileIsDescribedButHasNothingToCheck) {
  test::TempDir dir;
  const fs::path path = dir.file("rgb.exr");
  test::write_raw_exr(path, 2, 2,
                      {test::constant_channel("R", 2, 2, 1), test::constant_channel("G", 2, 2, 1),
                       test::constant_channel("B", 2, 2, 1)});
  const test::CommandResult described = run_chromatrace({"info", "--json", path.string()});
  ASSERT_EQ(described.exit_code, 0) << described.err;
  EXPECT_EQ(nlohmann::json::parse(described.out)["kind"], "RGB");
  expect_bad_input(run_chromatrace({"info", "--check", path.string()}), {path.string(), "no spectral channels"});
}

TEST(InfoCommand, DuplicatedWavelengths) {
  test::TempDir dir;
  const fs::path path = dir.file("dup.exr");
  test::write_raw_exr(
      path, 2, 2, {test::constant_channel("S0.550,0nm", 2, 2, 1), test::constant_channel("S0.550,000000nm", 2, 2, 1)});
  expect_bad_input(run_chromatrace({"info", path.string()}),
                   {path.string(), "channel S0.550,000000nm: duplicated wavelength 550 nm (also S0.550,0nm)"});
}

TEST(InfoCommand, NonFiniteValues) {
  test::TempDir dir;
  const fs::path path = dir.file("nan.exr");
  test::ComponentImage image = test::make_component_image(5, 4, 9);
  const std::size_t bands = image.layout.bands.size();
  image.total[(1 * 5 + 4) * bands + 3] = NAN;
  image.total[(3 * 5 + 0) * bands + 3] = -INFINITY;
  test::write_image(path, image, 4);
  expect_bad_input(run_chromatrace({"info", path.string()}),
                   {path.string(), "2 NaN/Inf values in channel S0.485,000000nm (first at 4,1)"});
}

TEST(InfoCommand, MissingFile) {
  test::TempDir dir;
  const fs::path path = dir.file("absent.exr");
  expect_bad_input(run_chromatrace({"info", path.string()}), {path.string()});
}

TEST(InfoCommand, UsageErrors) {
  EXPECT_EQ(run_chromatrace({"info"}).exit_code, 2);
  EXPECT_EQ(run_chromatrace({"info", "--threads", "-1", kD65.string()}).exit_code, 2);
  EXPECT_EQ(run_chromatrace({"info", "--help"}).exit_code, 0);
}

}  // namespace
}  // namespace ct
