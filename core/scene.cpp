// SPDX-License-Identifier: Apache-2.0
#include "core/scene.h"

#include <algorithm>
#include <sstream>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <tuple>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/cie.h"
#include "core/csv.h"
#include "core/embedded_data.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/limits.h"
#include "core/named.h"
#include "core/ply.h"
#include "core/rgb_to_spectrum.h"

namespace ct {
namespace {

// Every spectrum must reach into the range of the CIE observer; a spectrum that does not was almost
// certainly written in µm or m instead of nm.
constexpr double kVisibleLo = 360.0;
constexpr double kVisibleHi = 830.0;
// Upper bound on tessellation parameters: 4096 × 2048 sphere triangles (16.7 M) is already far beyond
// what convergence needs, and a typo such as 64000 must not exhaust memory.
constexpr std::int64_t kMaxSegments = 4096;
constexpr std::int64_t kMaxIntSetting = std::numeric_limits<int>::max();

// The largest or smallest sample of a spectrum, with its wavelength. The extremes of a piecewise-linear
// function lie on its samples (and extrapolation adds only zero or the end values).
struct Sample {
  double value, nm;
};
Sample extreme_sample(const PiecewiseLinearSpectrum& s, bool largest) {
  const std::vector<double>& v = s.values();
  const auto it = largest ? std::max_element(v.begin(), v.end()) : std::min_element(v.begin(), v.end());
  return {*it, s.wavelengths()[static_cast<std::size_t>(it - v.begin())]};
}

std::string describe_sample(const PiecewiseLinearSpectrum& s, const Sample& sample) {
  return s.wavelengths().size() == 1 ? fmt::format("{}", sample.value)
                                     : fmt::format("{} at {} nm", sample.value, sample.nm);
}

void check_visible_overlap(const JsonNode& node, double lo, double hi) {
  if (hi < kVisibleLo || lo > kVisibleHi)
    node.fail(fmt::format("wavelengths {} to {} do not overlap the visible range {}-{} nm (wavelengths are in nm)", lo,
                          hi, kVisibleLo, kVisibleHi));
}

bool valid_group_name(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

Vec3 nonzero_vec3(const JsonNode& node) {
  const Vec3 v = node.vec3();
  if (!(v.norm() > 0.0)) node.fail("must not be the zero vector");
  return v;
}

std::string beyond_reach(double distance) {
  return fmt::format("reaches {} m from the origin, beyond the ±{} m the renderers represent (32-bit floats)",
                     distance, kMaxCoordinateM);
}

double farthest_coordinate(const Bounds& b) { return std::max(b.lo.cwiseAbs().maxCoeff(), b.hi.cwiseAbs().maxCoeff()); }

// A position: each coordinate within ±kMaxCoordinateM.
Vec3 point_vec3(const JsonNode& node) {
  const Vec3 p = node.vec3();
  const double distance = p.cwiseAbs().maxCoeff();
  if (distance > kMaxCoordinateM) node.fail(beyond_reach(distance));
  return p;
}

// The whole shape within ±kMaxCoordinateM (its edges, radius or mesh vertices may carry it beyond); `node` is
// the shape, or a mesh's "file".
void check_within_reach(const JsonNode& node, const Shape& shape) {
  const double distance = farthest_coordinate(bounds(shape));
  if (!(distance <= kMaxCoordinateM)) node.fail(beyond_reach(distance));
}

// The peak of radiance · scale within kMaxRadiance; `node` is the scale if given, else the radiance.
void check_radiance_range(const JsonNode& node, const SpectrumRef& radiance, double scale) {
  double peak = 0;
  if (radiance.texture) {  // a texture has no spectrum of its own: its texels' largest value
    const std::vector<float>& rgb = radiance.texture->rgb;
    peak = radiance.texture->scale * (rgb.empty() ? 0.0 : *std::max_element(rgb.begin(), rgb.end()));
  } else {
    peak = extreme_sample(radiance.spectrum, true).value;
  }
  const double emitted = peak * scale;
  if (!(emitted <= kMaxRadiance))
    node.fail(fmt::format("the peak radiance {} times the scale {} is {} W m⁻² sr⁻¹ nm⁻¹, beyond the {} the "
                          "renderers represent (32-bit floats)",
                          peak, scale, emitted, kMaxRadiance));
}

int segments_setting(const JsonNode& node) { return static_cast<int>(node.integer_in(3, kMaxSegments)); }
int rings_setting(const JsonNode& node) { return static_cast<int>(node.integer_in(2, kMaxSegments)); }

QuadShape read_quad(const JsonNode& node) {
  node.expect_object({"type", "corner", "edge1", "edge2"});
  const QuadShape quad{point_vec3(node["corner"]), node["edge1"].vec3(), node["edge2"].vec3()};
  if (!(surface_area(quad) > 0.0)) node.fail("edge1 and edge2 are parallel or zero, so the quad has no area");
  check_within_reach(node, quad);
  return quad;
}

SphereShape read_sphere(const JsonNode& node, const Tessellation& defaults) {
  node.expect_object({"type", "center", "radius", "segments", "rings"});
  SphereShape sphere;
  sphere.center = point_vec3(node["center"]);
  sphere.radius = node["radius"].number_above(0.0);
  check_within_reach(node, sphere);
  const auto segments = node.find("segments");
  const auto rings = node.find("rings");
  sphere.segments = segments ? segments_setting(*segments) : defaults.segments;
  sphere.rings = rings ? rings_setting(*rings) : defaults.rings.value_or(std::max(2, sphere.segments / 2));
  return sphere;
}

CylinderShape read_cylinder(const JsonNode& node, const Tessellation& defaults) {
  node.expect_object({"type", "base", "axis", "radius", "height", "caps", "segments"});
  CylinderShape cylinder;
  cylinder.base = point_vec3(node["base"]);
  cylinder.axis = nonzero_vec3(node["axis"]).normalized();
  cylinder.radius = node["radius"].number_above(0.0);
  cylinder.height = node["height"].number_above(0.0);
  check_within_reach(node, cylinder);
  const auto caps = node.find("caps");
  cylinder.caps = caps ? caps->boolean() : true;
  const auto segments = node.find("segments");
  cylinder.segments = segments ? segments_setting(*segments) : defaults.segments;
  return cylinder;
}

BoxShape read_box(const JsonNode& node) {
  node.expect_object({"type", "corner", "edge1", "edge2", "edge3"});
  const BoxShape box{point_vec3(node["corner"]), node["edge1"].vec3(), node["edge2"].vec3(), node["edge3"].vec3()};
  if (!(std::abs(box.edge1.cross(box.edge2).dot(box.edge3)) > 0.0))
    node.fail("edge1, edge2 and edge3 are coplanar, so the box has no volume");
  check_within_reach(node, box);
  return box;
}

MeshShape read_mesh(const JsonNode& node, const std::filesystem::path& directory) {
  node.expect_object({"type", "file"});
  const JsonNode file = node["file"];
  MeshShape mesh;
  mesh.file = file.non_empty_string();
  const std::filesystem::path path = (directory / mesh.file).lexically_normal();
  try {
    mesh.mesh = read_ply(path);
  } catch (const InputError& e) {
    file.fail(e.what());
  }
  if (mesh.mesh.triangles.empty()) file.fail(fmt::format("{}: has no faces", path.string()));
  const double distance = farthest_coordinate(bounds(mesh.mesh));
  if (!(distance <= kMaxCoordinateM)) file.fail(fmt::format("{}: a vertex {}", path.string(), beyond_reach(distance)));
  return mesh;
}

Camera read_camera(const JsonNode& node) {
  node.expect_object({"position", "look_at", "up", "fov_deg", "fov_axis", "resolution", "sensor_width_mm"});
  Camera camera;
  camera.position = point_vec3(node["position"]);
  camera.look_at = point_vec3(node["look_at"]);
  if (!((camera.look_at - camera.position).norm() > 0.0)) node["look_at"].fail("must differ from position");
  const auto up = node.find("up");
  camera.up = up ? nonzero_vec3(*up) : Vec3(Vec3::UnitZ());
  if (camera.forward().cross(camera.up.normalized()).norm() < 1e-9) {
    if (up) up->fail("is parallel to the viewing direction");
    node.fail("the default up [0, 0, 1] is parallel to the viewing direction; give \"up\"");
  }

  const JsonNode fov = node["fov_deg"];
  camera.fov_deg = fov.number_above(0.0);
  if (!(camera.fov_deg < 180.0)) fov.fail(fmt::format("must be < 180, got {}", camera.fov_deg));
  if (const auto axis = node.find("fov_axis")) {
    const std::string name = axis->choice({"horizontal", "vertical", "smaller", "larger"});
    camera.fov_axis = name == "horizontal" ? FovAxis::Horizontal
                      : name == "vertical" ? FovAxis::Vertical
                      : name == "smaller"  ? FovAxis::Smaller
                                           : FovAxis::Larger;
  }

  const JsonNode resolution = node["resolution"];
  const std::vector<JsonNode> size = resolution.elements();
  if (size.size() != 2) resolution.fail(fmt::format("must be [width, height], got {} numbers", size.size()));
  camera.width = static_cast<int>(size[0].integer_in(1, 65536));
  camera.height = static_cast<int>(size[1].integer_in(1, 65536));

  if (const auto sensor = node.find("sensor_width_mm")) {
    camera.sensor_width_mm = sensor->number();
    // Real sensors are a few mm to a few hundred mm wide; 0.036 is a width in metres.
    if (!(camera.sensor_width_mm >= 1.0 && camera.sensor_width_mm <= 1000.0))
      sensor->fail(fmt::format("must be a width in mm within [1, 1000], got {}", camera.sensor_width_mm));
  }
  return camera;
}

RenderSettings read_render(const JsonNode& node) {
  node.expect_object({"samples", "max_bounces", "seed", "pixel_filter", "bands", "spectral_mode", "tessellation"});
  RenderSettings render;
  if (const auto n = node.find("samples")) render.samples = static_cast<int>(n->integer_in(1, kMaxIntSetting));
  if (const auto n = node.find("max_bounces")) render.max_bounces = static_cast<int>(n->integer_in(0, kMaxBounces));
  if (const auto n = node.find("seed"))
    render.seed = static_cast<std::uint64_t>(n->integer_in(0, std::numeric_limits<std::int64_t>::max()));
  if (const auto n = node.find("pixel_filter"))
    render.pixel_filter = n->choice({"box", "point"}) == "box" ? PixelFilter::Box : PixelFilter::Point;
  if (const auto n = node.find("spectral_mode"))
    render.spectral_mode =
        n->choice({"bands", "continuous"}) == "bands" ? SpectralMode::Bands : SpectralMode::Continuous;
  if (const auto n = node.find("bands")) {
    render.bands = Bands::parse(n->string(), n->location());
    check_visible_overlap(*n, render.bands.min_wavelength(), render.bands.max_wavelength());
  }
  if (const auto t = node.find("tessellation")) {
    t->expect_object({"segments", "rings"});
    if (const auto n = t->find("segments")) render.tessellation.segments = segments_setting(*n);
    if (const auto n = t->find("rings")) render.tessellation.rings = rings_setting(*n);
  }
  return render;
}

// Reads the parts of one scene document that refer to each other: spectra by name, materials by name,
// and CSV tables, each file read once however many spectra use it.
class SceneReader {
 public:
  explicit SceneReader(std::filesystem::path directory) : directory_(std::move(directory)) {}

  Scene read(const JsonNode& root);
  std::vector<NamedSpectrum> read_spectra(const JsonNode& root);

 private:
  // `emitted`: where a radiance is expected, so that an {"rgb"} colour is relative to D65 (rgb_to_emission_spectrum).
  PiecewiseLinearSpectrum spectrum_source(const JsonNode& node, bool emitted = false);
  PiecewiseLinearSpectrum csv_spectrum(const JsonNode& node);
  PiecewiseLinearSpectrum illuminant_spectrum(const JsonNode& node);
  PiecewiseLinearSpectrum samples_spectrum(const JsonNode& node);
  SpectrumRef spectrum_ref(const JsonNode& node, bool emitted = false);
  SpectrumRef texture_ref(const JsonNode& node, TextureUse use);
  SpectrumRef radiance(const JsonNode& node);
  SpectrumRef reflectance(const JsonNode& node);
  Environment environment(const JsonNode& node);
  void check_texture_coordinates(const JsonNode& objects) const;
  Material material(const std::string& name, const JsonNode& node);
  PrincipledMaterial principled(const JsonNode& node);
  std::size_t material_index(const JsonNode& node) const;
  Shape object_shape(const JsonNode& node) const;
  LightShape light_shape(const JsonNode& node) const;
  Light light(const JsonNode& node);

  std::filesystem::path directory_;
  std::map<std::string, CsvTable> csv_tables_;
  std::map<std::tuple<std::string, int, int, double>, std::shared_ptr<const ImageTexture>> textures_;
  Scene scene_;
};

// The colour of an {"rgb": [r, g, b]} spectrum source (already checked by spectrum_source), else nothing.
std::optional<std::array<double, 3>> rgb_colour(const JsonNode& node) {
  if (!node.json().is_object() || !node.has("rgb")) return std::nullopt;
  const std::vector<JsonNode> c = node["rgb"].elements();
  return std::array<double, 3>{c[0].number(), c[1].number(), c[2].number()};
}

constexpr std::string_view kSpectrumObject =
    "an object with one of \"csv\", \"constant\", \"blackbody_k\", \"illuminant\", \"samples\", \"rgb\"";

PiecewiseLinearSpectrum SceneReader::spectrum_source(const JsonNode& node, bool emitted) {
  static constexpr std::string_view kinds[] = {"csv", "constant", "blackbody_k", "illuminant", "samples", "rgb"};
  if (!node.json().is_object())
    node.fail(fmt::format("must be {}, got {}", kSpectrumObject, describe_json(node.json())));
  std::vector<std::string_view> given;
  for (std::string_view kind : kinds)
    if (node.has(kind)) given.push_back(kind);
  if (given.size() != 1)
    node.fail(given.empty()
                  ? fmt::format("must be {}", kSpectrumObject)
                  : fmt::format("gives both \"{}\" and \"{}\"; a spectrum has one source", given[0], given[1]));

  PiecewiseLinearSpectrum spectrum;
  const std::string_view kind = given[0];
  if (kind == "csv") {
    spectrum = csv_spectrum(node);
  } else if (kind == "constant") {
    node.expect_object({"constant"});
    spectrum = PiecewiseLinearSpectrum::constant(node["constant"].number());
  } else if (kind == "blackbody_k") {
    node.expect_object({"blackbody_k"});
    // Normalised to 1 at its maximum over 300-830 nm: the light's scale sets the absolute radiance.
    spectrum = blackbody(node["blackbody_k"].number_in(100.0, 100000.0), 300.0, 830.0, 1.0, true);
  } else if (kind == "illuminant") {
    spectrum = illuminant_spectrum(node);
  } else if (kind == "samples") {
    spectrum = samples_spectrum(node);
  } else {
    node.expect_object({"rgb"});
    const JsonNode rgb = node["rgb"];
    const std::vector<JsonNode> c = rgb.elements();
    if (c.size() != 3) rgb.fail(fmt::format("must be [r, g, b], got {} numbers", c.size()));
    const std::array<double, 3> colour = {c[0].number_in(0.0, 1.0), c[1].number_in(0.0, 1.0), c[2].number_in(0.0, 1.0)};
    spectrum = emitted ? rgb_to_emission_spectrum(colour) : rgb_to_spectrum(colour);
  }

  const Sample lowest = extreme_sample(spectrum, false);
  if (lowest.value < 0.0) node.fail(fmt::format("values must be >= 0, got {}", describe_sample(spectrum, lowest)));
  check_visible_overlap(node, spectrum.min_wavelength(), spectrum.max_wavelength());
  return spectrum;
}

PiecewiseLinearSpectrum SceneReader::csv_spectrum(const JsonNode& node) {
  node.expect_object({"csv", "column", "extend"});
  const JsonNode csv = node["csv"];
  const std::string path = (directory_ / csv.non_empty_string()).lexically_normal().string();
  auto cached = csv_tables_.find(path);
  if (cached == csv_tables_.end()) {
    try {
      scene_.files.emplace_back(path);
      cached = csv_tables_.emplace(path, read_csv(path)).first;
    } catch (const InputError& e) {
      csv.fail(e.what());
    }
  }
  const CsvTable& table = cached->second;

  std::string column;
  if (const auto name = node.find("column")) {
    column = name->string();
    if (std::find(table.columns.begin(), table.columns.end(), column) == table.columns.end())
      name->fail(fmt::format("{} has no column \"{}\" (columns: {})", path, column, fmt::join(table.columns, ", ")));
  } else if (table.columns.size() == 1) {
    column = table.columns[0];
  } else {
    node.fail(
        fmt::format("{} has several columns ({}); choose one with \"column\"", path, fmt::join(table.columns, ", ")));
  }

  PiecewiseLinearSpectrum spectrum;
  try {
    spectrum = table.spectrum(column);
  } catch (const InputError& e) {
    csv.fail(e.what());
  }
  const bool clamp = node.has("extend") && node["extend"].choice({"zero", "clamp"}) == "clamp";
  return clamp ? PiecewiseLinearSpectrum(spectrum.wavelengths(), spectrum.values(), Extrapolation::Clamp, path)
               : spectrum;
}

PiecewiseLinearSpectrum SceneReader::illuminant_spectrum(const JsonNode& node) {
  node.expect_object({"illuminant", "cct_k"});
  const JsonNode name = node["illuminant"];
  const std::string illuminant = name.string();
  if (illuminant == "D") return cie::daylight(node["cct_k"].number_in(4000.0, 25000.0));
  if (const auto cct = node.find("cct_k")) cct->fail("applies only to \"illuminant\": \"D\" (daylight at a CCT)");
  try {
    return cie::illuminant(illuminant);
  } catch (const InputError& e) {
    name.fail(e.what());
  }
}

PiecewiseLinearSpectrum SceneReader::samples_spectrum(const JsonNode& node) {
  node.expect_object({"samples", "extend"});
  const JsonNode samples = node["samples"];
  std::vector<double> wavelengths, values;
  for (const JsonNode& pair : samples.elements()) {
    const std::vector<JsonNode> nm_value = pair.elements();
    if (nm_value.size() != 2) pair.fail(fmt::format("must be [wavelength_nm, value], got {} numbers", nm_value.size()));
    const double nm = nm_value[0].number();
    if (!wavelengths.empty() && !(nm > wavelengths.back()))
      nm_value[0].fail(fmt::format("wavelengths must increase, but {} follows {}", nm, wavelengths.back()));
    wavelengths.push_back(nm);
    values.push_back(nm_value[1].number());
  }
  if (wavelengths.size() < 2) samples.fail(fmt::format("needs at least 2 samples, got {}", wavelengths.size()));
  const bool clamp = node.has("extend") && node["extend"].choice({"zero", "clamp"}) == "clamp";
  return PiecewiseLinearSpectrum(std::move(wavelengths), std::move(values),
                                 clamp ? Extrapolation::Clamp : Extrapolation::Zero, samples.location());
}

SpectrumRef SceneReader::spectrum_ref(const JsonNode& node, bool emitted) {
  if (node.json().is_object()) return {"", spectrum_source(node, emitted), nullptr};
  if (!node.json().is_string())
    node.fail(fmt::format("must be a spectrum name or {}, got {}", kSpectrumObject, describe_json(node.json())));
  const std::string name = node.string();
  if (const NamedSpectrum* named = scene_.find_spectrum(name))
    return {name, emitted && named->rgb ? rgb_to_emission_spectrum(*named->rgb) : named->spectrum, nullptr};
  node.fail(scene_.spectra.empty()
                ? fmt::format("unknown spectrum \"{}\" (the scene defines no spectra)", name)
                : fmt::format("unknown spectrum \"{}\" (spectra: {})", name, names_of(scene_.spectra)));
}

bool is_texture_source(const JsonNode& node) { return node.json().is_object() && node.has("texture"); }

// {"texture": file, "colour_space": "sRGB" | "linear", "scale": s}; each image is read once per scene and use.
SpectrumRef SceneReader::texture_ref(const JsonNode& node, TextureUse use) {
  node.expect_object({"texture", "colour_space", "scale"});
  const JsonNode file = node["texture"];
  const std::string written = file.non_empty_string();
  std::optional<TextureColourSpace> colour_space;
  if (const auto space = node.find("colour_space"))
    colour_space = space->choice({"sRGB", "linear"}) == "sRGB" ? TextureColourSpace::Srgb : TextureColourSpace::Linear;
  double scale = 1.0;
  if (const auto n = node.find("scale"))
    scale = use == TextureUse::Reflectance ? n->number_in(0.0, 1.0) : n->number_at_least(0.0);
  const std::string path = (directory_ / written).lexically_normal().string();
  const auto key = std::make_tuple(path, colour_space ? static_cast<int>(*colour_space) : -1, static_cast<int>(use), scale);
  auto cached = textures_.find(key);
  if (cached == textures_.end()) {
    scene_.files.emplace_back(path);
    try {
      cached = textures_
                   .emplace(key, std::make_shared<const ImageTexture>(
                                     read_image_texture(path, written, colour_space, use, scale)))
                   .first;
    } catch (const InputError& e) {
      file.fail(e.what());
    }
  }
  SpectrumRef ref;
  ref.texture = cached->second;
  return ref;
}

SpectrumRef SceneReader::radiance(const JsonNode& node) {
  return is_texture_source(node) ? texture_ref(node, TextureUse::Radiance) : spectrum_ref(node, true);
}

SpectrumRef SceneReader::reflectance(const JsonNode& node) {
  if (is_texture_source(node)) return texture_ref(node, TextureUse::Reflectance);
  SpectrumRef ref = spectrum_ref(node);
  const Sample highest = extreme_sample(ref.spectrum, true);
  if (highest.value > 1.0)
    node.fail(fmt::format("{} reaches {}, but a reflectance must be in [0, 1]",
                          ref.name.empty() ? std::string("the spectrum") : fmt::format("spectrum \"{}\"", ref.name),
                          describe_sample(ref.spectrum, highest)));
  return ref;
}

Material SceneReader::material(const std::string& name, const JsonNode& node) {
  const std::string type = node["type"].choice({"lambert", "dichromatic", "mirror", "principled"});
  if (type == "principled") return {name, principled(node)};
  if (type == "lambert") {
    node.expect_object({"type", "reflectance"});
    return {name, LambertMaterial{reflectance(node["reflectance"])}};
  }
  if (type == "mirror") {
    node.expect_object({"type", "reflectance"});
    return {name, MirrorMaterial{reflectance(node["reflectance"])}};
  }

  node.expect_object({"type", "diffuse", "specular", "lobe", "roughness", "masking", "exponent"});
  DichromaticMaterial dichromatic;
  dichromatic.diffuse = reflectance(node["diffuse"]);
  dichromatic.specular = node["specular"].number_in(0.0, 1.0);
  const bool ggx = !node.has("lobe") || node["lobe"].choice({"ggx", "phong"}) == "ggx";
  const std::vector<const char*> other_lobes_keys = ggx ? std::vector<const char*>{"exponent"}
                                                       : std::vector<const char*>{"roughness", "masking"};
  for (const char* key : other_lobes_keys)
    if (const auto other = node.find(key))
      other->fail(fmt::format("applies only to \"lobe\": \"{}\"", ggx ? "phong" : "ggx"));
  if (ggx) {
    const auto masking = node.find("masking");
    const bool correlated = masking && masking->choice({"separable", "height-correlated"}) == "height-correlated";
    dichromatic.lobe = DichromaticMaterial::Ggx{node["roughness"].number_in(0.0, 1.0),
                                                correlated ? DichromaticMaterial::Masking::HeightCorrelated
                                                           : DichromaticMaterial::Masking::Separable};
  } else {
    dichromatic.lobe = DichromaticMaterial::Phong{node["exponent"].number_at_least(0.0)};
  }
  // Neither lobe reflects more than k_s, so this bound keeps the material from creating energy. A texture's
  // spectra stay below its scale (the fitted sigmoid is < 1).
  const double body = dichromatic.diffuse.texture ? dichromatic.diffuse.texture->scale
                                                  : extreme_sample(dichromatic.diffuse.spectrum, true).value;
  if (body + dichromatic.specular > 1.0)
    node["specular"].fail(
        fmt::format("the diffuse maximum {} plus specular {} exceeds 1, so the material would "
                    "reflect more light than it receives",
                    body, dichromatic.specular));
  return {name, std::move(dichromatic)};
}

PrincipledMaterial SceneReader::principled(const JsonNode& node) {
  node.expect_object({"type", "version", "base_color", "roughness", "ior", "specular_ior_level", "specular",
                      "distribution"});
  PrincipledMaterial m;
  if (const auto version = node.find("version")) m.version = static_cast<int>(version->integer_in(1, 2));
  m.base_color = reflectance(node["base_color"]);
  if (const auto roughness = node.find("roughness")) m.roughness = roughness->number_in(0.0, 1.0);
  for (const char* key : m.version == 2 ? std::vector<const char*>{"specular"}
                                        : std::vector<const char*>{"ior", "specular_ior_level"})
    if (const auto other = node.find(key))
      other->fail(fmt::format("applies only to \"version\": {}", m.version == 2 ? 1 : 2));
  if (m.version == 2) {
    if (const auto ior = node.find("ior")) m.ior = ior->number_in(1.0, 10.0);
    if (const auto level = node.find("specular_ior_level")) m.specular_ior_level = level->number_in(0.0, 1.0);
  } else {
    if (const auto specular = node.find("specular")) m.specular = specular->number_in(0.0, 1.0);
  }
  if (const auto distribution = node.find("distribution")) {
    m.multiscatter = distribution->choice({"ggx", "multiscatter-ggx"}) == "multiscatter-ggx";
    if (m.multiscatter && m.version == 1)
      distribution->fail("Blender 3.x's Multiscatter GGX is a random walk the tracer does not hold; version 1 "
                         "takes \"ggx\"");
  } else if (m.version == 1) {
    m.multiscatter = false;  // Blender 3.x's default
  }
  // Below this Cycles makes the interface a perfect mirror (alpha² at its threshold), which the tracer's principled
  // lobe does not hold.
  if (m.roughness < 0.02 && m.effective_ior() > 1.0)
    node["roughness"].fail(fmt::format("{} is below 0.02, where Cycles' interface becomes a perfect mirror, which "
                                       "a principled material does not hold", m.roughness));
  return m;
}

std::size_t SceneReader::material_index(const JsonNode& node) const {
  const std::string name = node.string();
  const Material* material = scene_.find_material(name);
  if (!material) node.fail(fmt::format("unknown material \"{}\" (materials: {})", name, names_of(scene_.materials)));
  return static_cast<std::size_t>(material - scene_.materials.data());
}

Shape SceneReader::object_shape(const JsonNode& node) const {
  const std::string type = node["type"].choice({"quad", "sphere", "cylinder", "box", "mesh"});
  const Tessellation& defaults = scene_.render.tessellation;
  if (type == "quad") return read_quad(node);
  if (type == "sphere") return read_sphere(node, defaults);
  if (type == "cylinder") return read_cylinder(node, defaults);
  if (type == "box") return read_box(node);
  return read_mesh(node, directory_);
}

// The mesh files the objects read, in object order.
std::vector<std::filesystem::path> mesh_files(const Scene& scene) {
  std::vector<std::filesystem::path> files;
  for (const Object& object : scene.objects)
    if (const auto* mesh = std::get_if<MeshShape>(&object.shape))
      files.push_back((scene.directory / mesh->file).lexically_normal());
  return files;
}

LightShape SceneReader::light_shape(const JsonNode& node) const {
  if (node["type"].choice({"quad", "sphere"}) == "quad") return read_quad(node);
  return read_sphere(node, scene_.render.tessellation);
}

Light SceneReader::light(const JsonNode& node) {
  node.expect_object({"name", "shape", "radiance", "scale", "group", "two_sided", "material"});
  Light light;
  light.name = node["name"].non_empty_string();
  light.shape = light_shape(node["shape"]);
  light.radiance = radiance(node["radiance"]);
  const auto scale = node.find("scale");
  if (scale) light.scale = scale->number_at_least(0.0);
  check_radiance_range(scale ? *scale : node["radiance"], light.radiance, light.scale);
  if (const auto group = node.find("group")) {
    light.group = group->string();
    if (!valid_group_name(light.group))
      group->fail(
          fmt::format("\"{}\" cannot name an output component: use letters, digits, \"_\" and \"-\"", light.group));
  } else {
    light.group = light.name;
    if (!valid_group_name(light.group))
      node["name"].fail(
          fmt::format("\"{}\" is also the light's group, which names an output component: use "
                      "letters, digits, \"_\" and \"-\", or give \"group\"",
                      light.name));
  }
  if (const auto two_sided = node.find("two_sided")) light.two_sided = two_sided->boolean();
  if (const auto material = node.find("material")) light.material = material_index(*material);
  return light;
}

Environment SceneReader::environment(const JsonNode& node) {
  node.expect_object({"radiance", "scale", "rotation_deg", "group"});
  Environment environment;
  environment.radiance = radiance(node["radiance"]);
  const auto scale = node.find("scale");
  if (scale) environment.scale = scale->number_at_least(0.0);
  check_radiance_range(scale ? *scale : node["radiance"], environment.radiance, environment.scale);
  if (const auto rotation = node.find("rotation_deg")) {
    if (!environment.radiance.texture) rotation->fail("applies only to a texture radiance");
    environment.rotation_deg = rotation->number_in(-360.0, 360.0);
  }
  if (const auto group = node.find("group")) {
    environment.group = group->string();
    if (!valid_group_name(environment.group))
      group->fail(fmt::format("\"{}\" cannot name an output component: use letters, digits, \"_\" and \"-\"",
                              environment.group));
  }
  return environment;
}

// A textured material on a mesh needs texture coordinates in its file; the analytic shapes always have them.
void SceneReader::check_texture_coordinates(const JsonNode& objects) const {
  const std::vector<JsonNode> nodes = objects.elements();
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
    const Object& object = scene_.objects[i];
    const auto* mesh = std::get_if<MeshShape>(&object.shape);
    if (!mesh || !mesh->mesh.uvs.empty()) continue;
    const Material& material = scene_.materials[object.material];
    std::string textured;
    if (const auto* m = std::get_if<LambertMaterial>(&material.model); m && m->reflectance.texture) textured = "reflectance";
    if (const auto* m = std::get_if<DichromaticMaterial>(&material.model); m && m->diffuse.texture) textured = "diffuse";
    if (const auto* m = std::get_if<MirrorMaterial>(&material.model); m && m->reflectance.texture) textured = "reflectance";
    if (const auto* m = std::get_if<PrincipledMaterial>(&material.model); m && m->base_color.texture) textured = "base_color";
    if (textured.empty()) continue;
    nodes[i]["shape"]["file"].fail(fmt::format(
        "{} has no texture coordinates (vertex properties u, v or s, t), but object \"{}\" has material \"{}\" "
        "whose {} is a texture",
        (directory_ / mesh->file).lexically_normal().string(), object.name, material.name, textured));
  }
}

Scene SceneReader::read(const JsonNode& root) {
  const std::string format = root["format"].string();
  if (format != kSceneFormat) root["format"].fail(fmt::format("must be \"{}\", got \"{}\"", kSceneFormat, format));
  root.expect_object({"format", "name", "description", "spectra", "materials", "objects", "lights", "environment",
                      "camera", "render"});
  if (const auto name = root.find("name")) scene_.name = name->non_empty_string();
  if (const auto description = root.find("description")) scene_.description = description->string();
  // Render settings first: they hold the tessellation defaults the shapes use.
  if (const auto render = root.find("render")) scene_.render = read_render(*render);

  if (const auto spectra = root.find("spectra"))
    for (const auto& [name, node] : spectra->members())
      scene_.spectra.push_back({name, spectrum_source(node), rgb_colour(node)});
  for (const auto& [name, node] : root["materials"].members()) scene_.materials.push_back(material(name, node));

  // Objects and lights share one namespace, as their names label the same object-id image.
  std::map<std::string, std::string> owner_of_name;
  auto claim_name = [&](const JsonNode& node) {
    const std::string name = node["name"].non_empty_string();
    const auto [it, fresh] = owner_of_name.emplace(name, node.path());
    if (!fresh) node["name"].fail(fmt::format("\"{}\" is already the name of {}", name, it->second));
  };
  int id = 1;
  for (const JsonNode& node : root["objects"].elements()) {
    node.expect_object({"name", "shape", "material"});
    claim_name(node);
    scene_.objects.push_back(
        {node["name"].string(), id++, material_index(node["material"]), object_shape(node["shape"])});
  }
  const JsonNode lights = root["lights"];
  for (const JsonNode& node : lights.elements()) {
    Light light = this->light(node);
    claim_name(node);
    light.id = id++;
    scene_.lights.push_back(std::move(light));
  }
  check_texture_coordinates(root["objects"]);
  if (const auto environment = root.find("environment")) scene_.environment = this->environment(*environment);
  if (scene_.lights.empty() && !scene_.environment)
    lights.fail("a scene needs at least one light or an \"environment\"");

  scene_.camera = read_camera(root["camera"]);
  return std::move(scene_);
}

std::vector<NamedSpectrum> SceneReader::read_spectra(const JsonNode& root) {
  const std::string format = root["format"].string();
  if (format != kSpectraFormat) root["format"].fail(fmt::format("must be \"{}\", got \"{}\"", kSpectraFormat, format));
  root.expect_object({"format", "spectra", "radiance"});
  std::vector<NamedSpectrum> spectra;
  if (const auto reflectances = root.find("spectra"))
    for (const auto& [name, node] : reflectances->members()) spectra.push_back({name, spectrum_source(node), std::nullopt});
  if (const auto radiances = root.find("radiance"))
    for (const auto& [name, node] : radiances->members()) {
      if (find_by_name(spectra, name))
        node.fail(fmt::format("\"{}\" is already the name of an entry of \"spectra\"", name));
      spectra.push_back({name, spectrum_source(node, true), std::nullopt});
    }
  if (!root.find("spectra") && !root.find("radiance")) root.fail("needs \"spectra\" or \"radiance\"");
  return spectra;
}

}  // namespace

const char* material_type_name(const Material& material) {
  static constexpr const char* names[] = {"lambert", "dichromatic", "mirror", "principled"};
  return names[material.model.index()];
}

const SpectrumRef& Material::reflectance_spectrum() const {
  if (const auto* d = std::get_if<DichromaticMaterial>(&model)) return d->diffuse;
  if (const auto* m = std::get_if<MirrorMaterial>(&model)) return m->reflectance;
  if (const auto* p = std::get_if<PrincipledMaterial>(&model)) return p->base_color;
  return std::get<LambertMaterial>(model).reflectance;
}

const char* Material::reflectance_key() const {
  if (std::holds_alternative<PrincipledMaterial>(model)) return "base_color";
  return std::holds_alternative<DichromaticMaterial>(model) ? "diffuse" : "reflectance";
}

double PrincipledMaterial::effective_ior() const {
  if (version == 1) {
    // F0 = 0.08 · specular, and the IOR whose normal-incidence Fresnel that is.
    const double root = std::sqrt(0.08 * specular);
    return root > 0.0 ? (1.0 + root) / (1.0 - root) : 1.0;
  }
  if (specular_ior_level == 0.5) return ior;
  const double f0 = std::clamp(std::pow((ior - 1.0) / (ior + 1.0), 2) * 2.0 * specular_ior_level, 0.0, 0.99);
  const double root = std::sqrt(f0);
  return (1.0 + root) / (1.0 - root);
}

const Material* Scene::find_material(std::string_view name) const { return find_by_name(materials, name); }
const NamedSpectrum* Scene::find_spectrum(std::string_view name) const { return find_by_name(spectra, name); }

Scene parse_scene(const Json& document, const std::string& source, const std::filesystem::path& directory) {
  const JsonNode root(document, source);
  Scene scene = SceneReader(directory).read(root);
  scene.source = source;
  scene.directory = directory;
  scene.json = document;
  for (std::filesystem::path& mesh : mesh_files(scene)) scene.files.push_back(std::move(mesh));
  return scene;
}

Scene load_scene(const std::filesystem::path& file) {
  Scene scene = parse_scene(read_json(file), file.string(), file.parent_path());
  if (scene.name.empty()) scene.name = file.stem().string();
  scene.files.insert(scene.files.begin(), file);
  return scene;
}

std::vector<TriangleMesh> scene_meshes(const Scene& scene) {
  std::vector<TriangleMesh> meshes;
  for (const Object& object : scene.objects) meshes.push_back(tessellate(object.shape));
  for (const Light& light : scene.lights)
    meshes.push_back(std::visit([](const auto& shape) { return tessellate(shape); }, light.shape));
  return meshes;
}

std::vector<NamedSpectrum> load_spectra(const std::filesystem::path& file) {
  return parse_spectra(read_json(file), file.string(), file.parent_path());
}

std::vector<NamedSpectrum> parse_spectra(const Json& document, const std::string& source,
                                         const std::filesystem::path& directory) {
  return SceneReader(directory).read_spectra(JsonNode(document, source));
}

std::string document_format(const Json& document) {
  if (!document.is_object()) return "";
  const auto format = document.find("format");
  return format != document.end() && format->is_string() ? format->get<std::string>() : "";
}

namespace {

void visit_paths(Json& node, std::string_view key, const std::function<void(Json&)>& visit) {
  if (node.is_array()) {
    for (Json& element : node) visit_paths(element, "", visit);
    return;
  }
  if (!node.is_object()) return;
  for (auto& [k, child] : node.items()) {
    if ((k == "csv" || k == "texture" || (k == "file" && key == "shape")) && child.is_string())
      visit(child);
    else
      visit_paths(child, k, visit);
  }
}

}  // namespace

void for_each_scene_path(Json& document, const std::function<void(Json& path)>& visit) { visit_paths(document, "", visit); }

Json rebase_scene_paths(Json document, const std::filesystem::path& from, const std::filesystem::path& to) {
  for_each_scene_path(document, [&](Json& value) {
    std::filesystem::path path = value.get<std::string>();
    if (path.is_relative()) path = std::filesystem::absolute(from / path).lexically_normal();
    if (!to.empty()) path = path.lexically_relative(std::filesystem::absolute(to).lexically_normal());
    value = path.generic_string();
  });
  return document;
}

const RenderDefaults& render_defaults() {
  static const RenderDefaults defaults = [] {
    const Json render = Json::parse(embedded::file("defaults.json"))["render"];
    RenderDefaults d;
    d.samples = render["samples"].get<int>();
    d.max_bounces = render["max_bounces"].get<int>();
    d.seed = render["seed"].get<std::uint64_t>();
    d.pixel_filter = render["pixel_filter"] == "point" ? PixelFilter::Point : PixelFilter::Box;
    d.spectral_mode = render["spectral_mode"] == "continuous" ? SpectralMode::Continuous : SpectralMode::Bands;
    d.bands = render["bands"].get<std::string>();
    return d;
  }();
  return defaults;
}

}  // namespace ct
