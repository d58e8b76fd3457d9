// SPDX-License-Identifier: Apache-2.0
#pragma once
// The bad scenes in tests/data/scenes/bad/ and the one-line error each must get, shared by the library
// tests (tests/core/test_scene.cpp) and the end-to-end tests of `chromatrace check-scene`.

#include <string>
#include <vector>

namespace ct::test {

struct BadScene {
  std::string file;  // under tests/data/scenes/bad/
  // The message after "<scene path>: ". "{dir}" stands for the folder of the bad scenes.
  std::string message;
};

inline const std::vector<BadScene>& bad_scenes() {
  static const std::vector<BadScene> cases = {
      {"unknown_top_key.json",
       "colour: unknown key (allowed: \"format\", \"name\", \"description\", \"spectra\", \"materials\", "
       "\"objects\", \"lights\", \"environment\", \"camera\", \"render\")"},
      {"unknown_nested_key.json", "materials.wall.colour: unknown key (allowed: \"type\", \"reflectance\")"},
      {"missing_material.json", "objects[0].material: unknown material \"plstic\" (materials: wall)"},
      {"negative_radius.json", "objects[1].shape.radius: must be > 0, got -0.2"},
      {"wavelengths_not_increasing.json",
       "spectra.paint.csv: {dir}/wavelengths_not_increasing.csv: line 4: wavelength_nm 500 does not increase "
       "(previous 550)"},
      {"wrong_format.json", "format: must be \"chromatrace-scene/1\", got \"chromatrace-scene/2\""},
      {"syntax_error.json",
       "line 3, column 56: syntax error while parsing object - unexpected string literal; expected '}'"},
      {"unknown_spectrum.json", "materials.wall.reflectance: unknown spectrum \"whte\" (spectra: white)"},
      {"roughness_out_of_range.json", "materials.red_plastic.roughness: must be in [0, 1], got 1.5"},
      {"principled_mirror_roughness.json",
       "materials.plastic.roughness: 0.01 is below 0.02, where Cycles' interface becomes a perfect mirror, which a "
       "principled material does not hold"},
      {"principled_v1_multiscatter.json",
       "materials.plastic.distribution: Blender 3.x's Multiscatter GGX is a random walk the tracer does not hold; "
       "version 1 takes \"ggx\""},
      {"principled_v2_specular.json", "materials.plastic.specular: applies only to \"version\": 1"},
      {"unknown_masking.json",
       "materials.red_plastic.masking: must be one of \"separable\", \"height-correlated\", got \"smith\""},
      {"duplicate_key.json", "materials.wall.reflectance: key appears twice in one object"},
      {"reflectance_above_one.json",
       "materials.wall.reflectance: spectrum \"glow\" reaches 1.2 at 650 nm, but a reflectance must be in [0, 1]"},
      {"energy_gain.json",
       "materials.plastic.specular: the diffuse maximum 0.95 plus specular 0.1 exceeds 1, so the material would "
       "reflect more light than it receives"},
      {"wavelengths_in_micrometres.json",
       "spectra.paint: wavelengths 0.4 to 0.7 do not overlap the visible range 360-830 nm (wavelengths are in nm)"},
      {"sensor_in_metres.json", "camera.sensor_width_mm: must be a width in mm within [1, 1000], got 0.036"},
      {"missing_mesh.json", "objects[0].shape.file: {dir}/meshes/bunny.ply: cannot open file"},
      {"no_light.json", "lights: a scene needs at least one light or an \"environment\""},
      {"missing_texture.json", "materials.wood.reflectance.texture: {dir}/textures/wood.png: cannot open file"},
      {"texture_on_mesh_without_uvs.json",
       "objects[0].shape.file: {dir}/tetrahedron_no_uvs.ply has no texture coordinates (vertex properties u, v or "
       "s, t), but object \"tetra\" has material \"wood\" whose reflectance is a texture"},
      {"environment_rotation_without_texture.json", "environment.rotation_deg: applies only to a texture radiance"},
      {"duplicate_name.json", "lights[0].name: \"floor\" is already the name of objects[0]"},
      {"series_bad_variant.json", "variants[1] \"rough\": materials.plastic.roughness: must be in [0, 1], got 1.5"},
      {"series_cycle.json", "variants[0].extends: a cycle of extends: a → c → b → a"},
      {"series_missing_base.json", "base: {scenes}/no_such_scene.json: no such scene file"},
      // A name the system refuses is named as bad input, not thrown as a filesystem error (found by fuzz_series).
      {"series_base_name_too_long.json", "base: {scenes}/" + std::string(300, 'n') + ".json: File name too long"},
      {"series_unknown_structure.json",
       "variants[0].expect.image[1]: unknown structure \"banana\" (the analyzer's classes: none, clipped, "
       "mixed, point, linear, thickened-line, L, skewed-T, fork, gamma, curved, thickened, volume, P, superposed, "
       "planar)"},
      {"series_unknown_bend_cause.json",
       "variants[0].expect.ball.bent_by: unknown cause \"the lamp\" (causes: camera curve, mixing at edges, highlight lobe, "
       "interreflection)"},
      {"series_unknown_thickening_cause.json",
       "variants[0].expect.ball.thickened_by: unknown cause \"noise\" (causes: interreflection)"},
      {"series_unknown_components.json",
       "variants[0].components: unknown component family \"passes\" (known: paths, lights, bounces, all)"},
      {"series_unknown_target.json",
       "variants[0].expect.wals: \"wals\" is neither an object of the scene (floor, ball) nor a group (walls, image)"},
  };
  return cases;
}

inline std::string bad_scenes_dir() { return std::string(CHROMATRACE_TEST_DATA) + "/scenes/bad"; }

// The full message for a case: "<path>: <message>" with {dir} filled in.
inline std::string expected_message(const BadScene& bad) {
  std::string message = bad.message;
  const std::string token = "{dir}";
  if (const auto at = message.find(token); at != std::string::npos) message.replace(at, token.size(), bad_scenes_dir());
  const std::string scenes = "{scenes}";  // the folder above bad/
  if (const auto at = message.find(scenes); at != std::string::npos)
    message.replace(at, scenes.size(), std::string(CHROMATRACE_TEST_DATA) + "/scenes");
  return bad_scenes_dir() + "/" + bad.file + ": " + message;
}

}  // namespace ct::test
