// SPDX-License-Identifier: Apache-2.0
#include "tests/analyzer/synthetic.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

namespace ct::test {
namespace {

Vec3 dichromatic(double body, double specular) { return body * kBody + specular * kIlluminant; }

// A dichromatic sphere lit from the upper left: body (Lambert) and specular (Phong) weights at (u, v) of
// its bounding square; nullopt outside the disc.
struct SphereShading {
  double body = 0, specular = 0;
  bool inside = false;
};
SphereShading sphere(double u, double v, double shininess) {
  const double x = 2 * u - 1, y = 1 - 2 * v, r2 = x * x + y * y;
  if (r2 >= 0.98) return {};
  const Vec3 n(x, y, std::sqrt(1 - r2));
  const Vec3 light = Vec3(-0.4, 0.5, 0.77).normalized();
  const Vec3 half = (light + Vec3::UnitZ()).normalized();
  return {0.08 + 0.8 * std::max(0.0, n.dot(light)), 0.5 * std::pow(std::max(0.0, n.dot(half)), shininess), true};
}

}  // namespace

RgbImage matte_line() {
  return make_image(128, 128, [](double u, double v) -> Vec3 { return dichromatic(0.05 + 0.95 * (0.7 * u + 0.3 * v), 0); });
}

RgbImage l_shape() {
  return make_image(128, 128, [](double u, double) -> Vec3 {
    return u < 0.85 ? dichromatic(u / 0.85, 0) : dichromatic(1.0, 0.5 * (u - 0.85) / 0.15);
  });
}

RgbImage small_highlight_l() {
  // 128 columns; the last column of 82 of 128 rows … simpler: the highlight is the last 0.5 % of u.
  return make_image(128, 128, [](double u, double v) -> Vec3 {
    const double s = u + v / 128.0;  // one index over the whole image, in [0, 1 + 1/128]
    return s < 0.995 ? dichromatic(s / 0.995, 0) : dichromatic(1.0, 0.5 * (s - 0.995) / (1.0 + 1 / 128.0 - 0.995));
  });
}

RgbImage fork_shape() {
  // The object's upper half is lit by the body's light, its lower half by a second light of another colour
  // (e.g. a coloured wall), shading from near black to full.
  return make_image(128, 128, [](double u, double v) -> Vec3 {
    const double m = 0.05 + 0.95 * u;
    return v < 0.5 ? Vec3(m * kBody) : Vec3(m * 0.8 * kBody.cwiseProduct(kSecondLight).normalized());
  });
}

RgbImage thickened_line() {
  // Each pixel's colour turns by up to ±4 % towards a third colour, smoothly across the object and mostly
  // near its edges (by (2v − 1)³, as light from two walls of other colours): a fan about the body line, on
  // both of its sides.
  const Vec3 perpendicular = kBody.cross(Vec3(0, 0, 1)).normalized();
  return make_image(128, 128, [perpendicular](double u, double v) -> Vec3 {
    const double m = 0.05 + 0.95 * u;
    return m * (kBody + 0.04 * std::pow(2 * v - 1, 3) * perpendicular);
  });
}

RgbImage skewed_t() {
  return make_image(128, 128, [](double u, double) -> Vec3 {
    return u < 0.8 ? dichromatic(u / 0.8, 0) : dichromatic(0.5, 0.5 * (u - 0.8) / 0.2);
  });
}

RgbImage p_shape() {
  return make_image(128, 128, [](double u, double v) -> Vec3 {
    return u < 0.55 ? dichromatic(u / 0.55, 0) : dichromatic(0.5 + 0.4 * (u - 0.55) / 0.45, 0.35 * v);
  });
}

RgbImage curved_cluster() {
  return make_image(128, 128, [](double u, double) -> Vec3 {
    const double t = 2 * u - 1;
    return Vec3(0.5, 0.4, 0.35) + t * Vec3(0.3, 0.25, 0.05) + t * t * Vec3(0.02, 0.06, -0.12);
  });
}

RgbImage clipped_line() {
  return make_image(128, 128, [](double u, double v) -> Vec3 {
    const Vec3 c = 1.6 * dichromatic(0.05 + 0.95 * (0.7 * u + 0.3 * v), 0);
    return Vec3(std::min(c[0], 1.0), std::min(c[1], 1.0), std::min(c[2], 1.0));
  });
}

RgbImage gamma_line() {
  return make_image(128, 128, [](double u, double v) -> Vec3 {
    const Vec3 linear = Vec3(0.08, 0.1, 0.12) + (0.7 * u + 0.3 * v) * Vec3(0.7, 0.45, 0.25);
    return Vec3(std::pow(linear[0], kGamma), std::pow(linear[1], kGamma), std::pow(linear[2], kGamma));
  });
}

RgbImage thickened_plane() {
  const Vec3 third = Vec3(0.1, 0.3, 0.9).normalized();
  return make_image(128, 128, [&](double u, double v) -> Vec3 {
    const Vec3 c = u < 0.85 ? dichromatic(u / 0.85, 0) : dichromatic(1.0, 0.5 * (u - 0.85) / 0.15);
    return Vec3(c + 0.08 * v * (0.3 + u) * third);
  });
}

namespace {

// Four dichromatic spheres (body colours red, green, blue, yellow, shininess rising) in a 2 × 2 grid on
// black, under one illuminant; each part (diffuse, glossy, light from a green wall) as its own layer.
struct SceneParts {
  RgbImage diffuse, glossy, indirect;
  std::vector<std::int32_t> ids;
  std::map<std::int32_t, std::string> names;
};

SceneParts sphere_scene(const Vec3& illuminant, double indirect_strength, int size = 96) {
  const Vec3 bodies[] = {{0.8, 0.3, 0.2}, {0.25, 0.7, 0.3}, {0.2, 0.35, 0.85}, {0.8, 0.75, 0.2}};
  const char* names[] = {"red", "green", "blue", "yellow"};
  const Vec3 wall(0.3, 0.8, 0.35);
  const int kSize = size, kWidth = 2 * kSize;
  SceneParts parts;
  parts.diffuse = RgbImage{kWidth, kWidth, std::vector<float>(static_cast<std::size_t>(kWidth * kWidth * 3), 0.0f)};
  parts.glossy = parts.indirect = parts.diffuse;
  parts.ids.assign(static_cast<std::size_t>(kWidth * kWidth), 0);
  for (int o = 0; o < 4; ++o) {
    parts.names[o + 1] = names[o];
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const SphereShading s = sphere(x / double(kSize - 1), y / double(kSize - 1), 20.0 + 15 * o);
        if (!s.inside) continue;
        const std::size_t p = static_cast<std::size_t>(((o / 2) * kSize + y) * kWidth + (o % 2) * kSize + x);
        const Vec3 body = bodies[o].cwiseProduct(illuminant);
        const Vec3 d = 0.9 * s.body * body, g = 0.9 * s.specular * illuminant;
        const Vec3 i = indirect_strength * (0.3 + x / double(kSize)) * body.cwiseProduct(wall);
        for (int k = 0; k < 3; ++k) {
          parts.diffuse.rgb[p * 3 + k] = static_cast<float>(d[k]);
          parts.glossy.rgb[p * 3 + k] = static_cast<float>(g[k]);
          parts.indirect.rgb[p * 3 + k] = static_cast<float>(i[k]);
        }
        parts.ids[p] = o + 1;
      }
  }
  return parts;
}

RgbImage sum(const RgbImage& a, const RgbImage& b) {
  RgbImage out = a;
  for (std::size_t k = 0; k < out.rgb.size(); ++k) out.rgb[k] += b.rgb[k];
  return out;
}

}  // namespace

Scene dichromatic_scene(const Vec3& illuminant, int size) {
  SceneParts parts = sphere_scene(illuminant, 0.0, size);
  return {sum(parts.diffuse, parts.glossy), std::move(parts.ids), std::move(parts.names)};
}

RgbImage add_sensor_noise(const RgbImage& image, double full_well, double read_noise, std::uint32_t seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> read(0.0, read_noise);
  RgbImage out = image;
  for (float& v : out.rgb) {
    std::poisson_distribution<long> shot(std::max(0.0, static_cast<double>(v)) * full_well);
    v = static_cast<float>((static_cast<double>(shot(random)) + read(random)) / full_well);
  }
  return out;
}

analyzer::AnalysisImage analysis_image(const SensorExr& exr) {
  analyzer::AnalysisImage input;
  input.image = exr.final_image;
  input.linear = exr.linear;
  for (const auto& [name, layer] : exr.components) input.components.push_back({name, layer});
  input.object_ids = exr.ids;
  input.object_names = exr.names;
  return input;
}

SensorExr two_luminaires(double share_b, const Vec3& warm, const Vec3& cool) {
  const RgbImage a = make_image(64, 64, [&](double u, double v) -> Vec3 {
    return (0.1 + 0.9 * u) * (1 - share_b) * 2 * v * kBody.cwiseProduct(warm);
  });
  const RgbImage b = make_image(64, 64, [&](double u, double v) -> Vec3 {
    return (0.1 + 0.9 * u) * share_b * 2 * (1 - v) * kBody.cwiseProduct(cool);
  });
  RgbImage total = a;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) total.rgb[i] = a.rgb[i] + b.rgb[i];
  return {total, total, {{"light.warm", a}, {"light.cool", b}}, std::vector<std::int32_t>(64 * 64, 1), {{1, "wall"}}};
}

SensorExr two_objects_edge(bool box_filter) {
  const Vec3 other = kBody.cwiseProduct(kSecondLight).normalized();
  const RgbImage image = make_image(64, 64, [&](double u, double v) -> Vec3 {
    const double m = 0.1 + 0.9 * v;
    const int x = static_cast<int>(std::lround(u * 63));
    if (box_filter && x == 31) return m * (0.75 * kBody + 0.25 * other);
    return m * (x < 32 ? kBody : other);
  });
  std::vector<std::int32_t> ids;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) ids.push_back(x < 32 ? 1 : 2);
  return {image, image, {}, ids, {{1, "left"}, {2, "right"}}};
}

void write_sensor_exr(const std::filesystem::path& file, const SensorExr& exr) {
  const int w = exr.final_image.width, h = exr.final_image.height;
  std::vector<std::string> channels{"R", "G", "B", "linear.R", "linear.G", "linear.B"};
  std::vector<const RgbImage*> layers{&exr.final_image, &exr.linear};
  std::string component_list;
  for (const auto& [name, layer] : exr.components) {
    for (const char* c : {".R", ".G", ".B"}) channels.push_back(name + c);
    layers.push_back(&layer);
    component_list += (component_list.empty() ? "" : ",") + name;
  }
  const bool ids = !exr.ids.empty();
  if (ids) channels.push_back("object_id");
  const std::size_t nc = channels.size(), n = static_cast<std::size_t>(w) * h;
  std::vector<float> pixels(n * nc);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t l = 0; l < layers.size(); ++l)
      for (std::size_t c = 0; c < 3; ++c) pixels[i * nc + l * 3 + c] = layers[l]->rgb[i * 3 + c];
    if (ids) pixels[i * nc + nc - 1] = static_cast<float>(exr.ids[i]);
  }
  OIIO::ImageSpec spec(w, h, static_cast<int>(nc), OIIO::TypeDesc::FLOAT);
  spec.channelnames = channels;
  spec.attribute("compression", "zip");
  nlohmann::json names = nlohmann::json::object();
  for (const auto& [id, name] : exr.names) names[std::to_string(id)] = name;
  if (!exr.names.empty()) spec.attribute("chromatrace.objects", names.dump());
  if (!component_list.empty()) spec.attribute("chromatrace.components", component_list);
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out || !out->open(file.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close())
    throw std::runtime_error("cannot write " + file.string());
}

void write_rgb(const std::filesystem::path& file, const RgbImage& image, int bits) {
  OIIO::ImageSpec spec(image.width, image.height, 3, bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out || !out->open(file.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, image.rgb.data()) || !out->close())
    throw std::runtime_error("cannot write " + file.string());
}

SensorExr scene_with_components() {
  const SceneParts parts = sphere_scene(Vec3(1.0, 0.9, 0.75), 0.12);
  SensorExr exr;
  exr.ids = parts.ids;
  exr.names = parts.names;
  const RgbImage direct = sum(parts.diffuse, parts.glossy);
  exr.linear = sum(direct, parts.indirect);
  exr.final_image = exr.linear;
  exr.components = {{"diffuse_direct", parts.diffuse}, {"glossy_direct", parts.glossy}, {"diffuse_indirect", parts.indirect},
                    {"light.ceiling", exr.linear},      {"bounce.1", direct},             {"bounce.2", parts.indirect}};
  return exr;
}

}  // namespace ct::test
