// SPDX-License-Identifier: Apache-2.0
// Writes the synthetic test images (tests/analyzer/synthetic.h) into a directory, for the end-to-end and
// browser tests and for the example plots of docs/analyze.md.
//   analyzer_synthetic_images DIR
#include <cstdio>
#include <filesystem>

#include "tests/analyzer/synthetic.h"

int main(int argc, char** argv) {
  using namespace ct::test;
  if (argc != 2) {
    std::fprintf(stderr, "usage: analyzer_synthetic_images DIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  const std::pair<const char*, RgbImage> shapes[] = {
      {"linear", matte_line()},   {"L", l_shape()},           {"skewed-T", skewed_t()},
      {"P", p_shape()},           {"curved", curved_cluster()}, {"clipped", clipped_line()},
      {"gamma", gamma_line()},    {"thickened", thickened_plane()}, {"fork", fork_shape()},
      {"thickened-line", thickened_line()}};
  for (const auto& [name, image] : shapes) write_sensor_exr(dir / (std::string(name) + ".exr"), {image, image, {}, {}, {}});
  write_sensor_exr(dir / "scene.exr", scene_with_components());
  write_sensor_exr(dir / "superposed.exr", two_luminaires(0.4, Vec3(1.0, 0.8, 0.55), Vec3(0.8, 0.9, 1.0)));
  write_sensor_exr(dir / "mixed.exr", two_objects_edge(true));
  SensorExr noisy = scene_with_components();
  noisy.final_image = add_sensor_noise(noisy.final_image, 20000, 10, 42);
  write_sensor_exr(dir / "scene_noisy.exr", noisy);
  write_rgb(dir / "scene.png", noisy.final_image, 8);
  return 0;
}
