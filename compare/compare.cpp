// SPDX-License-Identifier: Apache-2.0
// Cross-validation of two spectral renders (compare.h, docs/compare.md).
#include "compare/compare.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numeric>
#include <set>

#include <fmt/core.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/json_input.h"
#include "core/spectral_exr.h"
#include "core/render_delta_e.h"
#include "core/scene.h"
#include "core/statistics.h"
#include "plan/plan.h"
#include "sensor_sim/spectral_response.h"

namespace ct::cmp {
namespace {

using nlohmann::json;

struct Render {
  std::string file;
  SpectralExrInfo info;
  std::map<std::string, std::vector<float>> layers;  // "total" and components, [y][x][band] on the file's bands
  std::vector<std::int32_t> ids;
};

std::vector<std::string> component_names(const SpectralExrInfo& info) {
  std::vector<std::string> names;
  for (const SpectralLayer& l : info.layers)
    if (!l.component.empty() && l.quantity == SpectralQuantity::S0) names.push_back(l.component);
  return names;
}

Render load(const std::string& file) {
  SpectralExrReader reader(file);
  Render r;
  r.file = file;
  r.info = reader.info();
  if (!r.info.emissive)
    throw InputError(fmt::format("{}: not a spectral emissive render (kind: {}); compare needs S0.<λ>nm channels", file,
                                 r.info.kind()));
  r.layers["total"] = reader.read_layer(r.info.layer("", SpectralQuantity::S0));
  for (const std::string& c : component_names(r.info))
    r.layers[c] = reader.read_layer(r.info.layer(c, SpectralQuantity::S0));
  if (r.info.has_object_ids) {
    r.ids.resize(static_cast<std::size_t>(r.info.width) * r.info.height);
    reader.read_object_ids(0, r.info.height, r.ids);
  }
  for (const auto& [name, values] : r.layers)
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        throw InputError(fmt::format("{}: layer {}: NaN or infinite value at pixel ({}, {})", file,
                                     name == "total" ? "S0" : name, i / r.info.bands.size() % r.info.width,
                                     i / r.info.bands.size() / r.info.width));
  return r;
}

std::string meta(const SpectralExrInfo& info, const std::string& key) {
  auto it = info.metadata.find(key);
  return it == info.metadata.end() ? std::string() : it->second;
}

json parse_meta(const SpectralExrInfo& info, const std::string& key) {
  const std::string text = meta(info, key);
  if (text.empty()) return json();
  json j = json::parse(text, nullptr, false);
  return j.is_discarded() ? json() : j;
}

bool same_edges(const Bands& a, const Bands& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.edges().size(); ++i)
    if (std::abs(a.edges()[i] - b.edges()[i]) > 1e-4) return false;
  return true;
}

// For each band of `coarse`, the bands of `fine` that tile it and their width fractions; nullopt when the
// plans do not nest (an edge of the coarse plan that is not an edge of the fine one, or a gap).
using Rebin = std::vector<std::vector<std::pair<std::size_t, double>>>;
std::optional<Rebin> nest(const Bands& coarse, const Bands& fine) {
  constexpr double eps = 1e-4;
  Rebin rebin(coarse.size());
  for (std::size_t j = 0; j < coarse.size(); ++j) {
    double at = coarse.lo(j);
    for (std::size_t i = 0; i < fine.size(); ++i) {
      if (fine.hi(i) <= coarse.lo(j) + eps || fine.lo(i) >= coarse.hi(j) - eps) continue;
      if (std::abs(fine.lo(i) - at) > eps || fine.hi(i) > coarse.hi(j) + eps) return std::nullopt;
      rebin[j].emplace_back(i, fine.width(i) / coarse.width(j));
      at = fine.hi(i);
    }
    if (std::abs(at - coarse.hi(j)) > eps) return std::nullopt;
  }
  return rebin;
}

std::vector<float> rebinned(const std::vector<float>& values, std::size_t in_bands, const Rebin& rebin) {
  const std::size_t pixels = values.size() / in_bands;
  std::vector<float> out(pixels * rebin.size());
  for (std::size_t p = 0; p < pixels; ++p)
    for (std::size_t j = 0; j < rebin.size(); ++j) {
      double s = 0;
      for (const auto& [i, w] : rebin[j]) s += w * values[p * in_bands + i];
      out[p * rebin.size() + j] = static_cast<float>(s);
    }
  return out;
}

std::string describe_bands(const Bands& b) {
  return fmt::format("{:g}-{:g} nm ({} bands)", b.min_wavelength(), b.max_wavelength(), b.size());
}

// Every render of a side must be of the same kind as its first.
void check_side(const std::vector<Render>& side) {
  const Render& first = side.front();
  for (std::size_t i = 1; i < side.size(); ++i) {
    const Render& r = side[i];
    if (r.info.width != first.info.width || r.info.height != first.info.height)
      throw InputError(fmt::format("{}: image is {}x{} but {} is {}x{}", r.file, r.info.width, r.info.height,
                                   first.file, first.info.width, first.info.height));
    if (!same_edges(r.info.bands, first.info.bands))
      throw InputError(fmt::format("{}: bands {} differ from {}'s {} (renders of one side need the same plan)", r.file,
                                   describe_bands(r.info.bands), first.file, describe_bands(first.info.bands)));
    if (component_names(r.info) != component_names(first.info))
      throw InputError(fmt::format("{}: components differ from {}'s", r.file, first.file));
  }
}

std::array<double, 3> vec(const json& j) {
  if (!j.is_array() || j.size() != 3) return {0, 0, 0};
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}
std::array<double, 3> normalised(std::array<double, 3> v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (n > 0)
    for (double& x : v) x /= n;
  return v;
}

// Different scenes, cameras or sizes are incomparable: an InputError naming B's file and what differs.
void check_comparable(const Render& a, const Render& b) {
  if (a.info.width != b.info.width || a.info.height != b.info.height)
    throw InputError(fmt::format("{}: image is {}x{} but {} is {}x{} (incomparable: different sizes)", b.file,
                                 b.info.width, b.info.height, a.file, a.info.width, a.info.height));
  const json sa = parse_meta(a.info, "chromatrace.scene"), sb = parse_meta(b.info, "chromatrace.scene");
  if (sa.is_object() && sb.is_object() && sa.contains("name") && sb.contains("name") && sa["name"] != sb["name"])
    throw InputError(fmt::format("{}: attribute chromatrace.scene: scene {} but {} renders {} (incomparable: "
                                 "different scenes)",
                                 b.file, sb["name"].dump(-1, ' ', false, kReplaceInvalidUtf8), a.file, sa["name"].dump(-1, ' ', false, kReplaceInvalidUtf8)));
  if (!a.info.object_names.empty() && !b.info.object_names.empty() && a.info.object_names != b.info.object_names) {
    for (const auto& [id, name] : a.info.object_names) {
      auto it = b.info.object_names.find(id);
      const std::string other = it == b.info.object_names.end() ? "no object" : "\"" + it->second + "\"";
      if (other != "\"" + name + "\"")
        throw InputError(fmt::format("{}: attribute chromatrace.objects: id {} is {} but \"{}\" in {} (incomparable: "
                                     "different scenes)",
                                     b.file, id, other, name, a.file));
    }
    // B's further ids may be its scene's lights that A's render has no ids for: Blender's light objects, which
    // Cycles does not index, exported as the scene file's lights (docs/compare.md).
    std::set<std::string> lights;
    if (sb.is_object() && sb.contains("lights") && sb["lights"].is_array())
      for (const json& light : sb["lights"])
        if (light.is_object() && light.contains("name") && light["name"].is_string())
          lights.insert(light["name"].get<std::string>());
    for (const auto& [id, name] : b.info.object_names)
      if (!a.info.object_names.count(id) && !lights.count(name))
        throw InputError(fmt::format("{}: attribute chromatrace.objects: more objects than in {} (incomparable: "
                                     "different scenes)",
                                     b.file, a.file));
  }
  const json ca = parse_meta(a.info, "chromatrace.camera"), cb = parse_meta(b.info, "chromatrace.camera");
  if (ca.is_object() && cb.is_object()) {
    auto differ = [&](const std::string& what, double x, double y, double tol) {
      if (std::abs(x - y) > tol)
        throw InputError(fmt::format("{}: attribute chromatrace.camera: {} is {:.6g} but {:.6g} in {} (incomparable: "
                                     "different cameras)",
                                     b.file, what, y, x, a.file));
    };
    const auto pa = vec(ca.value("position", json())), pb = vec(cb.value("position", json()));
    const auto la = vec(ca.value("look_at", json())), lb = vec(cb.value("look_at", json()));
    const auto da = normalised({la[0] - pa[0], la[1] - pa[1], la[2] - pa[2]});
    const auto db = normalised({lb[0] - pb[0], lb[1] - pb[1], lb[2] - pb[2]});
    auto ortho_up = [](std::array<double, 3> up, const std::array<double, 3>& d) {
      const double k = up[0] * d[0] + up[1] * d[1] + up[2] * d[2];
      for (int i = 0; i < 3; ++i) up[i] -= k * d[i];
      return normalised(up);
    };
    const auto ua = ortho_up(vec(ca.value("up", json())), da), ub = ortho_up(vec(cb.value("up", json())), db);
    static const char* axis = "xyz";
    for (int i = 0; i < 3; ++i) {
      differ(fmt::format("position.{}", axis[i]), pa[i], pb[i], 1e-4 * (1 + std::abs(pa[i])));
      differ(fmt::format("direction.{}", axis[i]), da[i], db[i], 1e-5);
      differ(fmt::format("up.{}", axis[i]), ua[i], ub[i], 1e-5);
    }
    for (const char* key : {"horizontal_fov_deg", "vertical_fov_deg"})
      if (ca.contains(key) && cb.contains(key)) differ(key, ca[key].get<double>(), cb[key].get<double>(), 1e-3);
  }
}

// The scene's BRDF type of each object name ("lambert", "dichromatic", …, "emitter" for lights).
std::map<std::string, std::string> brdf_types(const json& scene) {
  std::map<std::string, std::string> types;
  if (!scene.is_object()) return types;
  const json materials = scene.value("materials", json::object());
  for (const json& o : scene.value("objects", json::array())) {
    if (!o.is_object() || !o.contains("name")) continue;
    std::string type = "unknown";
    const json m = o.value("material", json());
    if (m.is_string() && materials.contains(m.get<std::string>()))
      type = materials[m.get<std::string>()].value("type", "unknown");
    else if (m.is_object())
      type = m.value("type", "unknown");
    types[o["name"].get<std::string>()] = type;
  }
  for (const json& l : scene.value("lights", json::array()))
    if (l.is_object() && l.contains("name")) types[l["name"].get<std::string>()] = "emitter";
  return types;
}

double default_tolerance(const std::string& brdf) { return brdf == "lambert" || brdf == "emitter" ? 0.01 : 0.02; }

struct Region {
  std::int32_t id = 0;
  std::string name, brdf;
  std::vector<std::size_t> pixels;
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  // neighbouring pixels both in the region
};

// Mean and standard error of one side's renders over a region, for one layer and band.
std::pair<double, double> side_stats(const std::vector<const std::vector<float>*>& layers, std::size_t bands,
                                     std::size_t band, const Region& region) {
  std::vector<double> means;
  for (const auto* values : layers) {
    double s = 0;
    for (std::size_t p : region.pixels) s += (*values)[p * bands + band];
    means.push_back(s / static_cast<double>(region.pixels.size()));
  }
  const MeanAndError seeds = mean_and_standard_error(means);
  const double mean = seeds.mean;
  if (means.size() >= 2) return {mean, seeds.standard_error};
  const std::vector<float>& v = *layers.front();
  double variance = 0;
  if (!region.pairs.empty()) {
    double ss = 0;
    for (const auto& [p, q] : region.pairs) {
      const double d = double(v[p * bands + band]) - v[q * bands + band];
      ss += d * d;
    }
    variance = ss / (2.0 * static_cast<double>(region.pairs.size()));
  } else if (region.pixels.size() >= 2) {
    double ss = 0;
    for (std::size_t p : region.pixels) ss += (v[p * bands + band] - mean) * (v[p * bands + band] - mean);
    variance = ss / static_cast<double>(region.pixels.size() - 1);
  } else {
    return {mean, std::abs(mean)};  // one pixel: no noise estimate; as uncertain as the value itself
  }
  return {mean, std::sqrt(variance / static_cast<double>(region.pixels.size()))};
}

// Standard error of mean_a − mean_b from the per-pixel differences of the two sides' average images.
double paired_se(const std::vector<const std::vector<float>*>& la, const std::vector<const std::vector<float>*>& lb,
                 std::size_t bands, std::size_t band, const Region& region) {
  const std::size_t n = region.pixels.size();
  if (n < 2) return 0.0;
  std::vector<double> d(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t at = region.pixels[i] * bands + band;
    double a = 0, b = 0;
    for (const auto* v : la) a += (*v)[at];
    for (const auto* v : lb) b += (*v)[at];
    d[i] = a / double(la.size()) - b / double(lb.size());
  }
  return mean_and_standard_error(d).standard_error;
}

SideSummary summary(const std::vector<Render>& side) {
  SideSummary s;
  std::vector<std::string> seeds;
  for (const Render& r : side) {
    s.files.push_back(r.file);
    seeds.push_back(meta(r.info, "chromatrace.seed"));
  }
  s.renderer = meta(side.front().info, "chromatrace.renderer");
  s.samples = meta(side.front().info, "chromatrace.samples");
  s.seeds = fmt::format("{}", fmt::join(seeds, ","));
  return s;
}

// The camera's responses (tristimulus values) of each pixel of `spectra` ([pixel][band] on `bands`).
template <typename T>
std::vector<Vec3d> responses(const std::vector<T>& spectra, const Bands& bands, const sensor::CameraCurves& curves,
                             std::size_t pixels) {
  return sensor::camera_tristimulus(std::span<const T>(spectra), bands, curves, pixels);
}

// The white's light (CompareOptions::white): the scene's, from A's header or else B's (its relative paths from
// chromatrace.scene_directory, else the file's folder), else D65; and what it is, said.
std::pair<PiecewiseLinearSpectrum, std::string> white_light(const Render& a, const Render& b, const std::string& white) {
  if (white == "d65") return {cie::illuminant("D65"), "D65"};
  std::vector<std::string> why;
  for (const Render* r : {&a, &b}) {
    const std::string side = r == &a ? "A" : "B";
    const auto it = r->info.metadata.find("chromatrace.scene");
    if (it == r->info.metadata.end()) {
      why.push_back(fmt::format("{}: no chromatrace.scene", side));
      continue;
    }
    const auto dir = r->info.metadata.find("chromatrace.scene_directory");
    const std::filesystem::path directory =
        dir != r->info.metadata.end() ? std::filesystem::path(dir->second) : std::filesystem::path(r->info.file).parent_path();
    try {
      const Scene scene = parse_scene(json::parse(it->second), r->info.file + ": chromatrace.scene", directory);
      return {plan::scene_light_spectrum(scene), fmt::format("the scene's light ({}'s chromatrace.scene)", side)};
    } catch (const std::exception& e) {  // a texture no longer where the scene says, a .blend's name for its scene
      why.push_back(fmt::format("{}: {}", side, e.what()));
    }
  }
  return {cie::illuminant("D65"), fmt::format("D65: no scene's light in either header ({})", fmt::join(why, "; "))};
}

// The white's light through the camera over the range of `bands`: its spectrum as it is, not band-averaged (a
// fluorescent lamp's lines would move its colour), as plan::measure_delta_e takes it.
Vec3d light_response(const PiecewiseLinearSpectrum& light, const Bands& bands, const sensor::CameraCurves& curves) {
  Vec3d out{};
  for (int c = 0; c < 3; ++c)
    out[c] = integral_of_product(light, curves.curves[c], bands.min_wavelength(), bands.max_wavelength());
  return out;
}

// With --colour own: each side through the camera over its own bands, before the finer side is averaged into the
// coarser (so the coarser plan's colour error counts); the mean of the side's renders.
std::vector<Vec3d> own_responses(const std::vector<Render>& side, const sensor::CameraCurves& curves) {
  const Bands& bands = side.front().info.bands;
  const std::size_t n = static_cast<std::size_t>(side.front().info.width) * side.front().info.height;
  std::vector<Vec3d> out(n, Vec3d{0, 0, 0});
  for (const Render& r : side) {
    const std::vector<Vec3d> x = responses(r.layers.at("total"), bands, curves, n);
    for (std::size_t p = 0; p < n; ++p)
      for (int k = 0; k < 3; ++k) out[p][k] += x[p][k] / static_cast<double>(side.size());
  }
  return out;
}

void check_options(const CompareOptions& options) {
  if (options.a.empty() || options.b.empty()) throw InputError("compare: needs two renders, A and B");
  if (options.pixels != "matched" && options.pixels != "interior")
    throw InputError(fmt::format("--pixels: must be matched or interior, got \"{}\"", options.pixels));
  if (options.tolerance && !(*options.tolerance >= 0 && *options.tolerance < 1))
    throw InputError(fmt::format("--tolerance: must be in [0, 100) %, got {:g} %", *options.tolerance * 100));
  if (!(options.sigmas >= 0)) throw InputError(fmt::format("--sigmas: must be >= 0, got {:g}", options.sigmas));
  if (options.colour != "common" && options.colour != "own")
    throw InputError(fmt::format("--colour: must be common or own, got \"{}\"", options.colour));
  if (options.white != "scene" && options.white != "d65")
    throw InputError(fmt::format("--white: must be scene or d65, got \"{}\"", options.white));
}

// Load: each side's renders, checked against each other and across the sides.
std::pair<std::vector<Render>, std::vector<Render>> load_sides(const CompareOptions& options) {
  std::vector<Render> A, B;
  for (const std::string& f : options.a) A.push_back(load(f));
  for (const std::string& f : options.b) B.push_back(load(f));
  check_side(A);
  check_side(B);
  check_comparable(A.front(), B.front());
  return {std::move(A), std::move(B)};
}

// Unify bands: the common band plan is the coarser of the two; the finer side's layers are averaged into it.
Bands unify_bands(std::vector<Render>& A, std::vector<Render>& B) {
  const Bands &ba = A.front().info.bands, &bb = B.front().info.bands;
  if (same_edges(ba, bb)) return ba;
  const bool a_coarse = ba.size() <= bb.size();
  const Bands& coarse = a_coarse ? ba : bb;
  const Bands& fine = a_coarse ? bb : ba;
  const auto rebin = nest(coarse, fine);
  if (!rebin)
    throw InputError(fmt::format("{}: bands {} do not nest with {}'s {} (every edge of the coarser plan must be an "
                                 "edge of the finer)",
                                 B.front().file, describe_bands(bb), A.front().file, describe_bands(ba)));
  const Bands common = coarse;
  const std::size_t fine_size = fine.size();
  for (Render& r : a_coarse ? B : A)
    for (auto& [name, values] : r.layers) values = rebinned(values, fine_size, *rebin);
  return common;
}

// The components both sides have ("total" first), and those only one has.
void shared_components(Comparison& c, const std::vector<Render>& A, const std::vector<Render>& B) {
  const auto ca = component_names(A.front().info), cb = component_names(B.front().info);
  c.components.push_back("total");
  for (const std::string& n : ca)
    if (std::find(cb.begin(), cb.end(), n) != cb.end()) c.components.push_back(n);
    else c.only_a.push_back(n);
  for (const std::string& n : cb)
    if (std::find(ca.begin(), ca.end(), n) == ca.end()) c.only_b.push_back(n);
}

// Regions: the whole image, then each object's pixels (ids equal in both renders; with "interior", also every
// 8-neighbour's), each with its pairs of neighbouring pixels.
std::vector<Region> object_regions(Comparison& c, const Render& a, const Render& b, const std::string& pixels,
                                   const std::map<std::string, std::string>& types) {
  const std::size_t W = static_cast<std::size_t>(c.width), H = static_cast<std::size_t>(c.height), N = W * H;
  std::vector<Region> regions;
  {
    Region image;
    image.id = -1;
    image.name = "(image)";
    image.brdf = "image";
    for (std::size_t p = 0; p < N; ++p) image.pixels.push_back(p);
    regions.push_back(std::move(image));
  }
  const std::vector<std::int32_t>& ida = a.ids;
  const std::vector<std::int32_t>& idb = b.ids;
  if (!ida.empty() && !idb.empty()) {
    std::vector<std::int32_t> label(N, -1);  // the object of each pixel used, or -1
    for (std::size_t p = 0; p < N; ++p) {
      if (ida[p] != idb[p]) {
        ++c.id_mismatch_pixels;
        continue;
      }
      if (ida[p] == 0) continue;
      bool keep = true;
      if (pixels == "interior") {
        const std::size_t x = p % W, y = p / W;
        for (int dy = -1; dy <= 1 && keep; ++dy)
          for (int dx = -1; dx <= 1 && keep; ++dx) {
            const long xx = long(x) + dx, yy = long(y) + dy;
            if (xx < 0 || yy < 0 || xx >= long(W) || yy >= long(H)) continue;
            const std::size_t q = std::size_t(yy) * W + std::size_t(xx);
            keep = ida[q] == ida[p] && idb[q] == ida[p];
          }
      }
      if (keep) label[p] = ida[p];
    }
    std::map<std::int32_t, Region> by_id;
    for (std::size_t p = 0; p < N; ++p)
      if (label[p] >= 0) by_id[label[p]].pixels.push_back(p);
    for (auto& [id, region] : by_id) {
      region.id = id;
      auto it = a.info.object_names.find(id);
      region.name = it != a.info.object_names.end() ? it->second : fmt::format("id {}", id);
      auto t = types.find(region.name);
      region.brdf = t != types.end() ? t->second : "unknown";
      for (std::size_t p : region.pixels) {
        const std::size_t x = p % W, y = p / W;
        if (x + 1 < W && label[p + 1] == id) region.pairs.emplace_back(p, p + 1);
        if (y + 1 < H && label[p + W] == id) region.pairs.emplace_back(p, p + W);
      }
      regions.push_back(std::move(region));
    }
  }
  for (Region& r : regions)
    if (r.id == -1)
      for (std::size_t p = 0; p < N; ++p) {
        if ((p % W) + 1 < W) r.pairs.emplace_back(p, p + 1);
        if (p + W < N) r.pairs.emplace_back(p, p + W);
      }
  return regions;
}

// One cell: a region's means on both sides for one component and band, their standard errors, z and the test.
Cell compare_cell(const Region& region, const std::string& component, std::size_t band, const Comparison& c,
                  const std::vector<const std::vector<float>*>& la, const std::vector<const std::vector<float>*>& lb,
                  bool seeds, double tol, double sigmas) {
  const std::size_t nb = c.bands.size();
  Cell cell;
  cell.object_id = region.id;
  cell.object = region.name;
  cell.brdf = region.brdf;
  cell.component = component;
  cell.band = band;
  cell.lo_nm = c.bands.lo(band);
  cell.hi_nm = c.bands.hi(band);
  cell.pixels = region.pixels.size();
  std::tie(cell.mean_a, cell.se_a) = side_stats(la, nb, band, region);
  std::tie(cell.mean_b, cell.se_b) = side_stats(lb, nb, band, region);
  const double diff = cell.mean_a - cell.mean_b;
  cell.se = seeds || region.pixels.size() < 2 ? std::hypot(cell.se_a, cell.se_b) : paired_se(la, lb, nb, band, region);
  const double se = cell.se;
  const double scale = std::max(std::abs(cell.mean_a), std::abs(cell.mean_b));
  // Exact values on both sides (a lamp seen directly): a difference within float rounding is z = 0.
  cell.z = se > 0                            ? diff / se
           : std::abs(diff) <= 1e-5 * scale ? 0.0
                                            : std::copysign(std::numeric_limits<double>::infinity(), diff);
  if (cell.mean_b != 0) {
    const double r = cell.mean_a / cell.mean_b;
    cell.ratio = r;
    cell.se_ratio = cell.mean_a != 0 ? std::abs(r) * std::hypot(cell.se_a / cell.mean_a, cell.se_b / cell.mean_b)
                                     : cell.se_a / std::abs(cell.mean_b);
  }
  cell.tolerance = tol;
  // Float rounding (band values pass through single-precision colours in Cycles) is never a disagreement.
  cell.pass = std::abs(diff) <= tol * std::abs(cell.mean_b) + sigmas * se + 1e-5 * scale;
  return cell;
}

// Cells: per region × component × band.
void compare_cells(Comparison& c, const std::vector<Render>& A, const std::vector<Render>& B,
                   const std::vector<Region>& regions, const CompareOptions& options) {
  double max_tolerance = 0.01;
  for (const Region& r : regions)
    if (r.id >= 0) max_tolerance = std::max(max_tolerance, default_tolerance(r.brdf));
  const bool seeds = A.size() >= 2 && B.size() >= 2;
  c.se_method = seeds ? "seeds" : "paired pixels";
  for (const Region& region : regions) {
    if (region.pixels.empty()) continue;
    const double tol = options.tolerance ? *options.tolerance
                       : region.id == -1 ? max_tolerance
                                         : default_tolerance(region.brdf);
    for (const std::string& component : c.components) {
      std::vector<const std::vector<float>*> la, lb;
      for (const Render& r : A) la.push_back(&r.layers.at(component));
      for (const Render& r : B) lb.push_back(&r.layers.at(component));
      for (std::size_t band = 0; band < c.bands.size(); ++band) {
        c.cells.push_back(compare_cell(region, component, band, c, la, lb, seeds, tol, options.sigmas));
        if (!c.cells.back().pass) ++c.failed;
      }
    }
  }
}

// Image level: ΔE00 through the camera between the sides' average images (core/render_delta_e.h), under the white
// of `light` (CompareOptions::white) at the level of A's surfaces (pixels on or next to an emitter left out); the
// linear previews of both sides.
void image_level(Comparison& c, const std::vector<Render>& A, const std::vector<Render>& B,
                 const std::vector<Region>& regions, const sensor::CameraCurves& curves,
                 const std::vector<Vec3d>& own_a, const std::vector<Vec3d>& own_b, const PiecewiseLinearSpectrum& light) {
  const std::size_t N = static_cast<std::size_t>(c.width) * static_cast<std::size_t>(c.height), nb = c.bands.size();
  auto average = [&](const std::vector<Render>& side) {
    std::vector<double> out(N * nb, 0.0);
    for (const Render& r : side) {
      const auto& v = r.layers.at("total");
      for (std::size_t i = 0; i < out.size(); ++i) out[i] += v[i];
    }
    for (double& v : out) v /= static_cast<double>(side.size());
    return out;
  };
  const bool own = !own_b.empty();
  const std::vector<Vec3d> xa = own ? own_a : responses(average(A), c.bands, curves, N);
  const std::vector<Vec3d> xb = own ? own_b : responses(average(B), c.bands, curves, N);
  std::set<std::int32_t> emitters;
  for (const Region& r : regions)
    if (r.brdf == "emitter") emitters.insert(r.id);
  WhitePolicy policy;
  policy.light = light_response(light, own ? B.front().info.bands : c.bands, curves);
  const Vec3d white = white_point(
      xa, near_emitters(A.front().ids, c.width, c.height, [&](std::int32_t id) { return emitters.count(id) > 0; }),
      policy);
  RenderDeltaE de = delta_e_between(xa, xb, white);
  c.delta_e = std::move(de.per_pixel);
  c.delta_e_mean = de.mean;
  c.delta_e_p95 = de.p95;
  c.delta_e_max = de.max;
  // Each object's mean over its region's pixels: with --pixels interior, edge pixels (which mix two objects) are
  // left out of it as they are of the band comparison.
  for (const Region& r : regions) {
    if (r.id < 0 || r.pixels.empty()) continue;
    double sum = 0;
    for (const std::size_t p : r.pixels) sum += c.delta_e[p];
    c.delta_e_by_object[r.id] = sum / static_cast<double>(r.pixels.size());
  }
  const double yw = white[1];
  c.rgb_a.resize(N * 3);
  c.rgb_b.resize(N * 3);
  const bool cie = curves.name == "cie1931";
  for (std::size_t p = 0; p < N; ++p)
    for (int side = 0; side < 2; ++side) {
      const Vec3d& x = side == 0 ? xa[p] : xb[p];
      Vec3d rgb;
      if (cie) rgb = xyz_to_linear_srgb({x[0] / yw, x[1] / yw, x[2] / yw});
      else rgb = {x[0] / white[0], x[1] / white[1], x[2] / white[2]};  // white-balanced camera RGB
      auto& out = side == 0 ? c.rgb_a : c.rgb_b;
      for (int k = 0; k < 3; ++k) out[p * 3 + k] = static_cast<float>(rgb[k]);
    }
}

}  // namespace

Comparison compare(const CompareOptions& options) {
  check_options(options);
  const sensor::CameraCurves curves = sensor::camera_curves(options.camera, {"r", "g", "b"}, "--camera");
  auto [A, B] = load_sides(options);
  std::vector<Vec3d> own_a, own_b;
  if (options.colour == "own") {
    own_a = own_responses(A, curves);
    own_b = own_responses(B, curves);
  }

  Comparison c;
  c.colour = options.colour;
  c.a = summary(A);
  c.b = summary(B);
  c.sigmas = options.sigmas;
  c.camera = curves.name;
  c.pixels_mode = options.pixels;
  c.tolerance_mode = options.tolerance ? fmt::format("fixed {:g} %", *options.tolerance * 100)
                                       : std::string("by BRDF type (Lambert and emitters 1 %, glossy 2 %)");
  c.width = A.front().info.width;
  c.height = A.front().info.height;
  const json scene = parse_meta(A.front().info, "chromatrace.scene");
  c.scene_name = scene.is_object() ? scene.value("name", "") : "";

  c.bands = unify_bands(A, B);
  shared_components(c, A, B);
  const std::vector<Region> regions = object_regions(c, A.front(), B.front(), options.pixels, brdf_types(scene));
  compare_cells(c, A, B, regions, options);
  const auto [light, white] = white_light(A.front(), B.front(), options.white);
  c.white = white;
  image_level(c, A, B, regions, curves, own_a, own_b, light);
  return c;
}

}  // namespace ct::cmp
