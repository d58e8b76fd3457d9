// SPDX-License-Identifier: Apache-2.0
#include "series/figure_data.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include <fmt/core.h>
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "analyzer/image_input.h"
#include "core/file_io.h"
#include "core/series_format.h"
#include "plot/png.h"
#include "series/preview.h"

namespace ct::series {
namespace fs = std::filesystem;
namespace {

std::string string_at(const Json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : "";
}

std::vector<std::string> strings_at(const Json& j, const char* key) {
  std::vector<std::string> out;
  if (j.is_object() && j.contains(key) && j[key].is_array())
    for (const Json& e : j[key])
      if (e.is_string()) out.push_back(e.get<std::string>());
  return out;
}

double number_at(const Json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<double>() : 0.0;
}

// The longest side a camera image is embedded with; larger ones are reduced.
constexpr int kMaxEmbeddedSide = 512;

}  // namespace

std::vector<VariantView> read_variants(const Json& result) {
  std::vector<VariantView> variants;
  if (!result.is_object() || !result.contains("variants") || !result["variants"].is_array()) return variants;
  for (const Json& v : result["variants"]) {
    VariantView view;
    view.name = string_at(v, "name");
    view.description = string_at(v, "description");
    view.figure = strings_at(v, "figure");
    view.ok = v.is_object() && v.contains("ok") && v["ok"].is_boolean() && v["ok"].get<bool>();
    view.error = string_at(v, "error");
    if (view.name.empty()) view.name = fmt::format("variant {}", variants.size() + 1);
    if (view.ok) {
      if (v.contains("sensor")) view.camera_exr = string_at(v["sensor"], "file");
      view.preview = string_at(v, "preview");
      if (v.contains("analysis")) {
        view.report = string_at(v["analysis"], "report");
        view.analysis = string_at(v["analysis"], "file");
        view.seconds += number_at(v["analysis"], "seconds");
      }
      if (v.contains("render")) view.seconds += number_at(v["render"], "seconds");
      if (v.contains("sensor")) view.seconds += number_at(v["sensor"], "seconds");
      if (v.contains("size") && v["size"].is_array() && v["size"].size() == 2 && v["size"][0].is_number_integer() &&
          v["size"][1].is_number_integer())
        view.size = std::array<int, 2>{v["size"][0].get<int>(), v["size"][1].get<int>()};
      if (v.contains("expect") && v["expect"].is_array())
        for (const Json& e : v["expect"]) {
          ++view.expectations;
          view.met += e.is_object() && e.contains("ok") && e["ok"].is_boolean() && e["ok"].get<bool>() ? 1 : 0;
          if (!e.is_object() || !e.contains("objects") || !e["objects"].is_array()) continue;
          for (const Json& o : e["objects"]) {
            FindingView f;
            f.target = string_at(e, "target");
            f.any_of = strings_at(e, "any_of");
            f.bent_by = string_at(e, "bent_by");
            f.thickened_by = string_at(e, "thickened_by");
            f.paper = string_at(e, "paper");
            f.object = string_at(o, "object");
            f.found = string_at(o, "found");
            f.ok = o.is_object() && o.contains("ok") && o["ok"].is_boolean() && o["ok"].get<bool>();
            f.explanation = string_at(o, "explanation");
            view.findings.push_back(std::move(f));
          }
        }
      if (view.camera_exr.empty()) {
        view.ok = false;
        view.error = "series.json names no camera image (sensor.file) for this variant";
      }
    } else if (view.error.empty()) {
      view.error = "the variant failed (series.json gives no reason)";
    }
    variants.push_back(std::move(view));
  }
  return variants;
}

void load_images(VariantView& variant, const fs::path& dir, std::size_t max_points) {
  if (!variant.ok) return;
  try {
    const fs::path exr = dir / variant.camera_exr;
    const analyzer::AnalysisImage input = analyzer::read_analysis_image(exr);
    const int width = input.image.width, height = input.image.height;
    cv::Mat camera;
    std::string camera_png;
    if (!variant.preview.empty() && fs::is_regular_file(dir / variant.preview)) {
      camera_png = read_file(dir / variant.preview);
      const std::vector<unsigned char> bytes(camera_png.begin(), camera_png.end());
      camera = cv::imdecode(bytes, cv::IMREAD_COLOR);
    }
    // camera.png is what a person sees; without it (or if it does not match the EXR) the same preview anew.
    if (camera.empty() || camera.cols != width || camera.rows != height) {
      camera = preview_image(input);
      camera_png.clear();
    }
    variant.camera = camera;
    if (camera_png.empty() || std::max(width, height) > kMaxEmbeddedSide) {
      cv::Mat shown = camera;
      if (std::max(width, height) > kMaxEmbeddedSide)
        cv::resize(camera, shown, display_size(camera, kMaxEmbeddedSide), 0, 0, cv::INTER_AREA);
      camera_png = plot::encode_png(shown);
    }
    variant.camera_png = std::move(camera_png);

    variant.points = gather_points(input, camera, channel_units(exr, input), max_points);
    variant.plane = plot::principal_plane(variant.points.rgb);
    variant.oblique = oblique_plot(variant.points);
    variant.projection = projection_plot(variant.points, variant.plane);
    variant.oblique_png = plot::encode_png(variant.oblique);
    variant.projection_png = plot::encode_png(variant.projection);
    variant.points.rgb.clear();
    variant.points.rgb.shrink_to_fit();
    variant.points.bgr.clear();
    variant.points.bgr.shrink_to_fit();
  } catch (const std::exception& e) {
    variant.image_error = e.what();
    variant.camera.release();
    variant.oblique.release();
    variant.projection.release();
    variant.camera_png.clear();
    variant.oblique_png.clear();
    variant.projection_png.clear();
  }
}

std::string thumbnail_png(const fs::path& dir, const VariantView& variant, int side) {
  cv::Mat camera = variant.camera;
  if (camera.empty() && variant.ok && !variant.preview.empty()) camera = cv::imread((dir / variant.preview).string(), cv::IMREAD_COLOR);
  if (camera.empty()) return "";
  cv::Mat small;
  const double f = static_cast<double>(side) / std::max(camera.cols, camera.rows);
  if (f >= 1) small = camera;
  else cv::resize(camera, small, cv::Size(std::max(1, static_cast<int>(camera.cols * f)), std::max(1, static_cast<int>(camera.rows * f))), 0, 0,
                  cv::INTER_AREA);
  return plot::encode_png(small);
}

std::string expected_text(const FindingView& f) {
  std::string text = expectation_phrase(f.any_of, " or ", f.bent_by, f.thickened_by);
  if (!f.paper.empty()) text += fmt::format(" (the paper: {})", f.paper);
  return text;
}

std::string panel_caption(const std::string& panel) {
  static const std::map<std::string, std::string> captions = {
      {"3a", "(a) Diffusely reflecting surfaces under direct illumination"},
      {"3b", "(b) Dichromatically reflecting surfaces under direct illumination"},
      {"3c", "(c) Diffusely reflecting surfaces under global illumination"},
      {"3d", "(d) Dichromatically reflecting surfaces under global illumination"},
      {"4a", "(a) Original image"},
      {"4b", "(b) With supersampling in the area of a pixel"},
      {"4c", "(c) With a different gamma factor"},
      {"4d", "(d) With clipping effect by over exposure"},
      {"3e", "(e) Beyond the paper: a concave object of one paint under global illumination, the banana"}};
  const auto it = captions.find(panel);
  return it == captions.end() ? "" : it->second;
}

std::string figure_title(int figure) {
  return figure == 3 ? "Figure 3: Simulations of color histogram" : "Figure 4: Histograms of images with direct illumination";
}

const std::array<std::string, 4>& figure_panels(int figure) {
  static const std::array<std::string, 4> three = {"3a", "3b", "3c", "3d"}, four = {"4a", "4b", "4c", "4d"};
  return figure == 3 ? three : four;
}

const std::vector<std::string>& extra_panels(int figure) {
  static const std::vector<std::string> three = {"3e"}, four = {};
  return figure == 3 ? three : four;
}

cv::Size display_size(const cv::Mat& camera, int box) {
  const int side = std::max(camera.cols, camera.rows);
  if (side <= 0) return {0, 0};
  if (side <= box) {
    const int k = std::max(1, box / side);
    return {camera.cols * k, camera.rows * k};
  }
  const double f = static_cast<double>(box) / side;
  return {std::max(1, static_cast<int>(camera.cols * f)), std::max(1, static_cast<int>(camera.rows * f))};
}

}  // namespace ct::series
