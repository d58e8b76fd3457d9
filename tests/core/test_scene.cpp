// SPDX-License-Identifier: Apache-2.0
// The scene format: validation messages, spectrum sources, the data model, the shipped scenes and series.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "core/cie.h"
#include "core/error.h"
#include "core/rgb_to_spectrum.h"
#include "core/scene.h"
#include "core/series_format.h"
#include "core/structures.h"
#include "tests/core/bad_scenes.h"

namespace ct {
namespace {
namespace fs = std::filesystem;

const std::filesystem::path kScenes = std::filesystem::path(CHROMATRACE_SOURCE_DIR) / "scenes";
const std::filesystem::path kTestScenes = std::filesystem::path(CHROMATRACE_TEST_DATA) / "scenes";

Json minimal_document() { return read_json(kTestScenes / "minimal.json"); }

// The minimal test scene with a JSON Merge Patch applied, validated as if it were "test.json" beside it.
Scene minimal_with(const Json& patch) {
  Json document = minimal_document();
  document.merge_patch(patch);
  return parse_scene(document, "test.json", kTestScenes);
}

std::string error_of(const Json& patch) {
  try {
    minimal_with(patch);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string error_of_json(const std::string& text) {
  try {
    parse_json(text, "x.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// A spectrum given inline as the wall's reflectance, resolved.
PiecewiseLinearSpectrum wall_reflectance(const Json& source) {
  const Scene scene = minimal_with({{"materials", {{"wall", {{"reflectance", source}}}}}});
  return std::get<LambertMaterial>(scene.find_material("wall")->model).reflectance.spectrum;
}

PiecewiseLinearSpectrum lamp_radiance(const Json& source) {
  Json document = minimal_document();
  document["lights"][0]["radiance"] = source;
  return parse_scene(document, "test.json", kTestScenes).lights[0].radiance.spectrum;
}

// ---- Bad input -----------------------------------------------------------------------------------------

TEST(Scene, BadScenesGetOneLineNamingFileAndJsonPath) {
  for (const test::BadScene& bad : test::bad_scenes()) {
    const std::filesystem::path file = test::bad_scenes_dir() + "/" + bad.file;
    try {
      if (bad.file.starts_with("series"))
        load_series(file);
      else
        load_scene(file);
      ADD_FAILURE() << bad.file << ": no error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.what(), test::expected_message(bad)) << bad.file;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << bad.file;
    }
  }
}

TEST(Scene, TypeAndRangeErrors) {
  EXPECT_EQ(error_of({{"render", {{"samples", 2.5}}}}),
            "test.json: render.samples: must be a whole number, got number 2.5");
  EXPECT_EQ(error_of({{"render", {{"samples", 0}}}}), "test.json: render.samples: must be >= 1, got 0");
  EXPECT_EQ(error_of({{"render", {{"pixel_filter", "gauss"}}}}),
            "test.json: render.pixel_filter: must be one of \"box\", \"point\", got \"gauss\"");
  EXPECT_EQ(error_of({{"render", {{"tessellation", {{"segments", 2}}}}}}),
            "test.json: render.tessellation.segments: must be >= 3, got 2");
  EXPECT_EQ(error_of({{"camera", {{"position", {0, 1}}}}}),
            "test.json: camera.position: must be an array of 3 numbers [x, y, z], got an array");
  EXPECT_EQ(error_of({{"camera", {{"fov_deg", 180}}}}), "test.json: camera.fov_deg: must be < 180, got 180");
  EXPECT_EQ(error_of({{"camera", {{"look_at", {0, -3, 1}}}}}), "test.json: camera.look_at: must differ from position");
  EXPECT_EQ(error_of({{"camera", {{"look_at", {0, -3, 0}}}}}),
            "test.json: camera: the default up [0, 0, 1] is parallel to the viewing direction; give \"up\"");
  EXPECT_EQ(error_of({{"materials", {{"wall", {{"type", "glass"}}}}}}),
            "test.json: materials.wall.type: must be one of \"lambert\", \"dichromatic\", \"mirror\", \"principled\", got \"glass\"");
  EXPECT_EQ(error_of({{"materials", {{"plastic", {{"exponent", 20}}}}}}),
            "test.json: materials.plastic.exponent: applies only to \"lobe\": \"phong\"");
  EXPECT_EQ(error_of({{"materials", {{"wall", {{"reflectance", {{"constant", -0.1}}}}}}}}),
            "test.json: materials.wall.reflectance: values must be >= 0, got -0.1");
  EXPECT_EQ(error_of({{"materials", {{"wall", {{"reflectance", 0.5}}}}}}),
            "test.json: materials.wall.reflectance: must be a spectrum name or an object with one of \"csv\", "
            "\"constant\", \"blackbody_k\", \"illuminant\", \"samples\", \"rgb\", got number 0.5");
  EXPECT_EQ(error_of({{"spectra", {{"white", 0.5}}}}),
            "test.json: spectra.white: must be an object with one of \"csv\", \"constant\", \"blackbody_k\", "
            "\"illuminant\", \"samples\", \"rgb\", got number 0.5");
  EXPECT_EQ(error_of({{"materials", {{"wall", {{"reflectance", {{"constant", 0.5}, {"rgb", {1, 1, 1}}}}}}}}}),
            "test.json: materials.wall.reflectance: gives both \"constant\" and \"rgb\"; a spectrum has one source");
  EXPECT_EQ(
      error_of(
          {{"objects",
            {{{"name", "q"},
              {"material", "wall"},
              {"shape", {{"type", "quad"}, {"corner", {0, 0, 0}}, {"edge1", {1, 0, 0}}, {"edge2", {2, 0, 0}}}}}}}}),
      "test.json: objects[0].shape: edge1 and edge2 are parallel or zero, so the quad has no area");
  EXPECT_EQ(
      error_of({{"lights", {{{"name", "lamp"}, {"radiance", {{"constant", 1}}}, {"shape", {{"type", "cylinder"}}}}}}}),
      "test.json: lights[0].shape.type: must be one of \"quad\", \"sphere\", got \"cylinder\"");
  EXPECT_EQ(
      error_of({{"lights",
                 {{{"name", "lamp"},
                   {"radiance", {{"constant", 1}}},
                   {"group", "a.b"},
                   {"shape", {{"type", "sphere"}, {"center", {0, 0, 2}}, {"radius", 0.1}}}}}}}),
      "test.json: lights[0].group: \"a.b\" cannot name an output component: use letters, digits, \"_\" and \"-\"");
}

TEST(Scene, DuplicateKeysAreNamedByTheirPath) {
  EXPECT_EQ(error_of_json("{\"objects\": [{}, {\"a\": [1, {\"b\": 2, \"b\": 3}]}]}"),
            "x.json: objects[1].a[1].b: key appears twice in one object");
  EXPECT_EQ(error_of_json("[1, 2"),
            "x.json: line 1, column 6: syntax error while parsing array - unexpected end of "
            "input; expected ']'");
}

TEST(Scene, JsonWholeNumbersMayBeWrittenAsFloats) {
  EXPECT_EQ(minimal_with({{"render", {{"samples", 256.0}}}}).render.samples, 256);
}

// ---- Spectrum sources ------------------------------------------------------------------------------------

TEST(Scene, SpectrumSources) {
  // constant: flat everywhere
  const PiecewiseLinearSpectrum constant = wall_reflectance({{"constant", 0.25}});
  EXPECT_EQ(constant(300.0), 0.25);
  EXPECT_EQ(constant(900.0), 0.25);

  // samples: linear in between; zero outside unless clamped
  const PiecewiseLinearSpectrum zero = wall_reflectance({{"samples", {{400, 0.2}, {600, 0.6}}}});
  EXPECT_DOUBLE_EQ(zero(500.0), 0.4);
  EXPECT_EQ(zero(700.0), 0.0);
  const PiecewiseLinearSpectrum clamped =
      wall_reflectance({{"samples", {{400, 0.2}, {600, 0.6}}}, {"extend", "clamp"}});
  EXPECT_EQ(clamped(700.0), 0.6);
  EXPECT_EQ(clamped(380.0), 0.2);

  // csv: relative to the scene file; a CSV with one value column needs no "column"
  const PiecewiseLinearSpectrum csv = wall_reflectance({{"csv", "one_column.csv"}});
  EXPECT_EQ(csv(450.0), 0.2);
  EXPECT_DOUBLE_EQ(csv(475.0), 0.35);

  // rgb: the Jakob-Hanika upsampling of core/rgb_to_spectrum.h
  const PiecewiseLinearSpectrum rgb = wall_reflectance({{"rgb", {0.2, 0.5, 0.3}}});
  EXPECT_EQ(rgb.values(), rgb_to_spectrum({0.2, 0.5, 0.3}).values());

  // rgb as a light's radiance: relative to D65 (rgb_to_emission_spectrum), so (1, 1, 1) is D65, not flat
  EXPECT_EQ(lamp_radiance({{"rgb", {0.2, 0.5, 0.3}}}).values(), rgb_to_emission_spectrum({0.2, 0.5, 0.3}).values());
  const PiecewiseLinearSpectrum white_lamp = lamp_radiance({{"rgb", {1.0, 1.0, 1.0}}});
  EXPECT_NEAR(white_lamp(450.0) / white_lamp(650.0), cie::illuminant("D65")(450.0) / cie::illuminant("D65")(650.0), 1e-12);

  // illuminants, as tabulated (relative, 100 at 560 nm)
  EXPECT_EQ(lamp_radiance({{"illuminant", "D65"}}).values(), cie::illuminant("D65").values());
  EXPECT_EQ(lamp_radiance({{"illuminant", "D"}, {"cct_k", 5500}}).values(), cie::daylight(5500).values());

  // blackbody: Planck's law normalised to 1 at its maximum (5000 K peaks at Wien's 579.6 nm)
  const PiecewiseLinearSpectrum warm = lamp_radiance({{"blackbody_k", 5000}});
  const double peak_nm = kWien / 5000.0 * 1e9;
  EXPECT_NEAR(warm(peak_nm), 1.0, 1e-5);
  EXPECT_NEAR(warm(450.0) / warm(650.0), planck(450.0, 5000.0) / planck(650.0, 5000.0), 1e-12);
}

TEST(Scene, NamedAndInlineSpectraAreResolved) {
  const Scene scene = minimal_with(Json::object());
  ASSERT_EQ(scene.spectra.size(), 1u);
  EXPECT_EQ(scene.spectra[0].name, "white");
  const auto& wall = std::get<LambertMaterial>(scene.find_material("wall")->model);
  EXPECT_EQ(wall.reflectance.name, "white");
  EXPECT_EQ(wall.reflectance.spectrum.values(), scene.spectra[0].spectrum.values());
  const auto& plastic = std::get<DichromaticMaterial>(scene.find_material("plastic")->model);
  EXPECT_EQ(plastic.diffuse.name, "");
  EXPECT_EQ(plastic.specular, 0.1);
  ASSERT_TRUE(std::holds_alternative<DichromaticMaterial::Ggx>(plastic.lobe));
  EXPECT_DOUBLE_EQ(std::get<DichromaticMaterial::Ggx>(plastic.lobe).alpha(), 0.04);  // roughness 0.2, squared
}

// A named {"rgb"} spectrum is the colour's reflectance where a material uses it and the colour relative to D65
// where a light or the environment emits it; a spectra list reads its "radiance" entries as emitted.
TEST(Scene, NamedRgbSpectrumIsEmittedRelativeToD65) {
  Json document = minimal_document();
  document["spectra"]["paint"] = {{"rgb", {0.9, 0.6, 0.2}}};
  document["materials"]["wall"]["reflectance"] = "paint";
  document["lights"][0]["radiance"] = "paint";
  document["environment"] = {{"radiance", "paint"}};
  const Scene scene = parse_scene(document, "test.json", kTestScenes);
  EXPECT_EQ(std::get<LambertMaterial>(scene.find_material("wall")->model).reflectance.spectrum.values(),
            rgb_to_spectrum({0.9, 0.6, 0.2}).values());
  EXPECT_EQ(scene.lights[0].radiance.spectrum.values(), rgb_to_emission_spectrum({0.9, 0.6, 0.2}).values());
  EXPECT_EQ(scene.environment->radiance.spectrum.values(), rgb_to_emission_spectrum({0.9, 0.6, 0.2}).values());

  const Json list = {{"format", "chromatrace-spectra/1"},
                     {"spectra", {{"paint", {{"rgb", {0.9, 0.6, 0.2}}}}}},
                     {"radiance", {{"lamp", {{"rgb", {0.9, 0.6, 0.2}}}}, {"tube", {{"illuminant", "F11"}}}}}};
  const std::vector<NamedSpectrum> spectra = parse_spectra(list, "list.json", kTestScenes);
  ASSERT_EQ(spectra.size(), 3u);
  EXPECT_EQ(spectra[0].spectrum.values(), rgb_to_spectrum({0.9, 0.6, 0.2}).values());
  EXPECT_EQ(spectra[1].name, "lamp");
  EXPECT_EQ(spectra[1].spectrum.values(), rgb_to_emission_spectrum({0.9, 0.6, 0.2}).values());
  EXPECT_EQ(spectra[2].spectrum.values(), cie::illuminant("F11").values());
  Json clash = list;
  clash["radiance"]["paint"] = {{"constant", 1.0}};
  try {
    parse_spectra(clash, "list.json", kTestScenes);
    ADD_FAILURE() << "a name in both sections was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "list.json: radiance.paint: \"paint\" is already the name of an entry of \"spectra\"");
  }
}

TEST(Scene, CsvErrorsNameTheScenePathAndTheCsv) {
  EXPECT_EQ(
      error_of({{"spectra",
                 {{"white",
                   {{"csv", "../../../scenes/spectra/cornell_box.csv"}, {"samples", nullptr}, {"extend", nullptr}}}}}}),
      "test.json: spectra.white: " +
          (kTestScenes / "../../../scenes/spectra/cornell_box.csv").lexically_normal().string() +
          " has several columns (white, red, green); choose one with \"column\"");
  EXPECT_EQ(
      error_of(
          {{"spectra",
            {{"white", {{"csv", "one_column.csv"}, {"column", "paint"}, {"samples", nullptr}, {"extend", nullptr}}}}}}),
      "test.json: spectra.white.column: " + (kTestScenes / "one_column.csv").string() +
          " has no column \"paint\" (columns: value)");
}

// ---- Data model ------------------------------------------------------------------------------------------

TEST(Scene, ObjectIdsLightsAndDefaults) {
  const Scene scene = load_scene(kTestScenes / "minimal.json");
  EXPECT_EQ(scene.name, "minimal");  // the file's stem when the document has no name
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[0].id, 1);
  EXPECT_EQ(scene.objects[1].id, 2);
  EXPECT_EQ(scene.objects[1].material, 1u);  // "plastic"
  ASSERT_EQ(scene.lights.size(), 1u);
  const Light& lamp = scene.lights[0];
  EXPECT_EQ(lamp.id, 3);
  EXPECT_EQ(scene.id_count(), 3);
  EXPECT_EQ(lamp.group, "lamp");  // defaults to the name
  EXPECT_FALSE(lamp.two_sided);
  EXPECT_FALSE(lamp.material.has_value());
  // 3000 K peaks beyond 830 nm, so its normalised maximum over 300-830 nm is at 830 nm; times scale 5.
  EXPECT_NEAR(lamp.emitted_radiance()(830.0), 5.0, 1e-9);

  // The sphere sets 16 segments; its rings default to half of them.
  const auto& ball = std::get<SphereShape>(scene.objects[1].shape);
  EXPECT_EQ(ball.segments, 16);
  EXPECT_EQ(ball.rings, 8);
  EXPECT_EQ(scene.render.samples, 64);
  EXPECT_EQ(scene.render.max_bounces, 8);
  EXPECT_EQ(scene.render.bands, Bands::uniform(380, 780, 10));
  EXPECT_EQ(scene.json, minimal_document());  // kept for embedding in outputs

  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  ASSERT_EQ(meshes.size(), 3u);
  EXPECT_EQ(meshes[1].triangles.size(), 2u * 16u * 7u);
}

TEST(Scene, RenderTessellationIsTheDefaultForShapes) {
  const Scene scene = minimal_with({{"render", {{"tessellation", {{"segments", 12}, {"rings", 5}}}}},
                                    {"objects",
                                     {{{"name", "ball"},
                                       {"material", "wall"},
                                       {"shape", {{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1}}}},
                                      {{"name", "can"},
                                       {"material", "wall"},
                                       {"shape",
                                        {{"type", "cylinder"},
                                         {"base", {0, 0, 0}},
                                         {"axis", {0, 0, 2}},
                                         {"radius", 1},
                                         {"height", 1},
                                         {"caps", false}}}}}}});
  const auto& ball = std::get<SphereShape>(scene.objects[0].shape);
  EXPECT_EQ(ball.segments, 12);
  EXPECT_EQ(ball.rings, 5);
  const auto& can = std::get<CylinderShape>(scene.objects[1].shape);
  EXPECT_EQ(can.segments, 12);
  EXPECT_FALSE(can.caps);
  EXPECT_EQ(can.axis, Vec3(0, 0, 1));  // normalised
}

TEST(Scene, CameraFocalLengthAndOffAxisAngle) {
  // The Cornell camera: a 25 mm square film, 39.3077° on the smaller axis -> f = 12.5 / tan(19.65°) = 35 mm.
  const Camera camera = load_scene(kScenes / "cornell_box/cornell_box.json").camera;
  EXPECT_NEAR(camera.focal_length_mm(), 35.0, 1e-4);
  EXPECT_NEAR(camera.off_axis_angle(128, 128), 0.0, 1e-15);
  EXPECT_NEAR((camera.ray_direction(128, 128) - camera.forward()).norm(), 0.0, 1e-15);
  // The image corner is 12.5·√2 mm off axis on the sensor.
  EXPECT_NEAR(camera.off_axis_angle(0, 0), std::atan(12.5 * std::sqrt(2.0) / 35.0), 1e-6);
  for (const auto& [px, py] : {std::pair{10.5, 200.5}, {255.5, 0.5}, {64.0, 64.0}})
    EXPECT_NEAR(std::cos(camera.off_axis_angle(px, py)), camera.ray_direction(px, py).dot(camera.forward()), 1e-14);
  // Image x grows to the right, image y downwards.
  EXPECT_GT(camera.ray_direction(255.5, 128).dot(camera.right()), 0.0);
  EXPECT_LT(camera.ray_direction(128, 255.5).dot(camera.image_up()), 0.0);

  // fov_axis: the minimal scene's 40° is horizontal on a 64 x 48 image.
  const Scene minimal = minimal_with(Json::object());
  EXPECT_NEAR(minimal.camera.tan_half_width(), std::tan(20.0 * std::numbers::pi / 180.0), 1e-15);
  EXPECT_NEAR(minimal.camera.tan_half_height(), std::tan(20.0 * std::numbers::pi / 180.0) * 48 / 64, 1e-15);
  for (const auto& [axis, tan_half_height] :
       {std::pair{"vertical", 1.0}, {"smaller", 1.0}, {"larger", 48.0 / 64.0}, {"horizontal", 48.0 / 64.0}}) {
    const Camera c = minimal_with({{"camera", {{"fov_axis", axis}, {"fov_deg", 90}}}}).camera;
    EXPECT_NEAR(c.tan_half_height(), tan_half_height, 1e-15) << axis;
  }
}

// ---- Shipped scenes ------------------------------------------------------------------------------------

Vec3 mean_position(const TriangleMesh& mesh) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& p : mesh.positions) sum += p;
  return sum / static_cast<double>(mesh.positions.size());
}

const Object& object_named(const Scene& scene, std::string_view name) {
  const auto it =
      std::find_if(scene.objects.begin(), scene.objects.end(), [&](const Object& o) { return o.name == name; });
  if (it == scene.objects.end()) throw std::logic_error("no object " + std::string(name));
  return *it;
}

TEST(ShippedScenes, CornellBoxKeepsRedWallLeftAndLightFacingDown) {
  const Scene scene = load_scene(kScenes / "cornell_box/cornell_box.json");
  const Camera& camera = scene.camera;
  auto sideways = [&](std::string_view name) {
    return (mean_position(tessellate(object_named(scene, name).shape)) - camera.position).dot(camera.right());
  };
  EXPECT_LT(sideways("red_wall"), -0.25);  // viewer's left, as in the Cornell data
  EXPECT_GT(sideways("green_wall"), 0.25);

  ASSERT_EQ(scene.lights.size(), 1u);
  const auto& light = std::get<QuadShape>(scene.lights[0].shape);
  EXPECT_NEAR((light.normal() - Vec3(0, 0, -1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(surface_area(light), 0.130 * 0.105, 1e-12);
  EXPECT_TRUE(scene.lights[0].material.has_value());

  // About 0.55 m across in every direction, the floor at Z = 0, the luminaire just under the ceiling.
  Bounds extent;
  for (const TriangleMesh& mesh : scene_meshes(scene)) extent.extend(bounds(mesh));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(extent.hi[k] - extent.lo[k], 0.555, 0.01) << "axis " << k;
  EXPECT_EQ(extent.lo.z(), 0.0);
  EXPECT_NEAR(light.corner.z(), 0.5488 - 0.0005, 1e-12);

  // Walls face into the box; the blocks' faces point out of the blocks.
  const Vec3 centre = 0.5 * (extent.lo + extent.hi);
  for (const Object& object : scene.objects) {
    const TriangleMesh mesh = tessellate(object.shape);
    const bool block = object.name.ends_with("block");
    const Vec3 inside = block ? mean_position(mesh) : centre;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& [a, b, c] = mesh.triangles[t];
      const Vec3 middle = (mesh.positions[a] + mesh.positions[b] + mesh.positions[c]) / 3.0;
      const double facing = face_normal(mesh, t).dot(inside - middle);
      EXPECT_TRUE(block ? facing < 0.0 : facing > 0.0) << object.name << " triangle " << t;
    }
  }
  EXPECT_EQ(scene.render.bands, Bands::uniform(400, 700, 10));
}

TEST(ShippedScenes, PaperBoxHasDistinctSurfacesAndACeilingLightFacingDown) {
  const Scene scene = load_scene(kScenes / "paper/box.json");
  for (const char* name : {"floor", "ceiling", "back_wall", "left_wall", "right_wall", "sphere", "cylinder"})
    EXPECT_NO_THROW(object_named(scene, name)) << name;
  EXPECT_TRUE(std::holds_alternative<SphereShape>(object_named(scene, "sphere").shape));
  EXPECT_TRUE(std::holds_alternative<CylinderShape>(object_named(scene, "cylinder").shape));

  // Walls Lambertian, sphere and cylinder dichromatic with GGX, every surface its own reflectance.
  std::vector<std::vector<double>> reflectances;
  for (const Object& object : scene.objects) {
    const Material& material = scene.materials[object.material];
    const bool curved = object.name == "sphere" || object.name == "cylinder";
    EXPECT_STREQ(material_type_name(material), curved ? "dichromatic" : "lambert") << object.name;
    const SpectrumRef& body = curved ? std::get<DichromaticMaterial>(material.model).diffuse
                                     : std::get<LambertMaterial>(material.model).reflectance;
    if (curved) {
      EXPECT_TRUE(std::holds_alternative<DichromaticMaterial::Ggx>(std::get<DichromaticMaterial>(material.model).lobe));
    }
    EXPECT_EQ(std::count(reflectances.begin(), reflectances.end(), body.spectrum.values()), 0) << object.name;
    reflectances.push_back(body.spectrum.values());
  }

  ASSERT_EQ(scene.lights.size(), 1u);
  const auto& light = std::get<QuadShape>(scene.lights[0].shape);
  EXPECT_NEAR((light.normal() - Vec3(0, 0, -1)).norm(), 0.0, 1e-12);
  Bounds box;
  for (const Object& object : scene.objects) box.extend(bounds(tessellate(object.shape)));
  const Bounds lamp = bounds(tessellate(light));
  EXPECT_TRUE((lamp.lo.array() > box.lo.array()).all() && (lamp.hi.array() < box.hi.array()).all());
  EXPECT_GT(lamp.lo.z(), 1.9);  // on the ceiling

  // Every wall faces the inside of the box; the camera looks in through the open side.
  const Vec3 centre = 0.5 * (box.lo + box.hi);
  for (const char* name : {"floor", "ceiling", "back_wall", "left_wall", "right_wall"}) {
    const auto& quad = std::get<QuadShape>(object_named(scene, name).shape);
    EXPECT_GT(quad.normal().dot(centre - quad.corner), 0.0) << name;
  }
  EXPECT_LT(scene.camera.position.y(), box.lo.y());
}

// ---- Series --------------------------------------------------------------------------------------------

TEST(Series, PaperSeriesValidatesEveryStep) {
  const Series series = load_series(kScenes / "paper/series.json", 2);
  ASSERT_EQ(series.variants.size(), 13u);
  EXPECT_EQ(series.base_scene.name, "paper-box");
  auto variant = [&](std::string_view name) -> const SeriesVariant& {
    return *std::find_if(series.variants.begin(), series.variants.end(),
                         [&](const SeriesVariant& v) { return v.name == name; });
  };

  const SeriesVariant& first = variant("1-lambert-direct");
  EXPECT_EQ(first.scene.render.max_bounces, 1);
  for (const Material& m : first.scene.materials) EXPECT_STREQ(material_type_name(m), "lambert") << m.name;
  ASSERT_EQ(first.expect.size(), 4u);
  EXPECT_EQ(first.expect[0].target, "walls");
  EXPECT_EQ(first.expect[0].objects, (std::vector<std::string>{"floor", "back_wall", "left_wall", "right_wall"}));
  EXPECT_EQ(first.expect[0].any_of, std::vector<std::string>{"linear"});
  EXPECT_EQ(first.expect[1].objects, std::vector<std::string>{"sphere"});

  EXPECT_EQ(variant("2-object-spectra").scene.find_spectrum("grey"), nullptr);  // deleted with null
  EXPECT_STREQ(material_type_name(*variant("3-specular").scene.find_material("sphere")), "dichromatic");
  EXPECT_EQ(variant("4-luminaire-spectrum").scene.lights[0].radiance.spectrum.values(), cie::illuminant("A").values());

  const Scene& two = variant("5-two-luminaires").scene;
  ASSERT_EQ(two.lights.size(), 2u);
  EXPECT_EQ(two.lights[0].group, "warm");
  EXPECT_EQ(two.lights[1].group, "cool");
  EXPECT_EQ(variant("6b-dichromatic-global").scene.render.max_bounces, 8);
  EXPECT_EQ(variant("7a-pixel-area").scene.render.pixel_filter, PixelFilter::Box);

  // Sensor settings merge along "extends": 7d adds noise to step 1's ideal sensor.
  const Json& sensor = variant("7d-noise").sensor;
  EXPECT_EQ(sensor["noise"]["enabled"], true);
  EXPECT_EQ(sensor["rendering"]["curve"], "linear");
  EXPECT_EQ(sensor["adc"]["bits"], 10);

  // The eight panels of the paper's Figures 3 and 4, each reproduced by one variant, and the banana beside 3d.
  std::vector<std::string> panels;
  for (const SeriesVariant& v : series.variants) panels.insert(panels.end(), v.figure.begin(), v.figure.end());
  std::sort(panels.begin(), panels.end());
  EXPECT_EQ(panels, (std::vector<std::string>{"3a", "3b", "3c", "3d", "3e", "4a", "4b", "4c", "4d"}));

  // The object form of an expectation: classes, the causes of the bend and of the thickening, and the paper's word;
  // extra components.
  const SeriesVariant& box_3d = variant("6b-dichromatic-global");
  ASSERT_EQ(box_3d.expect.size(), 4u);
  EXPECT_EQ(box_3d.expect[2].target, "sphere");
  EXPECT_EQ(box_3d.expect[2].any_of, (std::vector<std::string>{"thickened", "volume", "P"}));
  EXPECT_EQ(box_3d.expect[2].bent_by, "highlight lobe");
  EXPECT_EQ(box_3d.expect[2].thickened_by, "interreflection");
  EXPECT_EQ(box_3d.expect[2].paper, "curved");
  EXPECT_EQ(box_3d.expect[0].bent_by, "");
  EXPECT_EQ(box_3d.expect[0].thickened_by, "interreflection");
  EXPECT_EQ(variant("6c-banana").components, "bounces");
  EXPECT_EQ(variant("6c-banana").scene.render.max_bounces, 12);

  // Paths come out absolute, so the resolved scene can be written anywhere.
  const std::string csv = first.scene.json["spectra"]["beige"]["csv"];
  EXPECT_TRUE(std::filesystem::path(csv).is_absolute()) << csv;
  EXPECT_TRUE(std::filesystem::exists(csv)) << csv;
}

TEST(Series, RebasedScenePathsResolveFromTheirNewFolder) {
  const Series series = load_series(kScenes / "paper/series.json");
  const fs::path folder = fs::temp_directory_path() / "chromatrace_rebase";
  fs::create_directories(folder / "sub");
  const Json moved = rebase_scene_paths(series.variants[2].scene.json, {}, folder / "sub");
  const std::string csv = moved["spectra"]["beige"]["csv"];
  EXPECT_TRUE(fs::path(csv).is_relative()) << csv;
  EXPECT_TRUE(fs::exists(folder / "sub" / csv)) << csv;
  // The moved scene parses from its new folder to the same spectra.
  const Scene again = parse_scene(moved, "moved", folder / "sub");
  EXPECT_EQ(again.find_spectrum("beige")->spectrum.values(), series.variants[2].scene.find_spectrum("beige")->spectrum.values());
  fs::remove_all(folder);
}

TEST(Series, ExpectationsUseTheAnalyzersWords) {
  // Every word in a shipped series is a structure of core/structures.h, and each names itself back.
  for (const SeriesVariant& v : load_series(kScenes / "paper/series.json").variants)
    for (const Expectation& e : v.expect)
      for (const std::string& word : e.any_of) {
        const auto s = structure_from_word(word);
        ASSERT_TRUE(s) << v.name << ": " << word;
        EXPECT_EQ(structure_word(*s), word);
      }
  EXPECT_FALSE(structure_from_word("banana"));  // the paper's word; the analyzer's class is "curved"
  EXPECT_FALSE(structure_from_word("l"));
}

// docs/analyze.md defines every structure by numbers: one row of its class table per word.
TEST(Series, EveryStructureIsDefinedInTheDocs) {
  std::ifstream file(fs::path(CHROMATRACE_SOURCE_DIR) / "docs" / "analyze.md");
  const std::string docs((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  for (const StructureWord& w : kStructureWords)
    EXPECT_NE(docs.find(fmt::format("\n| `{}` |", w.word)), std::string::npos) << w.word;
}

TEST(Series, JsonMergePatchSemantics) {
  // RFC 7386: objects merge key by key, null deletes a key, arrays (and any non-object) replace.
  const Series series = load_series(kTestScenes / "series_merge.json");
  ASSERT_EQ(series.variants.size(), 2u);
  const Json& a = series.variants[0].scene.json;
  EXPECT_EQ(a["render"], (Json{{"seed", 7}, {"samples", 4}}));
  EXPECT_EQ(a["camera"]["resolution"], Json::array({32, 32}));
  EXPECT_EQ(a["camera"]["fov_deg"], 40);  // untouched keys of a merged object stay

  const SeriesVariant& b = series.variants[1];
  EXPECT_EQ(b.scene.json["render"], (Json{{"samples", 4}}));  // "seed": null deleted it ...
  EXPECT_EQ(b.scene.render.seed, 1u);                         // ... so the default applies
  EXPECT_EQ(b.scene.json["spectra"]["white"], (Json{{"samples", {{400, 0.2}, {700, 0.3}}}}));  // array replaced
  EXPECT_EQ(b.scene.spectra[0].spectrum(750.0), 0.0);  // "extend": null removed the clamp
  ASSERT_EQ(b.scene.lights.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<SphereShape>(b.scene.lights[0].shape));  // the lights array was replaced
  EXPECT_EQ(b.patch["render"]["seed"], nullptr);                              // the patch is kept as given
  EXPECT_EQ(b.sensor, (Json{{"gain", 2}, {"bits", 12}}));
}

TEST(Series, VariantErrors) {
  EXPECT_THROW(load_series(kScenes / "paper/box.json"), InputError);  // a scene is not a series
  try {
    load_series(kTestScenes / "bad/series_bad_variant.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_TRUE(std::string(e.what()).find("variants[1] \"rough\": materials.plastic.roughness") != std::string::npos);
  }
}

// The render defaults are core/data/defaults.json's (the file the Blender add-on reads too), and
// docs/scene-format.md's table states them.
TEST(RenderDefaults, AreTheSharedFilesAndTheDocsSayThem) {
  const std::filesystem::path source(CHROMATRACE_SOURCE_DIR);
  std::ifstream file(source / "core" / "data" / "defaults.json");
  const Json shared = Json::parse(file)["render"];
  const RenderSettings render;
  EXPECT_EQ(render.samples, shared["samples"].get<int>());
  EXPECT_EQ(render.max_bounces, shared["max_bounces"].get<int>());
  EXPECT_EQ(render.seed, shared["seed"].get<std::uint64_t>());
  EXPECT_EQ(render.pixel_filter == PixelFilter::Box ? "box" : "point", shared["pixel_filter"]);
  EXPECT_EQ(render.spectral_mode == SpectralMode::Bands ? "bands" : "continuous", shared["spectral_mode"]);
  EXPECT_EQ(render.bands.edges(), Bands::parse(shared["bands"].get<std::string>()).edges());
  EXPECT_EQ(render.bands.size(), 40u);  // 380:780:10, the docs' example
  std::ifstream docs_file(source / "docs" / "scene-format.md");
  const std::string docs((std::istreambuf_iterator<char>(docs_file)), std::istreambuf_iterator<char>());
  for (const std::string& row : {fmt::format("| `samples` | {} |", shared["samples"].get<int>()),
                                fmt::format("| `max_bounces` | {} |", shared["max_bounces"].get<int>()),
                                fmt::format("| `seed` | {} |", shared["seed"].get<int>()),
                                fmt::format("| `pixel_filter` | `\"{}\"` |", shared["pixel_filter"].get<std::string>()),
                                fmt::format("| `bands` | `\"{}\"` |", shared["bands"].get<std::string>()),
                                fmt::format("| `spectral_mode` | `\"{}\"` |", shared["spectral_mode"].get<std::string>())})
    EXPECT_NE(docs.find(row), std::string::npos) << row;
  // The illuminants the library knows are the ones the file names, each with its table.
  std::ifstream again(source / "core" / "data" / "defaults.json");
  EXPECT_EQ(cie::illuminant_names(), Json::parse(again)["illuminants"].get<std::vector<std::string>>());
  for (const std::string& name : cie::illuminant_names()) EXPECT_GT(cie::illuminant(name)(560.0), 0.0) << name;
}

}  // namespace
}  // namespace ct
