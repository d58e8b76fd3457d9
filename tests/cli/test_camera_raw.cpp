// SPDX-License-Identifier: Apache-2.0
// Camera raw both ways: the sensor's DNG read by independent raw readers, analyze on a DNG against analyze on
// the sensor's EXR of the same capture, reflectance images lit by an illuminant, and bad raw input.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>
#include <tiffio.h>

#include "core/cie.h"
#include "core/colour.h"
#include "core/spectral_exr.h"
#include "core/spectrum.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::run_chromatrace;
using test::run_program;

const fs::path kMacbeth =
    fs::path(CHROMATRACE_TEST_DATA) / "spectral_exr_samples" / "spectral-exr_Macbeth_reflective.exr";
const std::string kBox = std::string(CHROMATRACE_SOURCE_DIR) + "/scenes/paper/box.json";

int line_count(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// A program on the PATH, or "" when it is not installed.
std::string find_program(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (fs::exists(fs::path(dir) / name)) return (fs::path(dir) / name).string();
  return "";
}

struct Mosaic {
  int width = 0, height = 0;
  std::vector<int> values;  // [y][x]
};

// A 16-bit binary PGM (P5), as dcraw and dcraw_emu write one.
Mosaic parse_pgm(const std::string& bytes) {
  std::istringstream in(bytes);
  std::string magic;
  int maxval = 0;
  Mosaic m;
  in >> magic >> m.width >> m.height >> maxval;
  in.get();  // the single whitespace before the data
  EXPECT_EQ(magic, "P5");
  EXPECT_GT(maxval, 255);
  m.values.resize(static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height));
  for (int& v : m.values) {
    const int hi = in.get(), lo = in.get();
    v = hi * 256 + lo;  // big-endian
  }
  EXPECT_TRUE(in.good());
  return m;
}

// The image's channels as floats, [y][x][c]; `config` attributes for the reader (raw:Demosaic …).
std::vector<float> read_pixels(const fs::path& file, int& width, int& height, int& channels,
                               const OIIO::ImageSpec* config = nullptr) {
  auto in = OIIO::ImageInput::open(file.string(), config);
  if (!in) {
    ADD_FAILURE() << file << ": " << OIIO::geterror();
    return {};
  }
  const OIIO::ImageSpec& spec = in->spec();
  width = spec.width;
  height = spec.height;
  channels = spec.nchannels;
  std::vector<float> values(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(channels));
  EXPECT_TRUE(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, values.data())) << in->geterror();
  return values;
}

// Each of the canon preset's RGGB mosaic's pixels keeps the channel of its filter.
int rggb_channel(int x, int y) { return (y % 2 == 0) ? (x % 2 == 0 ? 0 : 1) : (x % 2 == 0 ? 1 : 2); }

class CameraRaw : public ::testing::Test {
 protected:
  void SetUp() override {
    test::ComponentImage image = test::make_component_image(kWidth, kHeight, 11);
    image.layout.attributes["chromatrace.camera"] =
        R"({"horizontal_fov_deg": 50, "vertical_fov_deg": 38.6, "resolution": [32, 24]})";
    input_ = dir_.file("scene.exr");
    test::write_image(input_, image, 8);
  }
  // The same capture (same exposure, seed and noise) as the DNG's mosaic or as 3 channels per pixel.
  test::CommandResult capture(const fs::path& output, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"sensor", input_.string(), "-o", output.string(), "--preset", "canon_eos_5d_mkiii",
                                     "--exposure-s", "auto", "--seed", "3", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_chromatrace(args);
  }
  static constexpr int kWidth = 32, kHeight = 24;
  test::TempDir dir_;
  fs::path input_;
};

// The simulator's own numbers: noise is keyed by (pixel, channel), so the channel a filter keeps has the same
// digital number with the CFA as without it; the TIFF of the capture without a CFA holds them exactly.
TEST_F(CameraRaw, DngMosaicIsTheSimulatorsNumbersInThreeReaders) {
  const fs::path dng = dir_.file("capture.dng"), tif = dir_.file("every_channel.tif");
  const test::CommandResult made = capture(dng);
  ASSERT_EQ(made.exit_code, 0) << made.err;
  ASSERT_EQ(capture(tif, {"--cfa", "none"}).exit_code, 0);
  int w = 0, h = 0, c = 0;
  const std::vector<float> every = read_pixels(tif, w, h, c);
  ASSERT_EQ(w, kWidth);
  ASSERT_EQ(c, 3);
  std::vector<int> expected(static_cast<std::size_t>(kWidth * kHeight));
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      expected[static_cast<std::size_t>(y * kWidth + x)] =
          static_cast<int>(std::lround(every[static_cast<std::size_t>((y * kWidth + x) * 3 + rggb_channel(x, y))] * 65535.0f));
  // The mosaic is not trivially flat: the noise and the scene spread it over hundreds of numbers.
  EXPECT_GT(*std::max_element(expected.begin(), expected.end()) - *std::min_element(expected.begin(), expected.end()), 200);

  // 1. LibRaw through OpenImageIO, without demosaicing: the raw numbers as 16-bit fractions.
  OIIO::ImageSpec config;
  config.attribute("raw:Demosaic", "none");
  const std::vector<float> oiio = read_pixels(dng, w, h, c, &config);
  ASSERT_EQ(w, kWidth);
  ASSERT_EQ(h, kHeight);
  ASSERT_EQ(c, 1);
  for (std::size_t i = 0; i < expected.size(); ++i)
    ASSERT_EQ(std::lround(oiio[i] * 65535.0f), expected[i]) << "OpenImageIO, pixel " << i;

  // 2. dcraw -D -4: "document mode", the raw numbers unscaled, as a 16-bit PGM.
  const std::string dcraw = find_program("dcraw");
  if (dcraw.empty()) {
    ADD_FAILURE() << "dcraw is not installed (setup.sh installs it)";
  } else {
    const test::CommandResult r = run_program(dcraw, {"-D", "-4", "-c", dng.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Mosaic m = parse_pgm(r.out);
    ASSERT_EQ(m.width, kWidth);
    ASSERT_EQ(m.height, kHeight);
    EXPECT_EQ(m.values, expected);
    const test::CommandResult id = run_program(dcraw, {"-i", "-v", dng.string()});
    EXPECT_NE(id.out.find("Filter pattern: RG/GB"), std::string::npos) << id.out;
    // Document mode with scaling (-d) says the levels it scales with.
    const test::CommandResult levels = run_program(dcraw, {"-v", "-d", "-c", dng.string()});
    EXPECT_NE(levels.err.find("darkness 2048, saturation 16383"), std::string::npos) << levels.err;
  }

  // 3. LibRaw's own tools: unprocessed_raw writes the raw numbers as capture.dng.pgm; raw-identify reports the
  //    pattern and the black level.
  const std::string unprocessed = find_program("unprocessed_raw"), identify = find_program("raw-identify");
  if (unprocessed.empty() || identify.empty()) {
    ADD_FAILURE() << "unprocessed_raw / raw-identify are not installed (libraw-bin; setup.sh installs it)";
  } else {
    const test::CommandResult r = run_program(unprocessed, {"-q", dng.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream pgm(dng.string() + ".pgm", std::ios::binary);
    const Mosaic m = parse_pgm(std::string(std::istreambuf_iterator<char>(pgm), {}));
    EXPECT_EQ(m.values, expected);
    const test::CommandResult id = run_program(identify, {"-v", dng.string()});
    ASSERT_EQ(id.exit_code, 0) << id.err;
    EXPECT_NE(id.out.find("Filter pattern: RGGBRGGBRGGBRGGB"), std::string::npos) << id.out;
    EXPECT_NE(id.out.find("black: 2048"), std::string::npos) << id.out;
  }
}

// The DNG's colour fields for the ideal colorimetric camera (the CIE 1931 observer as its curves), whose camera
// RGB is CIE XYZ: a D65 white's neutral is D65's white point (0.95047, 1, 1.08883) over its largest value, and
// the XYZ → camera matrix is the identity over that value. Tolerance 10⁻³: the D65 table's white through the
// 5 nm bands differs from the standard's white point by about 10⁻⁴.
TEST(CameraRawDng, ColourFieldsOfTheCieCameraAndTheExposure) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(380, 780, 5);
  const std::vector<double> d65 = band_averages(cie::illuminant("D65"), bands);
  const fs::path input = dir.file("d65.exr"), dng = dir.file("d65.dng");
  // 24 x 24: raw readers take no smaller image for a raw one, and sensor refuses a smaller DNG.
  test::write_radiance(input, bands, 24, 24, [&](int, int, std::size_t b) { return static_cast<float>(d65[b] * 0.01); }, {});
  const test::CommandResult r =
      run_chromatrace({"sensor", input.string(), "-o", dng.string(), "--preset", "canon_eos_5d_mkiii", "--camera",
                       "cie1931", "--exposure-s", "0.004", "--f-number", "5.6", "--no-noise", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;

  TIFF* tif = TIFFOpen(dng.c_str(), "r");
  ASSERT_NE(tif, nullptr);
  const Vec3d white = d65_white();
  const double top = std::max({white[0], white[1], white[2]});
  std::uint16_t count = 0;
  float* values = nullptr;
  ASSERT_TRUE(TIFFGetField(tif, TIFFTAG_ASSHOTNEUTRAL, &count, &values));
  ASSERT_EQ(count, 3);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(values[c], white[c] / top, 1e-3) << "AsShotNeutral " << c;
  // As Adobe's converter writes them: ColorMatrix1 under illuminant A, ColorMatrix2 under D65 (a reader that takes
  // one matrix, as dcraw does, takes the last). D65's, for an XYZ camera: the identity over the largest value of
  // D65's white.
  ASSERT_TRUE(TIFFGetField(tif, TIFFTAG_COLORMATRIX2, &count, &values));
  ASSERT_EQ(count, 9);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(values[i], i % 4 == 0 ? 1.0 / top : 0.0, 1e-3) << "ColorMatrix2 " << i;
  std::uint16_t illuminant = 0;
  ASSERT_TRUE(TIFFGetField(tif, TIFFTAG_CALIBRATIONILLUMINANT2, &illuminant));
  EXPECT_EQ(illuminant, 21);  // D65
  // A's: the identity over the largest value of A's white point through the same bands, (1.0985, 1, 0.3559) as the
  // standard gives it.
  const Vec3d a_white = bands_to_xyz(band_averages(cie::illuminant("A"), bands), bands);
  const double a_top = a_white[0] / a_white[1];
  EXPECT_NEAR(a_top, 1.09850, 1e-4);
  ASSERT_TRUE(TIFFGetField(tif, TIFFTAG_COLORMATRIX1, &count, &values));
  ASSERT_EQ(count, 9);
  // Tolerance 2·10⁻³: the fit's XYZ are integrals at 1 nm of reflectance × A, the camera's signals sums over the 5 nm
  // bands of the reflectance's band average × A's, which differ by up to 0.15 % where A is steep (its blue end).
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(values[i], i % 4 == 0 ? 1.0 / a_top : 0.0, 2e-3) << "ColorMatrix1 " << i;
  ASSERT_TRUE(TIFFGetField(tif, TIFFTAG_CALIBRATIONILLUMINANT1, &illuminant));
  EXPECT_EQ(illuminant, 17);  // standard light A
  std::uint64_t exif = 0;
  ASSERT_TRUE(TIFFGetField(tif, TIFFTAG_EXIFIFD, &exif));
  ASSERT_TRUE(TIFFReadEXIFDirectory(tif, exif));
  float exposure = 0, f_number = 0;  // rationals, which libtiff hands back as floats
  ASSERT_TRUE(TIFFGetField(tif, EXIFTAG_EXPOSURETIME, &exposure));
  ASSERT_TRUE(TIFFGetField(tif, EXIFTAG_FNUMBER, &f_number));
  EXPECT_NEAR(exposure, 0.004, 0.004 * 1e-6);
  EXPECT_NEAR(f_number, 5.6, 5.6 * 1e-6);
  TIFFClose(tif);
}

// What raw developers read from the DNG beyond the mosaic, by two readers that do not share its writer's code: LibRaw
// (raw-identify) reads both colour matrices with their illuminants, and ExifTool the noise profile, which is the
// sensor model's temporal noise in values normalised over white − black: scale K/D (shot noise), offset
// (K²(σ_read² + I_d·T) + 1/12)/D² (read noise, dark current shot noise, quantisation), from the capture's own settings.
TEST_F(CameraRaw, DevelopersReadBothColourMatricesAndTheNoiseProfile) {
  const fs::path dng = dir_.file("capture.dng"), exr = dir_.file("capture.exr");
  ASSERT_EQ(capture(dng).exit_code, 0);
  ASSERT_EQ(capture(exr, {"--cfa", "none"}).exit_code, 0);
  const OIIO::ImageBuf image(exr.string());
  const nlohmann::json settings = nlohmann::json::parse(image.spec().get_string_attribute("chromatrace.sensor"));
  const double K = settings["adc"]["gain_dn_per_e"], read = settings["noise"]["read_e"];
  const double dark = settings["noise"]["dark_current_e_per_s"], T = settings["exposure"]["time_s"];
  const double D = image.spec().get_float_attribute("chromatrace.white_level") - image.spec().get_float_attribute("chromatrace.black_level");
  ASSERT_GT(D, 0);
  const double scale = K / D, offset = (K * K * (read * read + dark * T) + 1.0 / 12.0) / (D * D);

  const std::string identify = find_program("raw-identify"), exiftool = find_program("exiftool");
  if (identify.empty() || exiftool.empty()) {
    ADD_FAILURE() << "raw-identify / exiftool are not installed (libraw-bin, libimage-exiftool-perl; setup.sh installs them)";
    return;
  }
  const test::CommandResult id = run_program(identify, {"-v", dng.string()});
  ASSERT_EQ(id.exit_code, 0) << id.err;
  EXPECT_NE(id.out.find("DNG Illuminant 1: Illuminant A"), std::string::npos) << id.out;
  EXPECT_NE(id.out.find("DNG Illuminant 2: D65"), std::string::npos) << id.out;
  // LibRaw's matrix 2 is the one written: the TIFF field, to the 4 decimals raw-identify prints.
  TIFF* tif = TIFFOpen(dng.c_str(), "r");
  ASSERT_NE(tif, nullptr);
  std::uint16_t count = 0;
  float* m2 = nullptr;
  ASSERT_TRUE(TIFFGetField(tif, TIFFTAG_COLORMATRIX2, &count, &m2));
  const std::size_t at = id.out.find("DNG color matrix 2:");
  ASSERT_NE(at, std::string::npos) << id.out;
  std::istringstream printed(id.out.substr(at + std::string("DNG color matrix 2:").size()));
  for (int i = 0; i < 9; ++i) {
    double v = 0;
    printed >> v;
    EXPECT_NEAR(v, m2[i], 6e-5) << "matrix 2, element " << i;
  }
  TIFFClose(tif);

  const test::CommandResult noise = run_program(exiftool, {"-n", "-s3", "-NoiseProfile", dng.string()});
  ASSERT_EQ(noise.exit_code, 0) << noise.err;
  std::istringstream profile(noise.out);
  double s = 0, o = 0;
  profile >> s >> o;
  EXPECT_NEAR(s, scale, 1e-9 * scale) << noise.out;
  EXPECT_NEAR(o, offset, 1e-9 * offset) << noise.out;
  // Without noise there is no profile.
  const fs::path clean = dir_.file("clean.dng");
  ASSERT_EQ(capture(clean, {"--no-noise"}).exit_code, 0);
  EXPECT_EQ(run_program(exiftool, {"-n", "-s3", "-NoiseProfile", clean.string()}).out, "");
}

// The half-size reading keeps each tile's red, first green and blue exactly: the whole image's mean is the mean of
// those digital numbers less the black level. info reads the file's pattern and levels.
TEST_F(CameraRaw, HalfSizeKeepsTheCapturedNumbersAndInfoReadsTheLevels) {
  const fs::path dng = dir_.file("capture.dng"), tif = dir_.file("every_channel.tif");
  ASSERT_EQ(capture(dng).exit_code, 0);
  ASSERT_EQ(capture(tif, {"--cfa", "none"}).exit_code, 0);
  int w = 0, h = 0, c = 0;
  const std::vector<float> every = read_pixels(tif, w, h, c);
  ASSERT_EQ(c, 3);
  std::array<double, 3> sum{};
  for (int y = 0; y < kHeight; y += 2)
    for (int x = 0; x < kWidth; x += 2)
      for (const auto& [dx, dy] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}}) {  // R, first G, B of RGGB
        const int channel = rggb_channel(x + dx, y + dy);
        sum[static_cast<std::size_t>(channel)] +=
            std::round(every[static_cast<std::size_t>(((y + dy) * kWidth + x + dx) * 3 + channel)] * 65535.0) - 2048.0;
      }
  const fs::path out = dir_.file("half");
  const test::CommandResult r =
      run_chromatrace({"analyze", dng.string(), "-o", out.string(), "--raw-half-size", "--no-plots", "--no-report", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out / "analysis.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["image"]["width"], kWidth / 2);
  EXPECT_EQ(j["image"]["height"], kHeight / 2);
  EXPECT_EQ(j["input"]["clipping_level"], 16383 - 2048);
  const nlohmann::json& whole = j["regions"][0];
  ASSERT_EQ(whole["source"], "image");
  const double tiles = double(kWidth / 2 * (kHeight / 2));
  for (std::size_t k = 0; k < 3; ++k)  // whole numbers summed exactly; the mean's rounding is ~1e-12 DN
    EXPECT_NEAR(whole["shape"]["mean"][k].get<double>(), sum[k] / tiles, 1e-6) << "channel " << k;

  const test::CommandResult info = run_chromatrace({"info", "--json", dng.string()});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json i = nlohmann::json::parse(info.out);
  EXPECT_EQ(i["format"], "DNG 1.4.0.0");
  EXPECT_EQ(i["camera"], "chromatrace canon_eos_5d_mkiii");
  EXPECT_EQ(i["cfa"], "RGGB");
  EXPECT_EQ(i["black_level"], "2048");
  EXPECT_EQ(i["white_level"], "16383");
  EXPECT_EQ(i["f_number"], "4");
}

// The same capture gives the same DNG bytes whatever the thread count and block size.
TEST_F(CameraRaw, DngBytesDoNotDependOnThreads) {
  const fs::path one = dir_.file("one.dng"), two = dir_.file("two.dng");
  ASSERT_EQ(capture(one, {"--threads", "1", "--block-rows", "1"}).exit_code, 0);
  ASSERT_EQ(capture(two, {"--threads", "2"}).exit_code, 0);
  EXPECT_EQ(test::read_bytes(one), test::read_bytes(two));
}

TEST_F(CameraRaw, DngConvertsInRawTherapee) {
  const std::string rt = find_program("rawtherapee-cli");
  if (rt.empty()) GTEST_SKIP() << "rawtherapee-cli is not installed (Debian package rawtherapee): conversion not checked";
  // RawTherapee refuses images much smaller than a photograph (it loads 300 x 200, not 200 x 200).
  constexpr int kWide = 320, kHigh = 240;
  input_ = dir_.file("large.exr");
  test::write_image(input_, test::make_component_image(kWide, kHigh, 12), 16);
  const fs::path dng = dir_.file("capture.dng");
  ASSERT_EQ(capture(dng).exit_code, 0);
  const fs::path out = dir_.file("developed.tif");
  // The default processing profile (-d), TIFF output (-t), overwriting (-Y).
  const test::CommandResult r =
      run_program(rt, {"-d", "-q", "-o", out.string(), "-t", "-Y", "-c", dng.string()});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  int w = 0, h = 0, c = 0;
  const std::vector<float> developed = read_pixels(out, w, h, c);
  EXPECT_GE(w, kWide - 8);  // RawTherapee may crop a border
  EXPECT_GE(h, kHigh - 8);
  EXPECT_EQ(c, 3);
  EXPECT_GT(*std::max_element(developed.begin(), developed.end()), 0.0f);
}

// Reads analysis.json's regions by label: class and principal axis.
std::map<int, std::pair<std::string, std::array<double, 3>>> regions_of(const fs::path& dir) {
  std::ifstream in(dir / "analysis.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::map<int, std::pair<std::string, std::array<double, 3>>> out;
  for (const nlohmann::json& r : j["regions"]) {
    if (r["label"].is_null() || r["shape"]["samples"].get<int>() == 0) continue;
    const nlohmann::json& axis = r["shape"]["axes"][0];
    out[r["label"].get<int>()] = {r["shape"]["class"].get<std::string>(),
                                  {axis[0].get<double>(), axis[1].get<double>(), axis[2].get<double>()}};
  }
  return out;
}

// Both are demosaiced, the EXR by OpenCV in the simulator and the DNG by LibRaw, so that their pixels differ by
// the demosaicing and the noise each leaves; their classes and directions must not. Over three sizes, sample
// counts and seeds.
void check_dng_against_exr(int size, int spp, int seed) {
  SCOPED_TRACE(fmt::format("{0}x{0}, {1} paths per pixel, seed {2}", size, spp, seed));
  test::TempDir dir;
  const fs::path scene = dir.file("box.exr"), exr = dir.file("camera.exr"), dng = dir.file("camera.dng");
  const test::CommandResult rendered = run_chromatrace({"render", kBox, "-o", scene.string(), "--resolution",
                                                        fmt::format("{0}x{0}", size), "--spp", std::to_string(spp),
                                                        "--seed", std::to_string(seed), "--quiet"});

  ASSERT_EQ(rendered.exit_code, 0) << rendered.err;
  for (const fs::path& out : {exr, dng}) {
    const test::CommandResult r = run_chromatrace({"sensor", scene.string(), "-o", out.string(), "--preset",
                                                   "canon_eos_5d_mkiii", "--exposure-s", "auto", "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  // The same regions and the same knowledge for both: the objects as a label image made from the EXR's object
  // ids, and the EXR's R, G, B with its camera metadata but without the ids, which a raw file cannot carry (with
  // them the analyzer also looks for edge pixels mixing two objects, the class "mixed"), nor the read noise that
  // a DNG has no tag for (with it a saturated pixel's read-out scattered just below the white level counts as
  // clipped; without it only the white level itself does).
  const OIIO::ImageBuf camera(exr.string());
  const int id_channel = camera.spec().channelindex("object_id");
  ASSERT_GE(id_channel, 0);
  const fs::path label_file = dir.file("labels.tif"), rgb = dir.file("camera_rgb.exr");
  OIIO::ImageBuf ids = OIIO::ImageBufAlgo::channels(camera, 1, {id_channel});
  ids = OIIO::ImageBufAlgo::mul(ids, 1.0f / 65535.0f);  // stored as 16-bit codes: id / 65535 of full scale
  ASSERT_TRUE(ids.write(label_file.string(), OIIO::TypeDesc::UINT16)) << ids.geterror();
  OIIO::ImageBuf colour = OIIO::ImageBufAlgo::channels(
      camera, 3, {camera.spec().channelindex("R"), camera.spec().channelindex("G"), camera.spec().channelindex("B")});
  ASSERT_NE(colour.spec().find_attribute("chromatrace.read_noise"), nullptr);
  colour.specmod().erase_attribute("chromatrace.read_noise");
  ASSERT_EQ(colour.spec().channelnames, (std::vector<std::string>{"R", "G", "B"}));
  ASSERT_TRUE(colour.write(rgb.string())) << colour.geterror();

  for (const auto& [image, result] : {std::pair{rgb, dir.file("exr")}, std::pair{dng, dir.file("dng")}}) {
    // The simulator demosaiced bilinearly (the preset's cfa.demosaic); LibRaw's "linear" is the same method.
    const test::CommandResult r = run_chromatrace({"analyze", image.string(), "-o", result.string(), "--labels",
                                                   label_file.string(), "--raw-demosaic", "linear", "--no-plots",
                                                   "--no-report", "--quiet"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const auto from_exr = regions_of(dir.file("exr")), from_dng = regions_of(dir.file("dng"));
  ASSERT_GE(from_exr.size(), 5u);
  ASSERT_EQ(from_exr.size(), from_dng.size());
  for (const auto& [label, expected] : from_exr) {
    ASSERT_TRUE(from_dng.contains(label)) << "label " << label;
    const auto& [cls, axis] = from_dng.at(label);
    EXPECT_EQ(cls, expected.first) << "label " << label;
    double dot = 0;
    for (int k = 0; k < 3; ++k) dot += axis[static_cast<std::size_t>(k)] * expected.second[static_cast<std::size_t>(k)];
    const double angle = std::acos(std::min(1.0, std::abs(dot))) * 180.0 / M_PI;
    EXPECT_LT(angle, 0.5) << "label " << label << " (" << cls << ")";
  }
}

TEST(CameraRawAnalysis, DngGivesTheClassesAndDirectionsOfTheSensorsExr) {
  check_dng_against_exr(64, 16, 1);
  check_dng_against_exr(96, 64, 2);
  check_dng_against_exr(80, 32, 3);
}

// Writes `reflectance` (T bands of kMacbeth) multiplied by D50, scaled to 1 at 560 nm, as an emissive file.
void write_lit_by_d50(const fs::path& target) {
  SpectralExrReader reader(kMacbeth);
  const SpectralExrInfo& info = reader.info();
  const std::vector<float> values = reader.read_layer(info.layer("", SpectralQuantity::T));
  const PiecewiseLinearSpectrum& d50 = cie::illuminant("D50");
  std::vector<double> scaled = d50.values();
  for (double& v : scaled) v /= d50(560.0);
  const std::vector<double> light =
      band_averages(PiecewiseLinearSpectrum(d50.wavelengths(), scaled, d50.extrapolation()), info.bands);
  const std::size_t n = light.size(), w = static_cast<std::size_t>(info.width);
  test::write_radiance(target, info.bands, info.width, info.height, [&](int x, int y, std::size_t b) {
    return static_cast<float>(values[(static_cast<std::size_t>(y) * w + static_cast<std::size_t>(x)) * n + b] * light[b]);
  }, {});
}

TEST(ReflectanceLit, EqualsTheSameImagePremultipliedByTheIlluminant) {
  test::TempDir dir;
  const fs::path emissive = dir.file("macbeth_d50.exr"), lit = dir.file("lit.exr"), direct = dir.file("direct.exr");
  write_lit_by_d50(emissive);
  const std::vector<std::string> common = {"--exposure-s", "0.01", "--quiet"};
  std::vector<std::string> a = {"sensor", kMacbeth.string(), "--illuminant", "D50", "-o", lit.string()};
  std::vector<std::string> b = {"sensor", emissive.string(), "-o", direct.string()};
  a.insert(a.end(), common.begin(), common.end());
  b.insert(b.end(), common.begin(), common.end());
  const test::CommandResult ra = run_chromatrace(a), rb = run_chromatrace(b);
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  int w = 0, h = 0, c = 0, w2 = 0, h2 = 0, c2 = 0;
  auto in_a = OIIO::ImageInput::open(lit.string()), in_b = OIIO::ImageInput::open(direct.string());
  ASSERT_TRUE(in_a && in_b);
  for (const char* layer : {"R", "linear.R"}) {
    const int ca = in_a->spec().channelindex(layer), cb = in_b->spec().channelindex(layer);
    ASSERT_GE(ca, 0);
    ASSERT_GE(cb, 0);
    w = in_a->spec().width, h = in_a->spec().height, w2 = in_b->spec().width, h2 = in_b->spec().height;
    ASSERT_EQ(w, w2);
    ASSERT_EQ(h, h2);
    std::vector<float> va(static_cast<std::size_t>(w * h * 3)), vb(va.size());
    ASSERT_TRUE(in_a->read_image(0, 0, ca, ca + 3, OIIO::TypeDesc::FLOAT, va.data()));
    ASSERT_TRUE(in_b->read_image(0, 0, cb, cb + 3, OIIO::TypeDesc::FLOAT, vb.data()));
    float peak = 0;
    for (float v : vb) peak = std::max(peak, v);
    ASSERT_GT(peak, 0.0f);
    // The band values are the same floats up to the rounding of the illuminant's scaling (one float rounding
    // of each band, ≤ 2⁻²⁴ relative), which the linear sum over bands keeps within a few 2⁻²³.
    for (std::size_t i = 0; i < va.size(); ++i)
      ASSERT_NEAR(va[i], vb[i], 4e-7 * std::max(std::abs(vb[i]), 1e-30f) + 1e-30) << layer << " value " << i;
  }
  (void)c;
  (void)c2;
}

// Bad input: one line naming the file and the problem, exit 2, nothing written.
void expect_bad_input(const test::CommandResult& r, const std::string& file, const std::string& problem) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
}

TEST_F(CameraRaw, BadRawInputIsOneLineAndExitTwo) {
  const fs::path dng = dir_.file("capture.dng"), truncated = dir_.file("truncated.dng");
  ASSERT_EQ(capture(dng).exit_code, 0);
  test::write_truncated_copy(dng, truncated, fs::file_size(dng) / 2);
  const fs::path out = dir_.file("analysis");
  expect_bad_input(run_chromatrace({"analyze", truncated.string(), "-o", out.string(), "--quiet"}), "truncated.dng",
                   "the file is truncated");
  expect_bad_input(run_chromatrace({"info", truncated.string()}), "truncated.dng", "the file is truncated");

  expect_bad_input(
      run_chromatrace({"analyze", dng.string(), "-o", out.string(), "--raw-demosaic", "amaze", "--quiet"}),
      "--raw-demosaic", "unknown method \"amaze\" (methods: linear, vng, ppg, ahd, dcb, dht, aahd)");

  const fs::path junk = dir_.file("junk.nef");
  std::ofstream(junk) << "this is no camera raw, only text that ends early\n";
  expect_bad_input(run_chromatrace({"analyze", junk.string(), "-o", out.string(), "--quiet"}), "junk.nef",
                   "LibRaw cannot open it as a camera raw");
  EXPECT_FALSE(fs::exists(out));
}

TEST(ReflectanceLit, BadInputIsOneLineAndExitTwo) {
  test::TempDir dir;
  const fs::path out = dir.file("out.exr");
  expect_bad_input(run_chromatrace({"sensor", kMacbeth.string(), "-o", out.string(), "--quiet"}),
                   kMacbeth.filename().string(), "light it with --illuminant");
  const fs::path negative = dir.file("negative.csv");
  std::ofstream(negative) << "wavelength_nm,power\n380,1\n560,-0.5\n780,1\n";
  expect_bad_input(
      run_chromatrace({"sensor", kMacbeth.string(), "--illuminant", negative.string(), "-o", out.string(), "--quiet"}),
      "negative.csv", "value -0.5 at 560 nm");
  EXPECT_FALSE(fs::exists(out));

  // A fluorescent file's re-radiation is not supported: said so, whether lit or not.
  const fs::path fluorescent = dir.file("fluorescent.exr");
  std::vector<test::RawChannel> channels;
  for (const char* name : {"T.400,0nm", "T.500,0nm", "T.600,0nm", "T.400,0nm.500,0nm"})
    channels.push_back(test::constant_channel(name, 4, 4, 0.25f));
  test::write_raw_exr(fluorescent, 4, 4, channels);
  for (const bool lit : {true, false}) {
    std::vector<std::string> args = {"sensor", fluorescent.string(), "-o", out.string(), "--quiet"};
    if (lit) args.insert(args.end(), {"--illuminant", "D65"});
    expect_bad_input(run_chromatrace(args), "fluorescent.exr", "bi-spectral (fluorescent) file");
  }
}

TEST_F(CameraRaw, DngNeedsARawMosaic) {
  const fs::path out = dir_.file("ideal.dng");
  expect_bad_input(run_chromatrace({"sensor", input_.string(), "-o", out.string(), "--quiet"}), "ideal.dng",
                   "a DNG holds a Bayer mosaic of at most 16-bit digital numbers");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace ct
