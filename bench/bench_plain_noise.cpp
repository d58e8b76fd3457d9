// SPDX-License-Identifier: Apache-2.0
// The Monte Carlo noise of a plain RGB Cycles render, in ΔE00, over the image and per object: what
// bench_plan_cycles.py sets beside a planned spectral render (bench/README.md, "A planned spectral Cycles render").
//
// A and B are two plain renders of one scene that differ only in their seed (Blender's multilayer EXR with the
// Combined and IndexOB passes). Their pixels are linear Rec. 709 (Blender's scene-linear), taken to CIE XYZ and
// compared as `compare` compares two renders (core/render_delta_e.h): in CIELAB under the white of the scene's light
// (SCENE, plan::scene_light_spectrum; D65 without it) at the 99th percentile of A's luminance over the pixels not on
// or next to an emitter. The difference of two renders holds twice the variance
// of either, so one render's noise is their mean ΔE00 / √2 (the convention of `plan`, docs/plan.md "Samples").
//
//   bench_plain_noise A.exr B.exr [--emitters ID,ID,...] [--scene SCENE]
//
// prints `image NOISE` and, per object id (Blender's pass index, which the add-on's import sets to the scene's id),
// `object ID PIXELS NOISE`.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>

#include "core/cie.h"
#include "core/colour.h"
#include "core/render_delta_e.h"
#include "core/scene.h"
#include "core/spectrum.h"
#include "plan/plan.h"

namespace {

struct Plain {
  int width = 0, height = 0;
  std::vector<ct::Vec3d> xyz;
  std::vector<std::int32_t> ids;
};

Plain read_plain(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open: {}", path, OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  // The first of `names` the file has (Blender 5 names the object-index pass "Object Index", earlier ones "IndexOB").
  auto channel = [&](std::initializer_list<std::string> names) {
    for (const std::string& name : names)
      for (int c = 0; c < spec.nchannels; ++c)
        if (spec.channelnames[static_cast<std::size_t>(c)] == name) return c;
    throw std::runtime_error(fmt::format("{}: no channel {}", path, *names.begin()));
  };
  const int r = channel({"ViewLayer.Combined.R"}), g = channel({"ViewLayer.Combined.G"}),
            b = channel({"ViewLayer.Combined.B"}), id = channel({"ViewLayer.IndexOB.X", "ViewLayer.Object Index.X"});
  const std::size_t n = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
  const std::size_t nc = static_cast<std::size_t>(spec.nchannels);
  std::vector<float> pixels(n * nc);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw std::runtime_error(fmt::format("{}: cannot read: {}", path, in->geterror()));
  Plain p;
  p.width = spec.width;
  p.height = spec.height;
  p.xyz.resize(n);
  p.ids.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float* px = &pixels[i * nc];
    p.xyz[i] = ct::linear_srgb_to_xyz({px[r], px[g], px[b]});
    p.ids[i] = static_cast<std::int32_t>(std::lround(px[id]));
  }
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> files;
    std::set<std::int32_t> emitters;
    std::string scene_file;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--emitters" && i + 1 < argc) {
        std::stringstream list(argv[++i]);
        for (std::string id; std::getline(list, id, ',');)
          if (!id.empty()) emitters.insert(std::stoi(id));
      } else if (a == "--scene" && i + 1 < argc) {
        scene_file = argv[++i];
      } else {
        files.push_back(a);
      }
    }
    if (files.size() != 2) throw std::runtime_error("usage: bench_plain_noise A.exr B.exr [--emitters ID,ID,...] [--scene SCENE]");
    const Plain a = read_plain(files[0]), b = read_plain(files[1]);
    if (a.width != b.width || a.height != b.height) throw std::runtime_error("A and B differ in size");

    ct::WhitePolicy policy;
    policy.light = ct::d65_white();  // as compare without the scene's light
    if (!scene_file.empty()) {
      const ct::PiecewiseLinearSpectrum light = ct::plan::scene_light_spectrum(ct::load_scene(scene_file));
      const ct::PiecewiseLinearSpectrum* bar[3] = {&ct::cie::x_bar(), &ct::cie::y_bar(), &ct::cie::z_bar()};
      for (int c = 0; c < 3; ++c) policy.light[c] = ct::integral_of_product(light, *bar[c], 380, 780);
    }
    const ct::Vec3d white = ct::white_point(
        a.xyz, ct::near_emitters(a.ids, a.width, a.height, [&](std::int32_t id) { return emitters.count(id) > 0; }),
        policy);
    const ct::RenderDeltaE de = ct::delta_e_between(a.xyz, b.xyz, white);
    fmt::print("image {:.4f}\n", de.mean / std::sqrt(2.0));
    std::map<std::int32_t, std::pair<double, std::size_t>> by_object;
    for (std::size_t p = 0; p < a.ids.size(); ++p)
      if (a.ids[p] == b.ids[p] && a.ids[p] > 0) {
        auto& [sum, count] = by_object[a.ids[p]];
        sum += de.per_pixel[p];
        ++count;
      }
    for (const auto& [id, s] : by_object)
      fmt::print("object {} {} {:.4f}\n", id, s.second, s.first / static_cast<double>(s.second) / std::sqrt(2.0));
    return 0;
  } catch (const std::exception& e) {
    fmt::print(stderr, "bench_plain_noise: {}\n", e.what());
    return 2;
  }
}
