// SPDX-License-Identifier: Apache-2.0
// plan::render_warnings: what a render's bounce limit and samples leave out, said before rendering by check-scene and
// render (plan/render_check.h, docs/stability.md). Known answers: the share of the luminance that arrives after more
// than 2 bounces in the paper box, measured by the tracer at 2 bounces against the model's reference depth (and that
// depth against 64 bounces: what it leaves out is at most 1 %), within four standard errors of the Monte Carlo noise;
// a white box (every surface 90 %) needs more bounces than the paper box and warns at the paper box's count; 4 paths
// per pixel give the noise the warning predicts (two independent renders, within a factor 1.5 as plan's own samples
// test); the settings plan chooses are silent.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "core/cie.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/scene.h"
#include "core/spectrum.h"
#include "plan/plan.h"
#include "plan/render_check.h"
#include "reference_tracer/render.h"
#include "tests/cli/run_command.h"
#include "tests/plan/paper_box.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::kBox;
constexpr int kSize = 24;  // pixels a side, for the prediction's preview and the measurements alike

// The paper box as a document with absolute paths, at kSize × kSize pixels.
Json box_document() {
  Json doc = read_json(kBox);
  for_each_scene_path(doc, [&](Json& path) {
    if (fs::path(path.get<std::string>()).is_relative()) path = (kBox.parent_path() / path.get<std::string>()).string();
  });
  doc["camera"]["resolution"] = {kSize, kSize};
  return doc;
}

// Strong interreflection: every surface a flat 90 % (the stability table's "white" scene).
Json white_box_document() {
  Json doc = box_document();
  for (auto& [name, m] : doc["materials"].items()) {
    for (const char* key : {"reflectance", "diffuse"})
      if (m.contains(key)) m[key] = Json{{"constant", 0.9}};
    if (m.contains("specular")) m["specular"] = 0.05;
  }
  return doc;
}

using test::scene_of;

plan::SettingsPrediction predict(const Scene& scene, int max_bounces, int samples) {
  plan::PlanOptions options;
  options.threads = 2;
  return plan::predict_settings(scene, max_bounces, samples, options);
}

// The mean luminance (CIE 1931 Y, relative) after at most `max_bounces` events over the pixels whose 3 × 3
// neighbourhood shows no light (object ids, each pixel's centre: the same in every render of this size), as the
// warning's share is taken.
double surface_luminance(const Scene& scene, int max_bounces, std::uint64_t seed, int spp) {
  rt::RenderOptions o;
  o.samples = spp;
  o.max_bounces = max_bounces;
  o.seed = seed;
  o.components = rt::ComponentSelection::parse("none");
  o.threads = 2;
  o.progress = false;
  const rt::RenderedImage image = rt::render(scene, o);
  const std::size_t nb = image.bands.size();
  std::vector<double> y(nb);
  for (std::size_t b = 0; b < nb; ++b)
    y[b] = integral_of_product(cie::y_bar(), PiecewiseLinearSpectrum::constant(1.0), image.bands.lo(b), image.bands.hi(b));
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  double sum = 0;
  for (int py = 0; py < image.height; ++py)
    for (int px = 0; px < image.width; ++px) {
      bool near = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = px + dx, yy = py + dy;
          if (x >= 0 && yy >= 0 && x < image.width && yy < image.height)
            near = near || image.object_ids[static_cast<std::size_t>(yy * image.width + x)] >= first_light;
        }
      if (near) continue;
      const std::size_t p = static_cast<std::size_t>(py * image.width + px);
      for (std::size_t b = 0; b < nb; ++b) sum += y[b] * image.layers[0][p * nb + b];
    }
  return sum;
}

struct Share {
  double mean = 0, sd = 0;  // over the seeds; sd: of one estimate
  int n = 0;
};
// 1 − Y(k)/Y(reference) from renders with the same seed, over `n` seeds (each its own estimate).
Share measured_share(const Scene& scene, int k, int reference, int n, int spp) {
  std::vector<double> s;
  for (int i = 0; i < n; ++i) {
    const std::uint64_t seed = 101 + static_cast<std::uint64_t>(i);
    s.push_back(1 - surface_luminance(scene, k, seed, spp) / surface_luminance(scene, reference, seed, spp));
  }
  Share out;
  out.n = n;
  out.mean = std::accumulate(s.begin(), s.end(), 0.0) / n;
  for (double v : s) out.sd += (v - out.mean) * (v - out.mean);
  out.sd = std::sqrt(out.sd / (n - 1));
  return out;
}

TEST(RenderCheck, BounceShareIsTheTracersWithinItsNoise) {
  const Scene box = scene_of(box_document());
  const plan::SettingsPrediction p = predict(box, 2, box.render.samples);
  // The prediction comes from one preview of kSize² pixels at 16 paths per pixel, like each measured render: its
  // noise is one estimate's, the measurement's that over √n.
  const Share m = measured_share(box, 2, p.reference_bounces, 8, 16);
  const double tolerance = 4 * m.sd * std::sqrt(1.0 + 1.0 / m.n);
  std::fprintf(stderr, "paper box, 2 bounces: predicted share %.4f (reference %d bounces), measured %.4f ± %.4f\n",
               p.share_beyond, p.reference_bounces, m.mean, m.sd / std::sqrt(m.n));
  EXPECT_NEAR(p.share_beyond, m.mean, tolerance);
  // The reference depth leaves out at most 1 % of the light (64 bounces: the tracer's survival is below 0.95 per
  // event, so what is left beyond them is far below that).
  const Share tail = measured_share(box, p.reference_bounces, 64, 4, 16);
  std::fprintf(stderr, "beyond %d bounces: %.4f ± %.4f\n", p.reference_bounces, tail.mean, tail.sd / std::sqrt(tail.n));
  EXPECT_LE(tail.mean, 0.01 + 4 * tail.sd / std::sqrt(tail.n));
  // The warning names the share, the predicted ΔE00 and plan's bounce count.
  EXPECT_GT(p.bounce_de00, 1.0);
  EXPECT_GT(p.bounces_for_target, 2);
  plan::RenderRequest request = plan::scene_settings(box);
  request.max_bounces = 2;
  request.threads = 2;
  const std::vector<std::string> warnings = plan::render_warnings(box, request);
  const std::string expected =
      fmt::format("render.max_bounces 2 leaves {:.0f} % of the luminance unrendered (light after more than 2 bounces), a "
                  "predicted mean ΔE00 of {:.3g}; use {} bounces",
                  100 * p.share_beyond, p.bounce_de00, p.bounces_for_target);
  ASSERT_FALSE(warnings.empty());
  EXPECT_EQ(warnings[0].rfind(expected, 0), 0u) << warnings[0];
}

TEST(RenderCheck, WhiteBoxNeedsMoreBouncesThanThePaperBox) {
  const Scene box = scene_of(box_document()), white = scene_of(white_box_document());
  const plan::SettingsPrediction pb = predict(box, 2, box.render.samples);
  const plan::SettingsPrediction pw = predict(white, 2, white.render.samples);
  std::fprintf(stderr, "beyond 2 bounces: paper box %.3f (plan: %d bounces), white box %.3f (plan: %d bounces)\n",
               pb.share_beyond, pb.bounces_for_target, pw.share_beyond, pw.bounces_for_target);
  EXPECT_GT(pw.share_beyond, pb.share_beyond);
  EXPECT_GT(pw.bounces_for_target, pb.bounces_for_target);
  // At the paper box's own count the paper box is silent and the white box is not.
  const int k = pb.bounces_for_target;
  EXPECT_LE(predict(box, k, box.render.samples).bounce_de00, 1.0);
  EXPECT_GT(predict(white, k, white.render.samples).bounce_de00, 1.0);
}

TEST(RenderCheck, FewSamplesGiveThePredictedNoise) {
  const Scene box = scene_of(box_document());
  const plan::SettingsPrediction p = predict(box, box.render.max_bounces, 4);
  EXPECT_GT(p.noise_de00, 1.0);
  EXPECT_GT(p.samples_for_target, 4);
  // Two renders at 4 paths per pixel with independent seeds differ by √2 × the noise of one; the colours compare on
  // the scale of a converged render.
  const fs::path dir = fs::temp_directory_path() / ("ct-render-check-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto render = [&](std::uint64_t seed, int spp, const std::string& name) {
    rt::RenderOptions o;
    o.samples = spp;
    o.seed = seed;
    o.components = rt::ComponentSelection::parse("none");
    o.threads = 2;
    o.progress = false;
    rt::write_render(dir / name, box, rt::render(box, o));
    return dir / name;
  };
  const fs::path a = render(11, 4, "a.exr"), b = render(12, 4, "b.exr"), c = render(13, 256, "c.exr");
  const double noise = plan::measure_delta_e(a, b, box, "cie1931", c).mean / std::sqrt(2.0);
  std::fprintf(stderr, "4 paths per pixel: predicted noise %.2f, measured %.2f; %d for 1\n", p.noise_de00, noise,
               p.samples_for_target);
  EXPECT_LE(p.noise_de00, 1.5 * noise);
  EXPECT_GE(p.noise_de00, noise / 1.5);
  fs::remove_all(dir);
}

// check-scene lists the warnings, render prints them before rendering, each naming the setting as it was given (and
// with the prediction's figures whatever the thread count); the settings plan chooses are silent.
TEST(RenderCheck, CheckSceneAndRenderSayItAndPlansSettingsAreSilent) {
  const fs::path dir = fs::temp_directory_path() / ("ct-render-check-cli-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Json doc = box_document();
  doc["render"]["max_bounces"] = 2;
  doc["render"]["samples"] = 4;
  write_file_atomically(dir / "few.json", doc.dump(2));
  const auto check = test::run_chromatrace({"check-scene", (dir / "few.json").string()});
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_NE(check.out.find("warning    render.max_bounces 2 leaves "), std::string::npos) << check.out;
  EXPECT_NE(check.out.find("warning    render.samples 4 gives Monte Carlo noise of a predicted mean ΔE00 of "),
            std::string::npos)
      << check.out;

  const Scene box = scene_of(box_document());
  const plan::SettingsPrediction p = predict(box, 2, 4);
  const auto render = test::run_chromatrace({"render", kBox.string(), "-o", (dir / "r.exr").string(), "--resolution",
                                             fmt::format("{}x{}", kSize, kSize), "--max-bounces", "2", "--spp", "4",
                                             "--threads", "1", "-q"});
  EXPECT_EQ(render.exit_code, 0) << render.err;
  EXPECT_NE(render.err.find(fmt::format("chromatrace render: warning: --max-bounces 2 leaves {:.0f} %",
                                        100 * p.share_beyond)),
            std::string::npos)
      << render.err;
  EXPECT_NE(render.err.find(fmt::format("chromatrace render: warning: --spp 4 gives Monte Carlo noise of a predicted "
                                        "mean ΔE00 of {:.3g} (the tracer in bands mode); use {} samples for 1",
                                        p.noise_de00, p.samples_for_target)),
            std::string::npos)
      << render.err;

  // A part of a split by seed is judged by the samples of the whole (the parts are combined).
  const auto part = test::run_chromatrace({"render", kBox.string(), "-o", (dir / "p.exr").string(), "--resolution",
                                           fmt::format("{}x{}", kSize, kSize), "--spp", "4", "--seeds", "2", "--part",
                                           "0", "-q"});
  EXPECT_EQ(part.exit_code, 0) << part.err;
  EXPECT_NE(part.err.find("warning: --spp 4 gives"), std::string::npos) << part.err;

  // For Cycles the noise is kCyclesNoiseRatio × the tracer's, and with samples per band group each group's falls
  // with its own: the tracer's noise at one sample n₁ = noise(4)·√4, then kCyclesNoiseRatio·n₁·√(mean of 1/N_g).
  const double at_one = p.noise_de00 * 2.0;
  const fs::path groups = dir / "groups.json";
  write_file_atomically(groups, R"({"format": "chromatrace-bands/1", "edges_nm": [380, 430, 480, 530, 580, 630, 780],
                                   "cycles_samples": [4, 16]})");
  const auto cycles = test::run_chromatrace({"check-scene", (dir / "few.json").string(), "--renderer", "cycles",
                                             "--bands-file", groups.string()});
  EXPECT_EQ(cycles.exit_code, 0) << cycles.err;
  EXPECT_NE(cycles.out.find(fmt::format(
                "warning    cycles_samples of {} 4, 16 gives Cycles Monte Carlo noise of a predicted mean ΔE00 of {:.3g} "
                "({:g} × the tracer's, the median over the test scenes); use {} samples for 1",
                groups.string(), plan::kCyclesNoiseRatio * at_one * std::sqrt((1.0 / 4 + 1.0 / 16) / 2),
                plan::kCyclesNoiseRatio,
                static_cast<int>(std::ceil(std::pow(plan::kCyclesNoiseRatio * at_one, 2))))),
            std::string::npos)
      << cycles.out;

  // What plan would choose: nothing to say.
  doc["render"]["max_bounces"] = p.bounces_for_target;
  doc["render"]["samples"] = p.samples_for_target;
  write_file_atomically(dir / "planned.json", doc.dump(2));
  const auto planned = test::run_chromatrace({"check-scene", (dir / "planned.json").string()});
  EXPECT_EQ(planned.exit_code, 0) << planned.err;
  EXPECT_EQ(planned.out.find("warning"), std::string::npos) << planned.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ct
