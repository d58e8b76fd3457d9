// SPDX-License-Identifier: Apache-2.0
// `chromatrace study` on the paper box at a small size: its files, the laws its numbers must follow (Monte Carlo
// noise falls as 1/√samples; truncating the bounces or coarsening the bands adds a systematic error that noise
// cannot hide), the Pareto front and the chart axes; bad input.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/core.h>
#include <opencv2/imgcodecs.hpp>

#include "core/json_input.h"
#include "study/charts.h"
#include "plan/plan.h"
#include "study/study.h"
#include "tests/cli/run_command.h"
#include "core/statistics.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::run_chromatrace;

const fs::path kBox = fs::path(CHROMATRACE_SOURCE_DIR) / "scenes/paper/box.json";

fs::path fresh_dir(const std::string& tag) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("ct-study-{}-{}", ::getpid(), tag);
  fs::remove_all(dir);
  return dir;
}

Json read_json(const fs::path& file) {
  std::ifstream in(file);
  return Json::parse(in);
}

const Json& setting(const Json& study, const std::string& name) {
  for (const Json& s : study.at("settings"))
    if (s.at("name") == name) return s;
  throw std::runtime_error("no setting " + name);
}

// The paper box at 32×32 pixels: uniform 3 and 12 bands, a plan fitted for ΔE00 1, 16 samples against the
// scene's 256, one bounce against the scene's 8, the continuous mode. One study (about a minute) serves every
// check below, so they are one test.
void check_files(const fs::path& dir, const Json& study) {
  EXPECT_EQ(study.at("format"), "chromatrace-study/1");
  const Json& settings = study.at("settings");
  std::vector<std::string> names;
  for (const Json& s : settings) {
    names.push_back(s.at("name"));
    EXPECT_TRUE(s.at("ok").get<bool>()) << s.dump();
  }
  EXPECT_EQ(names, (std::vector<std::string>{"tracer-base", "tracer-bands-3", "tracer-bands-12", "tracer-fitted-1",
                                             "tracer-samples-16", "tracer-bounces-1", "tracer-mode-continuous"}));
  EXPECT_EQ(study.at("reference").at("band_count"), 80);  // 380–780 nm in 5 nm bands
  for (const char* chart : {"error_vs_cost.png", "p95_vs_cost.png", "systematic_vs_cost.png", "structure_vs_cost.png"}) {
    const cv::Mat png = cv::imread((dir / chart).string());
    ASSERT_FALSE(png.empty()) << chart;
    EXPECT_EQ(png.cols, 980);
    EXPECT_EQ(png.rows, 640);
  }
  std::ifstream page(dir / "index.html");
  const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  for (const std::string& n : names) EXPECT_NE(html.find(n), std::string::npos) << n;
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  // Each setting's analysis report is there to follow.
  EXPECT_TRUE(fs::exists(dir / "runs" / "tracer-bands-3" / "analysis" / "report.html"));
}

void check_noise_law(const Json& study) {
  // 16 samples against the base's 256: √16 = 4 times the noise, within three standard errors of the ratio.
  const Json& few = setting(study, "tracer-samples-16").at("error");
  const Json& base = setting(study, "tracer-base").at("error");
  const double a = few.at("noise_rms_de00"), sa = few.at("noise_rms_de00_se");
  const double b = base.at("noise_rms_de00"), sb = base.at("noise_rms_de00_se");
  const double ratio = a / b, se = ratio * std::hypot(sa / a, sb / b);
  EXPECT_NEAR(ratio, 4.0, kSigmasOneCheck * se) << a << " / " << b;
  EXPECT_LT(se, 0.25 * ratio);  // the test has power
}

void check_systematic(const Json& study) {
  auto interval = [&](const std::string& name) {
    const Json& i = setting(study, name).at("error").at("systematic_rms_de00_interval");
    return std::pair<double, double>{i[0], i[1]};
  };
  // One bounce drops the light that arrives after more (about half the box's luminance); 3 bands cannot hold
  // its colours. Both are systematic: their intervals lie above the scene's own settings' and the finer bands'.
  EXPECT_GT(interval("tracer-bounces-1").first, interval("tracer-base").second);
  EXPECT_GT(interval("tracer-bands-3").first, interval("tracer-bands-12").second);
  // Changing only samples leaves the systematic part that of the base, within both intervals.
  const auto few = interval("tracer-samples-16"), base = interval("tracer-base");
  EXPECT_LE(few.first, base.second);
  EXPECT_LE(base.first, few.second);
}

void check_pareto(const Json& study) {
  const Json& settings = study.at("settings");
  for (const Json& a : settings) {
    bool beaten = false;
    for (const Json& b : settings) {
      const double ca = a.at("cost").at("cpu_seconds"), cb = b.at("cost").at("cpu_seconds");
      const double ea = a.at("error").at("mean_de00"), eb = b.at("error").at("mean_de00");
      beaten = beaten || (cb <= ca && eb <= ea && (cb < ca || eb < ea));
    }
    EXPECT_EQ(a.at("pareto").get<bool>(), !beaten) << a.at("name");
  }
}

TEST(Study, PaperBoxAtCiSize) {
  const fs::path dir = fresh_dir("box");
  const test::CommandResult r =
      run_chromatrace({"study", kBox.string(), "-o", dir.string(), "--resolution", "32x32", "--bands", "3,12",
                       "--fitted", "1", "--samples", "16", "--bounces", "1", "--modes", "continuous", "--no-plan",
                       "--reference-spp", "1024", "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json study = read_json(dir / "study.json");
  {
    SCOPED_TRACE("files");
    check_files(dir, study);
  }
  {
    SCOPED_TRACE("noise law");
    check_noise_law(study);
  }
  {
    SCOPED_TRACE("systematic errors");
    check_systematic(study);
  }
  {
    SCOPED_TRACE("Pareto front");
    check_pareto(study);
  }
  fs::remove_all(dir);
}

// The planned setting is plan's for its renderer: for Cycles its band groups each take the samples plan gives them
// (its cycles_samples, which the band file then carries); the tracer's takes plan's paths per pixel.
TEST(Study, PlannedCyclesSettingTakesEachBandGroupsSamples) {
  const Scene scene = load_scene(kBox);
  study::StudyOptions options;
  options.renderers = {series::Renderer::Tracer, series::Renderer::Cycles};
  options.threads = 2;
  const std::vector<study::Setting> settings = study::make_settings(scene, options);
  plan::PlanOptions po;
  po.threads = 2;
  const plan::Plan cycles = plan::make_plan(scene, po);
  po.renderer = plan::Renderer::Tracer;
  const plan::Plan tracer = plan::make_plan(scene, po);
  int found = 0;
  for (const study::Setting& s : settings) {
    if (s.knob != "planned") continue;
    ++found;
    if (s.renderer == series::Renderer::Cycles) {
      ASSERT_FALSE(cycles.cycles_samples.empty());
      EXPECT_EQ(s.cycles_samples, cycles.cycles_samples);
      EXPECT_EQ(s.samples, *std::max_element(cycles.cycles_samples.begin(), cycles.cycles_samples.end()));
      EXPECT_NE(s.value.find("samples per band group"), std::string::npos) << s.value;
      EXPECT_EQ(s.bands, cycles.bands);
    } else {
      EXPECT_TRUE(s.cycles_samples.empty());
      EXPECT_EQ(s.samples, tracer.samples);
    }
  }
  EXPECT_EQ(found, 2);

  // And guided (--guided 0.125): the group of most samples keeps them and guides the others at an eighth of them
  // (rounded up), rendered with adaptive sampling at Cycles' default threshold.
  options.guided_fraction = 0.125;
  int guided = 0;
  for (const study::Setting& s : study::make_settings(scene, options)) {
    if (s.knob != "guided") continue;
    ++guided;
    EXPECT_EQ(s.renderer, series::Renderer::Cycles);
    const auto most = std::max_element(cycles.cycles_samples.begin(), cycles.cycles_samples.end());
    const auto guide = static_cast<std::size_t>(most - cycles.cycles_samples.begin());
    ASSERT_EQ(s.cycles_samples.size(), cycles.cycles_samples.size());
    for (std::size_t g = 0; g < s.cycles_samples.size(); ++g) {
      EXPECT_EQ(s.cycles_samples[g], g == guide ? *most : (*most + 7) / 8) << g;
      EXPECT_EQ(std::count(s.cycles_guided_groups.begin(), s.cycles_guided_groups.end(), g), g == guide ? 0 : 1) << g;
    }
    EXPECT_EQ(s.cycles_guided_threshold, 0.01);
    EXPECT_EQ(s.bands, cycles.bands);
  }
  EXPECT_EQ(guided, 1);
}

// A chart's axis holds at least two of its ticks: settings between 3.4 and 7.8 CPU seconds, whose padded range
// holds only the 5 of 1, 2 and 5 times a power of ten, get an axis from 1 to 10 with 1, 2, 5 and 10 on it (it used to
// keep 3.1–8.5 and draw the powers of ten just outside, off the frame).
TEST(StudyCharts, AnAxisReachesItsTicks) {
  for (const std::vector<double>& values : {std::vector<double>{3.38, 7.83}, std::vector<double>{0.004, 90.0},
                                            std::vector<double>{5.0}, std::vector<double>{}}) {
    const study::LogRange r = study::log_range(values, 1e-3);
    ASSERT_GE(r.ticks.size(), 2u);
    for (double t : r.ticks) {
      EXPECT_GE(t, r.lo * (1 - 1e-9));
      EXPECT_LE(t, r.hi * (1 + 1e-9));
    }
    for (double v : values) {
      EXPECT_GE(v, r.lo);
      EXPECT_LE(v, r.hi);
    }
  }
  const study::LogRange narrow = study::log_range({3.38, 7.83}, 1e-3);
  EXPECT_DOUBLE_EQ(narrow.lo, 1.0);
  EXPECT_DOUBLE_EQ(narrow.hi, 10.0);
  EXPECT_EQ(narrow.ticks, (std::vector<double>{1, 2, 5, 10}));
}

TEST(StudyPareto, MarksExactlyTheUndominated) {
  std::vector<study::SettingResult> s(5);
  const double cost[] = {1, 2, 3, 2, 4}, error[] = {5, 3, 1, 4, 1};
  for (std::size_t i = 0; i < s.size(); ++i) {
    s[i].ok = true;
    s[i].cpu_s = cost[i];
    s[i].mean = error[i];
  }
  study::mark_pareto_front(s);
  EXPECT_TRUE(s[0].pareto);
  EXPECT_TRUE(s[1].pareto);
  EXPECT_TRUE(s[2].pareto);
  EXPECT_FALSE(s[3].pareto);  // (2, 4) is beaten by (2, 3)
  EXPECT_FALSE(s[4].pareto);  // (4, 1) is beaten by (3, 1)
}

TEST(StudyCommand, BadInputIsOneLineAndExit2) {
  const fs::path dir = fresh_dir("bad");
  const std::vector<std::vector<std::string>> cases = {
      {"--bands", "0"}, {"--renderers", "vray"}, {"--modes", "hero"}, {"--fitted", "-1"}, {"--camera", "nope"},
      {"--guided", "1.5"}, {"--guided", "0.125"}, {"--guided", "0.125", "--renderers", "cycles", "--no-plan"}};
  for (const auto& extra : cases) {
    std::vector<std::string> args = {"study", kBox.string(), "-o", dir.string(), "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    const test::CommandResult r = run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 2) << extra[0] << ": " << r.err;
    EXPECT_NE(r.err.find(extra[0] == "--camera" ? "nope" : extra[0]), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir)) << extra[0];
  }
}

}  // namespace
}  // namespace ct
