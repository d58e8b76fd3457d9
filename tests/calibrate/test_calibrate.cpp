// SPDX-License-Identifier: Apache-2.0
// chromatrace calibrate: photon-transfer series simulated by the sensor simulator with known EMVA 1288 parameters,
// and every parameter recovered — within 2 %, or within 3 standard errors where the frames cannot give 2 % (the
// row and column parts, measured on a few hundred lines whatever the frame count; a DSNU below the temporal noise).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "calibrate/calibration.h"
#include "calibrate/spatial.h"
#include "core/error.h"
#include "core/spectrum.h"
#include "core/json_input.h"
#include "core/statistics.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

const Bands kBand = Bands::from_edges({545, 555});
constexpr int kSize = 192;  // 192² values per channel: a temporal variance to ±0.74 % (1σ) per exposure
constexpr double kFNumber = 4, kPitchUm = 5;

// Photons per pixel and second per unit band radiance (eq. 1 and 2): μ_p = (π/4)(1/N)²·L·A·λ/(hc)·Δλ.
double photons_per_radiance_second() {
  return std::numbers::pi / 4.0 / (kFNumber * kFNumber) * kPitchUm * kPitchUm * 1e-12 * kBand.centre(0) * 1e-9 /
         (kPlanck * kLightSpeed) * kBand.width(0);
}

struct Camera {
  double qe, gain, black, full_well, read, dark_current, dsnu, prnu, dsnu_column, prnu_column;
  int bits;
};

// The exposure times of the series as shares of the time that fills the full well: ten up to 70 % for the gain, then
// steps through saturation, and two well beyond it, where every pixel clips.
const std::vector<double> kExposureShares = {0.04, 0.11, 0.18, 0.25, 0.32, 0.39, 0.46, 0.53, 0.6, 0.67,
                                             0.94, 0.97, 1.0,  1.03, 1.3,  1.6};
constexpr double kSaturationStep = 0.03;

class Calibrate : public ::testing::Test {
 protected:
  void SetUp() override { flat_camera_ = test::write_flat_camera(dir_.path()); }

  // Writes the series of a camera: two flats and two darks per exposure time. Returns the input and the photons
  // per pixel and second.
  calibrate::CalibrationInput series(const Camera& c, const std::string& name) { return series(c, name, kExposureShares, 2); }
  // As camera raw: DNGs of an RGGB mosaic of twice the size (each 2 × 2 tile's red, first green and blue are read).
  calibrate::CalibrationInput series(const Camera& c, const std::string& name, const std::vector<double>& shares, int per_step,
                                     bool dng = false) {
    std::vector<Shot> shots;
    for (const double share : shares) shots.push_back({share, 1.0, per_step, per_step});
    return shoot(c, name, shots, dng ? Output::Dng : Output::Exr);
  }

  // One step of a series: `flats` and `darks` frames of `time_s` under `light` times the radiance that fills the full
  // well in one second.
  struct Shot {
    double time_s, light;
    int flats, darks;
  };
  enum class Output { Exr, Dng, Demosaiced };  // the simulator's frames without a CFA, its RGGB DNG, or demosaiced RGB
  // The frames of `shots`, named <name>-<time>-<flat|dark>[-L<light>]-<k> (the light only where it is not 1).
  calibrate::CalibrationInput shoot(const Camera& c, const std::string& name, const std::vector<Shot>& shots, Output output,
                                    const Json& overrides = Json::object()) {
    const bool dng = output == Output::Dng;
    const int size = dng ? 2 * kSize : kSize;
    const double fill = c.full_well / c.qe / photons_per_radiance_second();  // the radiance that fills the well in 1 s
    const fs::path dark = dir_.file(name + "-dark.exr");
    test::write_radiance(dark, kBand, size, size, [&](int, int, std::size_t) { return 0.0f; });
    std::map<double, fs::path> lights;
    calibrate::CalibrationInput input;
    input.photons_per_s = fill * photons_per_radiance_second();
    for (const Shot& shot : shots)
      if (!lights.contains(shot.light)) {
        lights[shot.light] = dir_.file(fmt::format("{}-light-{}.exr", name, shot.light));
        test::write_radiance(lights[shot.light], kBand, size, size, [&](int, int, std::size_t) { return static_cast<float>(shot.light * fill); });
      }
    std::uint64_t seed = 1;
    for (const Shot& shot : shots)
      for (const bool is_flat : {true, false})
        for (int k = 0; k < (is_flat ? shot.flats : shot.darks); ++k) {
          Json patch = {{"optics", {{"f_number", kFNumber}, {"cos4", false}}},
                        {"exposure", {{"time_s", shot.time_s}}},
                        {"pixel", {{"pitch_um", kPitchUm}}},
                        {"spectral_response", {{"camera", flat_camera_.string()}, {"basis", "photon"}, {"peak_qe", c.qe}}},
                        {"noise",
                         {{"enabled", true},
                          {"dark_current_e_per_s", c.dark_current},
                          {"read_e", c.read},
                          {"dsnu_e", c.dsnu},
                          {"prnu", c.prnu},
                          {"dsnu_column_e", c.dsnu_column},
                          {"prnu_column", c.prnu_column},
                          {"seed", seed++},
                          {"pattern_seed", 7}}},
                        {"full_well", {{"enabled", true}, {"electrons", c.full_well}}},
                        {"adc", {{"enabled", true}, {"gain_dn_per_e", c.gain}, {"black_level_dn", c.black}, {"bits", c.bits}}},
                        {"display", {{"enabled", false}}}};
          if (output != Output::Exr) patch["cfa"] = {{"enabled", true}, {"pattern", "RGGB"}};
          patch.merge_patch(overrides);
          patch["noise"]["seed"] = seed - 1;  // each frame its own temporal noise, whatever the overrides say
          const std::string light = is_flat && shot.light != 1.0 ? fmt::format("-L{}", shot.light) : "";
          const fs::path out = dir_.file(fmt::format("{}-{}-{}{}-{}.{}", name, shot.time_s, is_flat ? "flat" : "dark", light, k, dng ? "dng" : "exr"));
          test::run_sensor(is_flat ? lights[shot.light] : dark, out, test::config_of(patch));
          (is_flat ? input.flats : input.darks).push_back(out);
        }
    return input;
  }

  test::TempDir dir_;
  fs::path flat_camera_;
};

// |estimate − truth| within 2 % of the truth or 3 standard errors, whichever is larger; the message names both.
void expect_recovered(const calibrate::Estimate& e, double truth, const std::string& what, double relative = 0.02) {
  const double allowed = std::max(relative * std::abs(truth), kSigmasPerItem * e.standard_error);
  EXPECT_LE(std::abs(e.value - truth), allowed) << what << ": " << e.value << " ± " << e.standard_error << ", truth " << truth;
}

void expect_camera(const calibrate::Calibration& cal, const Camera& c, std::size_t channels = 3) {
  ASSERT_EQ(cal.channels.size(), channels);
  for (const calibrate::ChannelCalibration& ch : cal.channels) {
    SCOPED_TRACE("channel " + ch.channel);
    expect_recovered(ch.gain_dn_per_e, c.gain, "system gain K");
    expect_recovered(ch.dark_noise_e, c.read, "temporal dark noise σ_d");
    expect_recovered(ch.dark_current_e_per_s, c.dark_current, "dark current");
    ASSERT_TRUE(ch.dark_current_from_variance_e_per_s);
    expect_recovered(*ch.dark_current_from_variance_e_per_s, c.dark_current, "dark current from the dark variance");
    expect_recovered(ch.black_level_dn, c.black, "black level", 0.002);
    ASSERT_TRUE(ch.clip_level_e);
    expect_recovered(*ch.clip_level_e, c.full_well, "clip level (the full well)");
    EXPECT_FALSE(ch.clips_at_adc);  // the well clips these cameras, below the ADC's top code
    // EMVA's saturation capacity: the exposure of largest temporal variance, where a frame's brightest pixels start to
    // clip — below the full well by the dark electrons, up to three standard deviations of the pixels' spread there
    // (shot noise and PRNU), and up to one step of the exposure series (3 % of the full well near saturation).
    const double spread = std::sqrt(c.full_well + std::pow(c.prnu * c.full_well, 2));
    EXPECT_LE(ch.saturation_capacity_e.value, c.full_well);
    EXPECT_GE(ch.saturation_capacity_e.value, c.full_well * (1 - kSaturationStep) - c.dark_current - 3 * spread -
                                                  kSigmasPerItem * ch.saturation_capacity_e.standard_error);
    expect_recovered(ch.dsnu_e.pixel, c.dsnu, "DSNU, pixel part");
    expect_recovered(ch.prnu.pixel, c.prnu, "PRNU, pixel part");
    expect_recovered(ch.dsnu_e.column, c.dsnu_column, "DSNU, column part");
    expect_recovered(ch.prnu.column, c.prnu_column, "PRNU, column part");
    expect_recovered(ch.dsnu_e.row, 0, "DSNU, row part");
    expect_recovered(ch.prnu.row, 0, "PRNU, row part");
    ASSERT_TRUE(ch.quantum_efficiency);
    expect_recovered(*ch.quantum_efficiency, c.qe, "quantum efficiency");
    // The simulated sensor is linear up to the full well: the linearity error is what the noise leaves, under 0.5 %.
    EXPECT_LT(ch.linearity_error, 0.005);
  }
}

TEST_F(Calibrate, RecoversEveryParameterOfAScientificCamera) {
  const Camera c{0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 16};
  const calibrate::Calibration cal = calibrate::calibrate(series(c, "scientific"));
  expect_camera(cal, c);
}

// The frames a camera gives: DNGs of its Bayer mosaic, read as camera raw without demosaicing.
TEST_F(Calibrate, RecoversAStrongColumnPatternApartFromThePixelsFromCameraRaw) {
  const Camera c{0.45, 0.5, 200, 15000, 3, 20, 1.5, 0.005, 1.0, 0.02, 14};
  const calibrate::CalibrationInput in = series(c, "columns", kExposureShares, 2, true);
  const calibrate::Calibration cal = calibrate::calibrate(in);
  expect_camera(cal, c);
  // The settings written reproduce the camera: the sensor simulator takes them as they are.
  const Json& s = cal.sensor;
  EXPECT_NEAR(s["adc"]["gain_dn_per_e"].get<double>(), c.gain, 0.02 * c.gain);
  EXPECT_NEAR(s["noise"]["prnu_column"].get<double>(), c.prnu_column, 0.2 * c.prnu_column);
  // A DNG has no ADC bits, only its white level (here black + K × full well = 7700): the fewest bits that hold it.
  EXPECT_EQ(s["adc"]["bits"].get<int>(), 13);
  EXPECT_NO_THROW(test::config_of(s));
  // EXIF's exposure time, a float in the file, is read as the decimal written (0.04 s, not 0.03999999910593033 s).
  ASSERT_EQ(cal.channels[1].points.size(), kExposureShares.size());
  for (std::size_t k = 0; k < kExposureShares.size(); ++k) EXPECT_EQ(cal.channels[1].points[k].exposure_s, kExposureShares[k]);

  // A frame of another mosaic (BGGR: its "red" plane holds other photosites) is refused by name.
  Json patch = {{"exposure", {{"time_s", 0.04}}}, {"noise", {{"enabled", true}}}, {"adc", {{"enabled", true}}},
                {"cfa", {{"enabled", true}, {"pattern", "BGGR"}}}, {"display", {{"enabled", false}}}};
  const fs::path bggr = dir_.file("bggr.dng");
  test::run_sensor(dir_.file("columns-dark.exr"), bggr, test::config_of(patch));
  calibrate::CalibrationInput mixed = in;
  mixed.darks.push_back(bggr);
  try {
    calibrate::calibrate(mixed);
    ADD_FAILURE() << "a BGGR frame among RGGB frames was not refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(bggr.string() + ": camera raw, "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("CFA BGGR, but"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ct

namespace ct {
namespace {

std::vector<std::string> calibrate_args(const std::vector<fs::path>& flats, const std::vector<fs::path>& darks, const fs::path& out) {
  std::vector<std::string> args = {"calibrate", "-o", out.string(), "-q", "--flat"};
  for (const fs::path& f : flats) args.push_back(f.string());
  args.push_back("--dark");
  for (const fs::path& d : darks) args.push_back(d.string());
  return args;
}

// Frames whose exposure share is in `shares` (the files are named by it).
std::vector<fs::path> only(const std::vector<fs::path>& frames, const std::vector<double>& shares) {
  std::vector<fs::path> kept;
  for (const fs::path& f : frames)
    for (const double s : shares)
      if (f.filename().string().find(fmt::format("-{}-", s)) != std::string::npos) kept.push_back(f);
  return kept;
}

TEST_F(Calibrate, TheCommandWritesSettingsTheSensorTakesAndRefusesSeriesThatCannotSupportThem) {
  const Camera c{0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 16};
  const calibrate::CalibrationInput in = series(c, "cli");
  const fs::path out = dir_.file("camera.json"), report = dir_.file("report");
  std::vector<std::string> args = calibrate_args(in.flats, in.darks, out);
  args.insert(args.end(), {"--report", report.string(), "--photons-per-s", fmt::format("{}", *in.photons_per_s), "--pixel-um", "5",
                           "--temperature", "25"});
  const auto ok = test::run_chromatrace(args);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(read_json(report / "calibration.json")["operating_point"]["pixel_pitch_um"].get<double>(), 5.0);
  EXPECT_EQ(read_json(report / "calibration.json")["operating_point"]["temperature_c"].get<double>(), 25.0);
  const sensor::SensorConfig settings = test::config_of(read_json(out));
  EXPECT_NEAR(settings.adc.gain_dn_per_e, c.gain, 0.02 * c.gain);
  EXPECT_NEAR(settings.full_well.electrons, c.full_well, 0.02 * c.full_well);
  const Json written = read_json(report / "calibration.json");
  ASSERT_EQ(written["channels"].size(), 3u);
  EXPECT_NEAR(written["channels"][1]["gain_dn_per_e"]["value"].get<double>(), c.gain, 0.02 * c.gain);
  for (const char* file : {"index.html", "photon_transfer.svg", "snr.svg", "linearity.svg", "dark_signal.svg"})
    EXPECT_GT(fs::file_size(report / file), 1000u) << file;

  // Each bad series: exit 2, one line naming the option and what is missing, and no settings written.
  const fs::path bad = dir_.file("bad.json");
  std::vector<fs::path> one_flat_less = in.flats;
  one_flat_less.erase(one_flat_less.begin());
  const std::vector<double> unsaturated(kExposureShares.begin(), kExposureShares.begin() + 10);
  struct Case {
    std::vector<fs::path> flats, darks;
    std::string message;
  };
  const std::vector<Case> cases = {
      {only(in.flats, {0.04}), only(in.darks, {0.04}), "the photon transfer needs a series of exposures"},
      {one_flat_less, in.darks, "--flat: 1 flat frame at 0.04 s"},
      {in.flats, only(in.darks, {0.04, 0.11}), "--dark: 0 dark frames at 0.18 s"},
      {only(in.flats, unsaturated), only(in.darks, unsaturated), "no exposure saturates"},
      {only(in.flats, {0.25, 0.67, 0.94, 0.97, 1.0, 1.03, 1.3, 1.6}), only(in.darks, {0.25, 0.67, 0.94, 0.97, 1.0, 1.03, 1.3, 1.6}),
       "between black and 70 % of saturation; the gain needs at least three"},
      // The brightest pixels clip first (PRNU), so the temporal variance peaks at 0.94 of the full well's exposure.
      {only(in.flats, {0.94, 0.97, 1.0, 1.03, 1.3, 1.6}), only(in.darks, {0.94, 0.97, 1.0, 1.03, 1.3, 1.6}),
       "the shortest exposure, 0.94 s, already saturates"},
      {only(in.flats, {1.3, 1.6}), only(in.darks, {1.3, 1.6}), "every exposure clips every pixel"},
      // From a quarter of the full well straight to clipping: the peak of the variance, saturation, never measured.
      {only(in.flats, {0.04, 0.11, 0.18, 0.25, 1.3, 1.6}), only(in.darks, {0.04, 0.11, 0.18, 0.25, 1.3, 1.6}),
       "the series jumps from 0.25 s"},
      {in.darks, in.darks, "no flat is brighter than the dark frames of its exposure time"},
  };
  for (const Case& k : cases) {
    const auto r = test::run_chromatrace(calibrate_args(k.flats, k.darks, bad));
    EXPECT_EQ(r.exit_code, 2) << k.message;
    EXPECT_NE(r.err.find(k.message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(bad));
  }

  // A frame of another size, and a demosaiced frame (its pixels share noise), are refused by name.
  const fs::path small = dir_.file("small.exr"), small_frame = dir_.file("small-frame.exr");
  test::write_radiance(small, kBand, 64, 64, [](int, int, std::size_t) { return 0.0f; });
  Json patch = {{"exposure", {{"time_s", 0.04}}}, {"noise", {{"enabled", true}}}, {"adc", {{"enabled", true}}}, {"display", {{"enabled", false}}}};
  test::run_sensor(small, small_frame, test::config_of(patch));
  std::vector<fs::path> darks = in.darks;
  darks.push_back(small_frame);
  auto r = test::run_chromatrace(calibrate_args(in.flats, darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(small_frame.string() + ": 64 x 64 values per channel"), std::string::npos) << r.err;
  // The odd frame given first is still the one named, against a frame of the size most frames have.
  std::vector<fs::path> flats = in.flats;
  flats.insert(flats.begin(), small_frame);
  r = test::run_chromatrace(calibrate_args(flats, in.darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(small_frame.string() + ": 64 x 64 values per channel, but " + in.flats[0].string() +
                       fmt::format(" has {0} x {0}", kSize)),
            std::string::npos) << r.err;
  patch["cfa"] = {{"enabled", true}};
  const fs::path mosaic = dir_.file("demosaiced.exr");
  test::run_sensor(small, mosaic, test::config_of(patch));
  darks.back() = mosaic;
  r = test::run_chromatrace(calibrate_args(in.flats, darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(mosaic.string() + ": its pixels were interpolated from a colour filter array"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(bad));

  std::vector<std::string> bad_pitch = calibrate_args(in.flats, in.darks, bad);
  bad_pitch.insert(bad_pitch.end(), {"--pixel-um", "0"});
  r = test::run_chromatrace(bad_pitch);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "chromatrace calibrate: error: --pixel-um: must be a positive number of micrometres, got 0\n");

  // An option where the frames should be: named as what it is, not as a missing option.
  auto no_frames = test::run_chromatrace({"calibrate", "--flat", "--dark", in.darks[0].string(), in.darks[1].string(), "-o", bad.string()});
  EXPECT_EQ(no_frames.exit_code, 2);
  EXPECT_EQ(no_frames.err, "chromatrace calibrate: error: --flat: no value given before the option --dark\n");
  no_frames = test::run_chromatrace({"calibrate", "--dark", in.darks[0].string(), "--flat", "-o", bad.string()});
  EXPECT_EQ(no_frames.err, "chromatrace calibrate: error: --flat: no value given before the option -o\n");
  EXPECT_FALSE(fs::exists(bad));

  // A frame grabber that hands one buffer twice: each exposure's second flat a copy of its first. Refused naming both
  // files, with the report asked for too (its photon transfer would have no noise to plot), and nothing written.
  std::vector<fs::path> copied;
  for (const double share : kExposureShares) {
    const std::vector<fs::path> pair = only(in.flats, {share});
    ASSERT_EQ(pair.size(), 2u);
    const fs::path copy = dir_.file(fmt::format("copy-{}.exr", share));
    fs::copy_file(pair[0], copy);
    copied.insert(copied.end(), {pair[0], copy});
  }
  const fs::path bad_report = dir_.file("bad-report");
  std::vector<std::string> copied_args = calibrate_args(copied, in.darks, bad);
  copied_args.insert(copied_args.end(), {"--report", bad_report.string()});
  r = test::run_chromatrace(copied_args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(fmt::format("copy-{}.exr: the same image as {} (both flat frames at", kExposureShares[0],
                                   only(in.flats, {kExposureShares[0]})[0].string())),
            std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(bad));
  EXPECT_FALSE(fs::exists(bad_report));

  // A full disk where the settings go (a 64 KiB tmpfs, nearly filled, in a mount namespace of its own): the settings
  // cannot be written, the command says so naming the file and fails (exit 1: the machine, not the input), and neither the report (staged in full on
  // another disk) nor a half-written settings file is left.
  {
    const fs::path disk = dir_.file("full-disk"), full_report = dir_.file("full-disk-report");
    fs::create_directory(disk);
    std::string command = fmt::format("mount -t tmpfs -o size=64k tmpfs '{}' || {{ echo mount-failed; exit 0; }}; "
                                      "head -c 64000 /dev/zero > '{}/filler' 2>/dev/null; '{}'",
                                      disk.string(), disk.string(), CHROMATRACE_EXE);
    for (const std::string& a : calibrate_args(in.flats, in.darks, disk / "camera.json")) command += " '" + a + "'";
    command += fmt::format(" --report '{}'; echo exit=$?; ls -A '{}'", full_report.string(), disk.string());
    const auto full = test::run_program("/usr/bin/unshare", {"-m", "sh", "-c", command});
    if (full.out.find("mount-failed") != std::string::npos) {
      std::cerr << "no mount namespace here (unshare -m and a tmpfs need CAP_SYS_ADMIN): the full-disk case was not run\n";
    } else {
      EXPECT_NE(full.out.find("exit=1\nfiller\n"), std::string::npos) << full.out << full.err;
      EXPECT_EQ(full.out.find("camera.json"), std::string::npos) << full.out;
      EXPECT_NE(full.err.find((disk / "camera.json").string()), std::string::npos) << full.err;
      EXPECT_FALSE(fs::exists(full_report));
    }
  }

  // An input frame inside the report's folder under a name the report writes is refused, and left as it was.
  const fs::path inside = dir_.file("report-with-input");
  fs::create_directory(inside);
  fs::copy_file(in.darks[0], inside / "calibration.json");
  const std::uintmax_t size = fs::file_size(inside / "calibration.json");
  std::vector<fs::path> darks_inside = in.darks;
  darks_inside[0] = inside / "calibration.json";
  std::vector<std::string> inside_args = calibrate_args(in.flats, darks_inside, bad);
  inside_args.insert(inside_args.end(), {"--report", inside.string()});
  r = test::run_chromatrace(inside_args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find((inside / "calibration.json").string() + ": is the input"), std::string::npos) << r.err;
  EXPECT_EQ(fs::file_size(inside / "calibration.json"), size);
  EXPECT_FALSE(fs::exists(bad));
}

// A frame as an ordinary camera file: the channels `channels` of the simulator's frame, its digital numbers as they
// are, without the simulator's metadata; the exposure time in EXIF's ExposureTime. `type` UINT16 (a TIFF or PNG) or
// FLOAT (an EXR), the values times `scale`.
fs::path write_plain(const fs::path& exr, const std::vector<int>& channels, const fs::path& out, double exposure_s,
                     OIIO::TypeDesc type = OIIO::TypeDesc::UINT16, float scale = 1) {
  const test::RgbLayer rgb = test::read_rgb(exr);
  const auto n = static_cast<std::size_t>(rgb.width) * static_cast<std::size_t>(rgb.height);
  std::vector<float> values(n * channels.size());
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < channels.size(); ++k) values[i * channels.size() + k] = rgb.values[i * 3 + static_cast<std::size_t>(channels[k])] * scale;
  OIIO::ImageSpec spec(rgb.width, rgb.height, static_cast<int>(channels.size()), type);
  spec.attribute("ExposureTime", static_cast<float>(exposure_s));
  spec.attribute("DateTime", "2026:11:29 <img src=x onerror=alert(1)>");  // a hostile date: the report shows it as text
  auto file = OIIO::ImageOutput::create(out.string());
  EXPECT_TRUE(file);
  // Integer files take values as fractions of full scale.
  if (type == OIIO::TypeDesc::UINT16 || type == OIIO::TypeDesc::UINT8)
    for (float& v : values) v /= type == OIIO::TypeDesc::UINT8 ? 255.0f : 65535.0f;
  EXPECT_TRUE(file->open(out.string(), spec));
  EXPECT_TRUE(file->write_image(OIIO::TypeDesc::FLOAT, values.data()));
  file->close();
  return out;
}

// The exposure time of a frame named <name>-<time>-… (as shoot() names them).
double time_of(const fs::path& frame) {
  const std::string name = frame.stem().string();
  const std::size_t a = name.find('-') + 1;
  return std::stod(name.substr(a, name.find('-', a) - a));
}

// Every frame of a series as plain 16-bit TIFFs of `channels`.
calibrate::CalibrationInput plain_series(const calibrate::CalibrationInput& in, const std::vector<int>& channels, const std::string& suffix) {
  calibrate::CalibrationInput out = in;
  for (auto* set : {&out.flats, &out.darks})
    for (fs::path& f : *set) f = write_plain(f, channels, f.parent_path() / (f.stem().string() + suffix + ".tif"), time_of(f));
  return out;
}

// Frames as a machine-vision camera writes them: 16-bit TIFFs (or float EXRs) of digital numbers without any metadata
// but EXIF's exposure time, three channels or one (a monochrome camera). Calibrated as the simulator's own files are: every
// parameter recovered, the noise of neighbouring pixels and of the channels uncorrelated (0 within three standard
// errors), and the ADC's 12 bits found from the largest value (the flats clip at the full well, 3700 DN: 12 bits, not
// the file's 16).
TEST_F(Calibrate, OrdinaryFramesOfAColourOrAMonochromeCameraAreCalibrated) {
  const Camera c{0.6, 0.18, 100, 20000, 5, 100, 2, 0.01, 0, 0, 12};
  const calibrate::CalibrationInput simulated = series(c, "plain");
  calibrate::CalibrationInput rgb = plain_series(simulated, {0, 1, 2}, "-rgb");
  const calibrate::Calibration colour = calibrate::calibrate(rgb);
  expect_camera(colour, c);
  EXPECT_EQ(colour.sensor["adc"]["bits"].get<int>(), 12);
  EXPECT_NE(colour.sensor["description"].get<std::string>().find("from the largest value in the frames"), std::string::npos);
  const calibrate::NoiseCorrelation& nc = colour.noise_correlation;
  for (const double rho : {nc.horizontal, nc.vertical, nc.between_channels}) EXPECT_LT(rho, kSigmasPerItem * nc.standard_error);
  std::cerr << fmt::format("plain frames: noise correlation {:.4f} horizontal, {:.4f} vertical, {:.4f} between channels, ± {:.4f}\n",
                           nc.horizontal, nc.vertical, nc.between_channels, nc.standard_error);

  // The same as float EXRs of whole digital numbers, with no metadata but the exposure time.
  calibrate::CalibrationInput exr = simulated;
  for (auto* set : {&exr.flats, &exr.darks})
    for (fs::path& f : *set) f = write_plain(f, {0, 1, 2}, f.parent_path() / (f.stem().string() + "-plain.exr"), time_of(f), OIIO::TypeDesc::FLOAT);
  expect_camera(calibrate::calibrate(exr), c);

  calibrate::CalibrationInput grey = plain_series(simulated, {1}, "-mono");
  const calibrate::Calibration mono = calibrate::calibrate(grey);
  expect_camera(mono, c, 1);
  EXPECT_EQ(mono.channels[0].channel, "Y");
  EXPECT_NE(mono.sensor["description"].get<std::string>().find("one channel (monochrome)"), std::string::npos);
  EXPECT_NO_THROW(test::config_of(mono.sensor));
  // Through the command, with the report: one channel in it.
  const fs::path report = dir_.file("mono-report"), out = dir_.file("mono.json");
  std::vector<std::string> args = calibrate_args(grey.flats, grey.darks, out);
  args.insert(args.end(), {"--report", report.string(), "--photons-per-s", fmt::format("{}", *grey.photons_per_s)});
  const auto r = test::run_chromatrace(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_json(report / "calibration.json")["channels"].size(), 1u);
  // The frames' EXIF date, made hostile (TIFF keeps its first 19 characters), is in the datasheet as text.
  std::ifstream page(report / "index.html");
  const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("2026:11:29 &lt;img src="), std::string::npos);
  EXPECT_EQ(html.find("<img"), std::string::npos);

  // A colour camera's mosaic written as one grey channel (dcraw -D -4 -T: the raw values, not demosaiced), under a
  // green light that its red and blue photosites see far less of: refused, where its PRNU would report the filters.
  const std::vector<Shot> shots = {{0.2, 1, 2, 2}, {0.4, 1, 2, 2}, {0.6, 1, 2, 2}, {1.2, 1, 2, 2}};
  const calibrate::CalibrationInput dngs =
      shoot(c, "mosaic", shots, Output::Dng, {{"spectral_response", {{"camera", "nikon_d810"}, {"peak_qe", c.qe}}}});
  std::vector<std::string> mosaic_args = {"calibrate", "-o", dir_.file("mosaic.json").string(), "-q", "--flat"};
  for (const auto* set : {&dngs.flats, &dngs.darks}) {
    if (set == &dngs.darks) mosaic_args.push_back("--dark");
    for (const fs::path& dng : *set) {
      const int status = std::system(fmt::format("dcraw -D -4 -T '{}'", dng.string()).c_str());
      ASSERT_EQ(status, 0) << "dcraw -D -4 -T " << dng;
      mosaic_args.push_back(fs::path(dng).replace_extension(".tiff").string());
    }
  }
  const auto refused = test::run_chromatrace(mosaic_args);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("2 × 2 phases differ by"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("a colour camera's mosaic"), std::string::npos) << refused.err;
  std::cerr << refused.err;

  // A monochrome frame among colour ones: named against the rest.
  calibrate::CalibrationInput mixed = rgb;
  mixed.darks.back() = grey.darks.back();
  try {
    calibrate::calibrate(mixed);
    ADD_FAILURE() << "a monochrome frame among colour frames was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(grey.darks.back().string() + ": linear TIF, one channel (monochrome), but"), std::string::npos) << e.what();
  }
}

// Frames whose pixels share noise, or that are not digital numbers, are refused by name: the simulator's demosaiced
// frames written as plain TIFFs (no metadata says so; bilinear interpolation correlates a pixel's noise with its
// neighbours' by about 0.5), a float EXR scaled to 0–1, a series encoded with the sRGB curve, and a JPEG (a
// tone-mapped picture, unless the user says it is linear).
TEST_F(Calibrate, FramesWhosePixelsShareNoiseOrAreNotDigitalNumbersAreRefused) {
  const Camera c{0.6, 0.18, 100, 20000, 5, 100, 2, 0.01, 0, 0, 12};
  const std::vector<Shot> shots = {{0.2, 1, 2, 2}, {0.4, 1, 2, 2}, {0.6, 1, 2, 2}, {1.2, 1, 2, 2}};
  const calibrate::CalibrationInput demosaiced = plain_series(shoot(c, "demosaiced", shots, Output::Demosaiced), {0, 1, 2}, "-plain");
  const fs::path bad = dir_.file("bad.json");
  auto r = test::run_chromatrace(calibrate_args(demosaiced.flats, demosaiced.darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--flat: the temporal noise of the flats correlates by"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the frames were interpolated or filtered"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(bad));
  std::cerr << r.err;

  const calibrate::CalibrationInput frames = shoot(c, "formats", shots, Output::Exr);
  const fs::path scaled = write_plain(frames.flats[0], {0, 1, 2}, dir_.file("scaled.exr"), 0.2, OIIO::TypeDesc::FLOAT, 1.0f / 4095);
  std::vector<fs::path> flats = frames.flats;
  flats[0] = scaled;
  r = test::run_chromatrace(calibrate_args(flats, frames.darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(scaled.string() + ": channel R holds"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not a whole number"), std::string::npos) << r.err;

  // A series encoded with the sRGB curve (a 16-bit TIFF that says nothing of it): its temporal variance peaks while its
  // signal still grows, named as what that is rather than as too few exposures below saturation.
  calibrate::CalibrationInput encoded = series(c, "srgb");
  for (auto* set : {&encoded.flats, &encoded.darks})
    for (fs::path& f : *set) {
      const test::RgbLayer rgb = test::read_rgb(f);
      std::vector<float> v(rgb.values.size());
      for (std::size_t i = 0; i < v.size(); ++i) {
        const double x = std::clamp(rgb.values[i] / 4095.0, 0.0, 1.0);
        v[i] = static_cast<float>(x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055);
      }
      OIIO::ImageSpec spec(rgb.width, rgb.height, 3, OIIO::TypeDesc::UINT16);
      spec.attribute("ExposureTime", static_cast<float>(time_of(f)));
      const fs::path out = f.parent_path() / (f.stem().string() + "-srgb.tif");
      auto file = OIIO::ImageOutput::create(out.string());
      ASSERT_TRUE(file && file->open(out.string(), spec) && file->write_image(OIIO::TypeDesc::FLOAT, v.data()));
      file->close();
      f = out;
    }
  r = test::run_chromatrace(calibrate_args(encoded.flats, encoded.darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("the variance falls while the signal still grows, as in frames encoded with a response curve"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(bad));

  const fs::path jpeg = write_plain(frames.flats[0], {0, 1, 2}, dir_.file("frame.jpg"), 0.2, OIIO::TypeDesc::UINT8, 1.0f / 16);
  flats[0] = jpeg;
  r = test::run_chromatrace(calibrate_args(flats, frames.darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(jpeg.string() + ": its values are encoded with a response curve (the sRGB curve, from a JPEG"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--input-transfer linear"), std::string::npos) << r.err;
  std::vector<std::string> linear = calibrate_args(flats, frames.darks, bad);
  linear.insert(linear.end(), {"--input-transfer", "linear"});
  r = test::run_chromatrace(linear);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.find("response curve"), std::string::npos) << r.err;  // taken as linear: on to the next question
  EXPECT_FALSE(fs::exists(bad));
}

// EMVA 1288's second method: one exposure time (0.5 s), the irradiance varied, the flats in pairs in the order given,
// with the photons per pixel of each pair; darks at 0.5 s, and darks alone at 0.1 and 1.5 s for the dark current.
// Every parameter is recovered as from an exposure series.
TEST_F(Calibrate, ASeriesAtOneExposureTimeUnderVaryingIrradiance) {
  const Camera c{0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 16};
  const double t = 0.5;
  std::vector<Shot> shots;
  for (const double share : kExposureShares) shots.push_back({t, share / t, 2, 0});
  shots.push_back({t, 1, 0, 2});
  shots.push_back({0.1, 1, 0, 2});
  shots.push_back({1.5, 1, 0, 2});
  calibrate::CalibrationInput in = shoot(c, "irradiance", shots, Output::Exr);
  const double photons_per_s = *in.photons_per_s;
  in.photons_per_s.reset();
  for (const double share : kExposureShares) in.photons_per_pixel.push_back(photons_per_s * share);
  const calibrate::Calibration cal = calibrate::calibrate(in);
  expect_camera(cal, c);
  EXPECT_EQ(cal.series, fmt::format("{} irradiances at 0.5 s; darks alone at 2 further times", kExposureShares.size()));
  EXPECT_EQ(cal.channels[0].dark_points.size(), 3u);

  // Without the photons: no linearity, no quantum efficiency, said.
  calibrate::CalibrationInput no_photons = in;
  no_photons.photons_per_pixel.clear();
  const calibrate::Calibration without = calibrate::calibrate(no_photons);
  EXPECT_FALSE(without.channels[1].quantum_efficiency);
  bool said = false;
  for (const std::string& n : without.channels[1].notes) said = said || n.find("--photons-per-pixel") != std::string::npos;
  EXPECT_TRUE(said);

  // Refused by name: two flats swapped between pairs (A1 B1 A2 B2), an odd flat, photons per second, and a wrong count.
  const fs::path bad = dir_.file("bad.json");
  std::vector<fs::path> swapped = in.flats;
  std::swap(swapped[1], swapped[2]);
  auto r = test::run_chromatrace(calibrate_args(swapped, in.darks, bad));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(swapped[1].string() + ": its channel R is"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("each pair one irradiance"), std::string::npos) << r.err;
  std::vector<fs::path> odd = in.flats;
  odd.pop_back();
  r = test::run_chromatrace(calibrate_args(odd, in.darks, bad));
  EXPECT_NE(r.err.find(fmt::format("--flat: {} flat frames at 0.5 s", odd.size())), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(odd.back().string() + ", has no partner"), std::string::npos) << r.err;
  std::vector<std::string> args = calibrate_args(in.flats, in.darks, bad);
  args.insert(args.end(), {"--photons-per-s", "1000"});
  r = test::run_chromatrace(args);
  EXPECT_NE(r.err.find("--photons-per-s: every flat has the exposure time 0.5 s, so the irradiance varied"), std::string::npos) << r.err;
  args = calibrate_args(in.flats, in.darks, bad);
  args.insert(args.end(), {"--photons-per-pixel", "1000", "2000"});
  r = test::run_chromatrace(args);
  EXPECT_NE(r.err.find(fmt::format("--photons-per-pixel: 2 values for {} pairs of flats", kExposureShares.size())), std::string::npos) << r.err;
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(fs::exists(bad));
}

// The quantum efficiency measured at the flats' wavelength sets the simulator's peak QE through the camera's curves.
// Curves (photon basis) of 1 up to 600 nm and 2 from 700 nm, simulated with a peak QE of 0.6: η at 550 nm is 0.3, and
// calibrate with --wavelength 550 gives the peak QE 0.6 back (within 2 % or 3 standard errors), every channel
// agreeing, written as spectral_response. Curves whose red channel is half the others' at 550 nm give the red
// channel's peak QE twice the others': the disagreement is said. --wavelength without --camera is refused.
TEST_F(Calibrate, TheMeasuredQuantumEfficiencySetsThePeakQeThroughTheCameraCurves) {
  auto write_curves = [&](const std::string& name, double red_at_550) {
    const fs::path csv = dir_.file(name);
    std::ofstream(csv) << "wavelength_nm,r,g,b\n"
                       << fmt::format("300,{0},1,1\n600,{0},1,1\n700,2,2,2\n900,2,2,2\n", red_at_550);
    return csv;
  };
  const fs::path curves = write_curves("curves.csv", 1), red_half = write_curves("red-half.csv", 0.5);
  const Camera c{0.3, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 16};  // qe: η at 550 nm
  const std::vector<double> shares(kExposureShares.begin(), kExposureShares.end());
  std::vector<Shot> shots;
  for (const double share : shares) shots.push_back({share, 1, 2, 2});
  calibrate::CalibrationInput in =
      shoot(c, "peak", shots, Output::Exr, {{"spectral_response", {{"camera", curves.string()}, {"basis", "photon"}, {"peak_qe", 0.6}}}});
  in.wavelength_nm = 550;
  in.camera = curves.string();
  in.basis = "photon";
  const calibrate::Calibration cal = calibrate::calibrate(in);
  expect_camera(cal, c);
  ASSERT_TRUE(cal.peak_qe);
  expect_recovered(cal.peak_qe->value, 0.6, "peak QE");
  EXPECT_TRUE(cal.peak_qe->channels_agree);
  for (const double r : cal.peak_qe->relative_qe) EXPECT_NEAR(r, 0.5, 1e-6);
  EXPECT_EQ(cal.sensor["spectral_response"]["peak_qe"].get<double>(), cal.peak_qe->value.value);
  EXPECT_EQ(cal.sensor["spectral_response"]["basis"], "photon");
  EXPECT_EQ(test::config_of(cal.sensor).response.peak_qe, cal.peak_qe->value.value);

  in.camera = red_half.string();
  const calibrate::Calibration disagreeing = calibrate::calibrate(in);
  ASSERT_TRUE(disagreeing.peak_qe);
  EXPECT_FALSE(disagreeing.peak_qe->channels_agree);
  expect_recovered(disagreeing.peak_qe->per_channel[0], 1.2, "the red channel's peak QE through curves half the truth");
  bool said = false;
  for (const std::string& n : disagreeing.notes) said = said || n.find("disagree") != std::string::npos;
  EXPECT_TRUE(said);

  in.camera.clear();
  EXPECT_THROW(calibrate::calibrate(in), InputError);
  std::vector<std::string> args = calibrate_args(in.flats, in.darks, dir_.file("bad.json"));
  args.insert(args.end(), {"--wavelength", "550"});
  const auto r = test::run_chromatrace(args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "chromatrace calibrate: error: --wavelength: needs the camera's curves too (--camera), to turn η there into a peak QE\n");
}

// The settings calibrate writes, given to the simulator, make the camera again: over the whole series, clipping
// included, each exposure's mean signal above dark, temporal variance and SNR from the calibrated settings agree with
// the original camera's within 2 %, or within what the statistics and the calibration's own errors allow: a variance
// measured on 192² pixels has a standard error of 0.74 %; and where the pixels clip, the variance moves with the
// clip: a clip δ higher clips as this one would at an exposure (1 − δ/clip) times as long, so the original's curve
// there (piecewise linear through its exposures) bounds it, δ being how far the settings' clip may lie from this
// channel's (the channels' one well against this channel's clip level, and three of its standard errors). Tested for a camera its well clips and one its 12-bit ADC clips; the spectral response is the
// calibrated one too (--wavelength 550 through the flat camera's curves).
TEST_F(Calibrate, TheSettingsWrittenReproduceTheCamerasCurvesClippingIncluded) {
  const std::vector<Camera> cameras = {{0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 16}, {0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 12}};
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    const Camera& c = cameras[k];
    SCOPED_TRACE(k == 0 ? "the well clips" : "the ADC clips");
    calibrate::CalibrationInput in = series(c, fmt::format("original{}", k));
    in.wavelength_nm = 550;
    in.camera = flat_camera_.string();
    in.basis = "photon";
    const calibrate::Calibration original = calibrate::calibrate(in);
    std::vector<Shot> shots;
    for (const double share : kExposureShares) shots.push_back({share, 1, 2, 2});
    const calibrate::Calibration again = calibrate::calibrate(shoot(c, fmt::format("again{}", k), shots, Output::Exr, original.sensor));
    const double settings_well = original.sensor["full_well"]["electrons"].get<double>();
    for (std::size_t ch = 0; ch < 3; ++ch) {
      const calibrate::ChannelCalibration& cc = original.channels[ch];
      const auto &a = cc.points, &b = again.channels[ch].points;
      ASSERT_EQ(a.size(), b.size());
      ASSERT_TRUE(cc.clip_level_e);
      // How far the settings' clip may lie from this channel's, in DN: the ADC's top code is the same code; a well is
      // the channels' one.
      const double clip_shift = cc.gain_dn_per_e.value * ((cc.clips_at_adc ? 0.0 : std::abs(settings_well - cc.clip_level_e->value)) +
                                                          kSigmasPerItem * cc.clip_level_e->standard_error);
      auto signal = [](const calibrate::TransferPoint& p) { return p.mean_dn - p.dark_mean_dn; };
      for (std::size_t i = 0; i < a.size(); ++i) {
        SCOPED_TRACE(fmt::format("channel {}, exposure {} s", cc.channel, a[i].exposure_s));
        EXPECT_NEAR(signal(b[i]), signal(a[i]), 0.02 * signal(a[i]));
        // Where the pixels clip, a clip moved by δ DN clips them as the same clip would at exposures (1 ∓ δ/clip) times
        // this one (the signal grows in proportion to the exposure): the original curve, piecewise linear through its
        // exposures, there is how far the variance may move with it.
        double moved = 0;
        const bool clipping = a[i].mean_dn >= cc.saturation_mean_dn;
        const double relative_shift = clip_shift / (cc.gain_dn_per_e.value * cc.clip_level_e->value);
        if (clipping)
          for (const double t : {a[i].exposure_s * (1 - relative_shift), a[i].exposure_s * (1 + relative_shift)})
            for (std::size_t j = 0; j + 1 < a.size(); ++j)
              if (const double t0 = a[j].exposure_s, t1 = a[j + 1].exposure_s; t >= t0 && t <= t1)
                moved = std::max(moved, std::abs(a[j].variance_dn2 + (t - t0) / (t1 - t0) * (a[j + 1].variance_dn2 - a[j].variance_dn2) -
                                                 a[i].variance_dn2));
        const double variance_se = std::hypot(a[i].variance_dn2, b[i].variance_dn2) * std::sqrt(2.0 / (kSize * kSize - 1));
        const double allowed = std::max(0.02 * a[i].variance_dn2, kSigmasPerItem * variance_se + moved) + 1e-9;
        EXPECT_NEAR(b[i].variance_dn2, a[i].variance_dn2, allowed);
        if (clipping)
          std::cerr << fmt::format("{} {} at {} s (at or beyond saturation): variance {:.4g} against {:.4g} DN², allowed ± {:.3g}\n",
                                   k == 0 ? "well" : "ADC", cc.channel, a[i].exposure_s, b[i].variance_dn2, a[i].variance_dn2, allowed);
        if (a[i].variance_dn2 > 0 && b[i].variance_dn2 > 0) {
          const double snr_a = signal(a[i]) / std::sqrt(a[i].variance_dn2), snr_b = signal(b[i]) / std::sqrt(b[i].variance_dn2);
          EXPECT_NEAR(snr_b, snr_a, 0.02 * snr_a + snr_a * allowed / a[i].variance_dn2 / 2);
        }
      }
    }
  }
}

// A camera whose 12-bit ADC clips before its full well (K 0.25 DN/e⁻ × 20 000 e⁻ + 100 DN would be 5 100 DN): its
// over-exposed pixels all hold the top code, 4 095. Calibrate finds the clip at (4095 − 100)/K = 15 980 e⁻, says the
// ADC clips there, and writes the full well above it, so that the camera simulated from its settings gives every
// over-exposed pixel 4 095 too (no variance), where a well at the clip level itself leaves the read noise on them.
TEST_F(Calibrate, ACameraThatClipsAtItsAdcIsSimulatedClippingToOneCode) {
  const Camera c{0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 12};
  const calibrate::Calibration cal = calibrate::calibrate(series(c, "adc"));
  for (const calibrate::ChannelCalibration& ch : cal.channels) {
    expect_recovered(ch.gain_dn_per_e, c.gain, "system gain K");
    ASSERT_TRUE(ch.clip_level_e);
    expect_recovered(*ch.clip_level_e, (4095 - c.black) / c.gain, "clip level at the ADC's top code");
    EXPECT_TRUE(ch.clips_at_adc);
  }
  // The top code in the settings' electrons (their gain and black level), and the well written above it.
  const double K = cal.sensor["adc"]["gain_dn_per_e"].get<double>(), black = cal.sensor["adc"]["black_level_dn"].get<double>();
  const double well = cal.sensor["full_well"]["electrons"].get<double>(), top = (4095 - black) / K;
  EXPECT_GT(well, top + 5 * c.read);
  EXPECT_EQ(cal.sensor["adc"]["bits"].get<int>(), 12);

  // Over-exposed (1.3 × the time that fills the well) through the calibrated settings, and through a well at the
  // clip level.
  auto overexposed = [&](double full_well, const std::string& name) {
    Json patch = cal.sensor;
    patch.merge_patch({{"optics", {{"f_number", kFNumber}, {"cos4", false}}},
                       {"exposure", {{"time_s", 1.3}}},
                       {"pixel", {{"pitch_um", kPitchUm}}},
                       {"spectral_response", {{"camera", flat_camera_.string()}, {"basis", "photon"}, {"peak_qe", c.qe}}},
                       {"full_well", {{"electrons", full_well}}},
                       {"display", {{"enabled", false}}}});
    const fs::path out = dir_.file(name);
    test::run_sensor(dir_.file("adc-light-1.exr"), out, test::config_of(patch));
    const test::RgbLayer rgb = test::read_rgb(out);
    double lowest = 1e9, highest = 0;
    for (const float v : rgb.values) lowest = std::min(lowest, double(v)), highest = std::max(highest, double(v));
    return std::pair{lowest, highest};
  };
  const auto [lo, hi] = overexposed(well, "calibrated.exr");
  EXPECT_EQ(lo, 4095);
  EXPECT_EQ(hi, 4095);
  const auto [spread_lo, spread_hi] = overexposed(top, "at-the-clip.exr");
  EXPECT_LT(spread_lo, 4095);  // the defect the settings avoid
  bool said = false;
  for (const std::string& n : cal.notes) said = said || n.find("the ADC's top code clips the pixels") != std::string::npos;
  EXPECT_TRUE(said);
}

// A 64 × 64 frame of Gaussian noise of `variance` whose mean is exactly `mean` (the noise drawn, then its own mean
// removed).
calibrate::Plane exact_mean_frame(std::mt19937_64& random, double mean, double variance) {
  std::normal_distribution<double> noise(0.0, std::sqrt(variance));
  calibrate::Plane p{64, 64, std::vector<double>(64 * 64)};
  double sum = 0;
  for (double& v : p.values) sum += (v = noise(random));
  for (double& v : p.values) v += mean - sum / double(p.values.size());
  return p;
}

// A compressive response, signal = 1000·t·(1 − 0.03·t) DN over exposures t = 0.1 … 1 s, with flats and darks whose
// means are exact (their noise drawn, then its mean removed) and whose temporal variance grows as a camera's: the
// linearity error is EMVA 1288's, the half range of the relative deviations from the line fitted with weights 1/y
// (the reference implementation's closed form, written out here), not an unweighted line's, which lies apart from it
// by far more than the floating-point rounding both are computed to.
TEST(CalibrateChannel, TheLinearityErrorIsTheStandardsWeightedFit) {
  std::mt19937_64 random(5);
  auto frame = [&](double mean, double variance) { return exact_mean_frame(random, mean, variance); };
  auto response = [](double t) { return 1000 * t * (1 - 0.03 * t); };
  std::vector<calibrate::ExposureStep> steps;
  for (int k = 1; k <= 11; ++k) {
    calibrate::ExposureStep s;
    s.exposure_s = 0.1 * k;
    const bool clipped = k == 11;  // beyond saturation: every pixel at the clip, a little above the last signal
    for (int i = 0; i < 2; ++i) {
      s.flats.push_back(clipped ? calibrate::Plane{64, 64, std::vector<double>(64 * 64, 100 + 1.05 * response(1.0))}
                                : frame(100 + response(s.exposure_s), 4 + 0.5 * response(s.exposure_s)));
      s.darks.push_back(frame(100, 4));
    }
    steps.push_back(s);
  }
  const calibrate::ChannelCalibration c = calibrate::calibrate_channel("G", steps);
  // The points between 5 % and 95 % of saturation (the flats at t = 1 s): t = 0.1 … 0.9 s.
  std::vector<double> x, y;
  for (int k = 1; k <= 10; ++k)
    if (response(0.1 * k) >= 0.05 * response(1.0) && response(0.1 * k) <= 0.95 * response(1.0)) x.push_back(0.1 * k), y.push_back(response(0.1 * k));
  auto half_range = [&](double a, double b) {  // signal = a·x + b
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (std::size_t i = 0; i < x.size(); ++i) lo = std::min(lo, (y[i] - (a * x[i] + b)) / (a * x[i] + b)), hi = std::max(hi, (y[i] - (a * x[i] + b)) / (a * x[i] + b));
    return (hi - lo) / 2;
  };
  double xy = 0, xy2 = 0, x2y2 = 0, y1 = 0, y2 = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    xy += x[i] / y[i], xy2 += x[i] / (y[i] * y[i]), x2y2 += (x[i] / y[i]) * (x[i] / y[i]), y1 += 1 / y[i], y2 += 1 / (y[i] * y[i]);
  const double b = (xy * xy2 - x2y2 * y1) / (xy2 * xy2 - x2y2 * y2), a = (xy - b * xy2) / x2y2;
  const double weighted = half_range(a, b);
  double mx = 0, my = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / double(x.size()), my += y[i] / double(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  const double unweighted = half_range(sxy / sxx, my - sxy / sxx * mx);
  std::cerr << fmt::format("linearity error {:.4f} %: the standard's fit {:.4f} %, an unweighted one {:.4f} %\n", 100 * c.linearity_error,
                           100 * weighted, 100 * unweighted);
  EXPECT_NEAR(c.linearity_error, weighted, 1e-9);
  EXPECT_GT(std::abs(unweighted - weighted), 1e-4);
}

// Flats whose temporal variance does not grow in proportion to their signal (it alternates between 4 and 44 DN²
// while the signal climbs in steps of 100 DN) give a slope through the origin of 0.045 ± 0.033 DN/e⁻ below 70 % of
// saturation: no measurement of the gain, refused rather than written (its saturation capacity and read noise would
// follow from it).
TEST(CalibrateChannel, AGainThatIsNoMeasurementIsRefused) {
  std::mt19937_64 random(3);
  auto frame = [&](double mean, double variance) {
    std::normal_distribution<double> noise(mean, std::sqrt(variance));
    calibrate::Plane p{64, 64, std::vector<double>(64 * 64)};
    for (double& v : p.values) v = noise(random);
    return p;
  };
  const std::vector<double> above_dark = {0, 40, 0, 40, 0, 40, 0, 50};
  std::vector<calibrate::ExposureStep> steps;
  for (std::size_t k = 0; k <= above_dark.size(); ++k) {
    calibrate::ExposureStep s;
    s.exposure_s = 0.01 * double(k + 1);
    const bool clipped = k == above_dark.size();  // every pixel at the clip, just above the last signal: no temporal variance
    for (int i = 0; i < 2; ++i) {
      s.flats.push_back(clipped ? calibrate::Plane{64, 64, std::vector<double>(64 * 64, 100.0 * double(k + 1))} : frame(100.0 * double(k + 1), 4 + above_dark[k]));
      s.darks.push_back(frame(0, 4));
    }
    steps.push_back(s);
  }
  try {
    calibrate::calibrate_channel("G", steps);
    ADD_FAILURE() << "a gain that is no measurement was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("channel G: the photon transfer gives a gain of"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("which is no measurement"), std::string::npos) << e.what();
    std::cerr << e.what() << "\n";
  }
}

// A series of Gaussian frames with exact means (noise drawn, its mean removed) and the temporal variance a camera
// gives: K²·(σ_d² + dark electrons + signal electrons) + 1/12 DN², the dark electrons I·t; darks at `dark_mean(t)`,
// flats that many DN above, ten exposures of 0.01 … 0.1 s reaching 20 000 e⁻, then one where every pixel clips (at
// 5 % above that).
std::vector<calibrate::ExposureStep> gaussian_series(double K, double sigma_d, double dark_current,
                                                     const std::function<double(double)>& dark_mean, unsigned seed) {
  std::mt19937_64 random(seed);
  auto frame = [&](double mean, double variance) { return exact_mean_frame(random, mean, variance); };
  std::vector<calibrate::ExposureStep> steps;
  for (int k = 1; k <= 11; ++k) {
    calibrate::ExposureStep s;
    s.exposure_s = 0.01 * k;
    const double dark_e = dark_current * s.exposure_s, signal_e = 2e5 * s.exposure_s;
    for (int i = 0; i < 2; ++i) {
      s.flats.push_back(k == 11 ? calibrate::Plane{64, 64, std::vector<double>(64 * 64, dark_mean(s.exposure_s) + 1.05 * K * 2e4)}
                                : frame(dark_mean(s.exposure_s) + K * signal_e,
                                        K * K * (sigma_d * sigma_d + dark_e + signal_e) + 1.0 / 12));
      s.darks.push_back(frame(dark_mean(s.exposure_s), K * K * (sigma_d * sigma_d + dark_e) + 1.0 / 12));
    }
    steps.push_back(s);
  }
  return steps;
}

// A camera that subtracts its dark offset on chip: the dark mean stays at 100 DN while the dark electrons' shot noise
// grows (500 e⁻/s). The dark mean's estimate is about zero; the dark variance's (EMVA 1288 gives both) is 500 within
// three of its standard errors, and the sensor settings take it: the noise the histograms show. Where the camera
// keeps its dark signal (the mean grows by K·I·t), the two agree and the settings take the mean's.
TEST(CalibrateChannel, TheDarkCurrentFromTheVarianceSeesACameraThatSubtractsItsDarkOffset) {
  const double K = 0.35, I = 500;
  const calibrate::ChannelCalibration subtracted =
      calibrate::calibrate_channel("G", gaussian_series(K, 6, I, [](double) { return 100.0; }, 7));
  ASSERT_TRUE(subtracted.dark_current_from_variance_e_per_s);
  const calibrate::Estimate& v = *subtracted.dark_current_from_variance_e_per_s;
  std::cerr << fmt::format("on-chip subtraction: dark current from the mean {:.3g} ± {:.2g}, from the variance {:.4g} ± {:.2g} e⁻/s\n",
                           subtracted.dark_current_e_per_s.value, subtracted.dark_current_e_per_s.standard_error, v.value,
                           v.standard_error);
  EXPECT_NEAR(v.value, I, kSigmasPerItem * v.standard_error);
  EXPECT_LT(v.standard_error, 0.1 * I);  // a measurement
  EXPECT_NEAR(subtracted.dark_current_e_per_s.value, 0.0, 1e-6);
  EXPECT_NEAR(calibrate::simulated_dark_current(subtracted), v.value, 1e-12);
  const calibrate::ChannelCalibration kept =
      calibrate::calibrate_channel("G", gaussian_series(K, 6, I, [&](double t) { return 100.0 + K * I * t; }, 7));
  EXPECT_NEAR(kept.dark_current_e_per_s.value, I, kSigmasPerItem * kept.dark_current_e_per_s.standard_error);
  EXPECT_NEAR(calibrate::simulated_dark_current(kept), kept.dark_current_e_per_s.value, 1e-12);
}

// The spatial curves on an image of known make-up: white noise of σ = 1 plus a column pattern A·cos(2π·k₀·j/N) of
// A = 0.5 at k₀ = 20 of N = 256 columns (M = 128 rows). The horizontal spectrogram (along the rows) holds the pattern
// at k₀ as A·√N/2 = 4 over the noise (|DFT|²/N of a cosine), and σ elsewhere; the vertical one is σ everywhere; the
// horizontal profile is the pattern within the noise of a mean of M values; the histogram counts every pixel and the
// accumulated one starts at 100 %.
TEST(CalibrateChannel, TheSpatialCurvesShowAColumnPatternAboveWhiteNoise) {
  constexpr int M = 128, N = 256, k0 = 20;
  constexpr double A = 0.5;
  std::mt19937_64 random(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  calibrate::Plane image{N, M, std::vector<double>(M * N)};
  for (int i = 0; i < M; ++i)
    for (int j = 0; j < N; ++j) image.values[static_cast<std::size_t>(i * N + j)] = 100 + noise(random) + A * std::cos(2 * std::numbers::pi * k0 * j / N);
  const calibrate::SpatialCurves c = calibrate::spatial_curves(image, 1, 0.25);
  ASSERT_EQ(c.spectrum_horizontal.size(), N / 2u);
  ASSERT_EQ(c.spectrum_vertical.size(), M / 2u);
  // Each value averages M (or N) lines' power, an exponential of mean σ²: relative error 1/√lines in the power.
  const double peak = std::sqrt(A * A * N / 4 + 1);
  EXPECT_NEAR(c.spectrum_horizontal[k0 - 1], peak, kSigmasPerItem * peak / std::sqrt(double(M)));
  double rest = 0;
  for (std::size_t k = 0; k < c.spectrum_horizontal.size(); ++k)
    if (k != k0 - 1) rest += c.spectrum_horizontal[k] * c.spectrum_horizontal[k] / double(N / 2 - 1);
  EXPECT_NEAR(std::sqrt(rest), 1.0, kSigmasPerItem / std::sqrt(double(M) * (N / 2 - 1)));
  double vertical = 0;
  for (const double v : c.spectrum_vertical) vertical += v * v / double(M / 2);
  EXPECT_NEAR(std::sqrt(vertical), 1.0, kSigmasPerItem / std::sqrt(double(N) * (M / 2)));
  EXPECT_NEAR(c.temporal_floor, 0.5, 1e-12);
  for (int j = 0; j < N; ++j)
    EXPECT_NEAR(c.profile_horizontal[static_cast<std::size_t>(j)], A * std::cos(2 * std::numbers::pi * k0 * j / N), 4.5 / std::sqrt(double(M)));
  double counted = 0;
  for (const auto& [x, n] : c.histogram) counted += n;
  EXPECT_EQ(counted, M * N);
  EXPECT_EQ(c.accumulated.front().first, 0.0);
  EXPECT_NEAR(c.accumulated.front().second, 100.0, 1e-9);
}

// Where the dark frames' temporal variance is below 0.24 DN², quantisation hides the read noise: a camera with
// K = 0.08 DN/e⁻ and 2 e⁻ of read noise has σ²_y.dark = 0.0256 + 1/12 = 0.109 DN². EMVA 1288 then gives the upper
// limit √(0.24 − 1/12)/K = 4.95 e⁻ (the reference implementation's too; K as measured, within its errors of 0.08),
// marked as a limit and said in a note.
TEST(CalibrateChannel, DarkNoiseUnderTheQuantisationLimitIsAnUpperLimit) {
  const double K = 0.08;
  const calibrate::ChannelCalibration c = calibrate::calibrate_channel("G", gaussian_series(K, 2, 0, [](double) { return 100.0; }, 9));
  EXPECT_TRUE(c.dark_noise_upper_limit);
  EXPECT_NEAR(c.dark_noise_e.value, std::sqrt(0.24 - 1.0 / 12) / c.gain_dn_per_e.value, 1e-9);  // K as measured
  EXPECT_NEAR(c.dark_noise_e.value, std::sqrt(0.24 - 1.0 / 12) / K,
              kSigmasPerItem * c.dark_noise_e.value * c.gain_dn_per_e.standard_error / c.gain_dn_per_e.value);
  bool said = false;
  for (const std::string& n : c.notes) said = said || n.find("below 0.24 DN²") != std::string::npos;
  EXPECT_TRUE(said);
  // Above the limit it is a measurement.
  EXPECT_FALSE(calibrate::calibrate_channel("G", gaussian_series(0.35, 6, 0, [](double) { return 100.0; }, 9)).dark_noise_upper_limit);
}

}  // namespace
}  // namespace ct

namespace ct {
namespace {

// One channel of a frame as a 16-bit grey TIFF, the reference implementation's input.
void write_channel_tiff(const fs::path& exr, int channel, const fs::path& tiff) {
  const test::RgbLayer rgb = test::read_rgb(exr);
  std::vector<std::uint16_t> plane(static_cast<std::size_t>(rgb.width) * static_cast<std::size_t>(rgb.height));
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x)
      plane[static_cast<std::size_t>(y) * static_cast<std::size_t>(rgb.width) + static_cast<std::size_t>(x)] =
          static_cast<std::uint16_t>(std::lround(rgb.at(x, y, channel)));
  auto out = OIIO::ImageOutput::create(tiff.string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(tiff.string(), OIIO::ImageSpec(rgb.width, rgb.height, 1, OIIO::TypeDesc::UINT16)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT16, plane.data()));
  out->close();
}

// The same frames through the EMVA 1288 reference implementation (PyPI's emva1288 1.0.2, a test-only virtual
// environment set up by setup.sh): the green channel of a series with 8 flats and 8 darks at half saturation (its
// spatial set). Its gain, dark noise, saturation capacity, dark current, quantum efficiency, DSNU and PRNU (with
// their column and pixel parts) agree with calibrate's within 4 standard errors of calibrate's estimates. (Both take
// σ_d from the dark variance extrapolated to no exposure.)
TEST_F(Calibrate, AgreesWithTheEmva1288ReferenceImplementation) {
  const char* python = std::getenv("CHROMATRACE_EMVA1288_PYTHON");
  if (!python || !*python || !fs::exists(python))
    GTEST_SKIP() << "the EMVA 1288 reference implementation is not installed (./setup.sh puts it in build/emva1288-venv)";
  const Camera c{0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0.5, 0.004, 16};
  calibrate::CalibrationInput in = series(c, "reference");
  const calibrate::CalibrationInput spatial = series(c, "spatial", {0.5}, 8);
  in.flats.insert(in.flats.end(), spatial.flats.begin(), spatial.flats.end());
  in.darks.insert(in.darks.end(), spatial.darks.begin(), spatial.darks.end());
  const calibrate::Calibration cal = calibrate::calibrate(in);
  const calibrate::ChannelCalibration& g = cal.channels[1];

  // The descriptor file: per exposure (in ns) its flats ("b", with the photons per pixel) and its darks ("d").
  std::string descriptor = fmt::format("v 3.1\nn 16 {} {}\n", kSize, kSize);
  auto block = [&](const calibrate::CalibrationInput& set, double share, int per_step) {
    const double t = share, photons = *in.photons_per_s * t;
    for (const bool is_flat : {true, false}) {
      descriptor += is_flat ? fmt::format("b {:.0f} {:.6f}\n", t * 1e9, photons) : fmt::format("d {:.0f}\n", t * 1e9);
      const std::vector<fs::path>& frames = is_flat ? set.flats : set.darks;
      int written = 0;
      for (const fs::path& f : frames)
        if (f.filename().string().find(fmt::format("-{}-", share)) != std::string::npos && written < per_step) {
          const fs::path tiff = fs::path(f).replace_extension(".G.tif");
          write_channel_tiff(f, 1, tiff);
          descriptor += "i " + tiff.string() + "\n";
          ++written;
        }
    }
  };
  for (const double share : kExposureShares) block(in, share, 2);
  block(spatial, 0.5, 8);
  const fs::path file = dir_.file("descriptor.txt");
  { std::ofstream(file) << descriptor; }

  const auto r = test::run_program(python, {std::string(CHROMATRACE_SOURCE_DIR) + "/tests/calibrate/emva1288_reference.py", file.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json ref = Json::parse(r.out);
  auto agree = [&](const calibrate::Estimate& ours, double theirs, const std::string& what) {
    EXPECT_LE(std::abs(ours.value - theirs), kSigmasPerItem * ours.standard_error)
        << what << ": calibrate " << ours.value << " ± " << ours.standard_error << ", reference " << theirs;
  };
  agree(g.gain_dn_per_e, ref["K"].get<double>(), "system gain K");
  agree(g.dark_noise_e, ref["sigma_d"].get<double>(), "temporal dark noise");
  agree(g.saturation_capacity_e, ref["u_e_sat"].get<double>(), "saturation capacity");
  agree(g.dark_current_e_per_s, ref["dark_current_mean"].get<double>(), "dark current");
  agree(*g.dark_current_from_variance_e_per_s, ref["dark_current_var"].get<double>(), "dark current from the variance");
  agree(*g.quantum_efficiency, ref["QE"].get<double>(), "quantum efficiency");
  agree(g.dsnu_e.total, ref["DSNU"].get<double>(), "DSNU");
  agree(g.dsnu_e.column, ref["DSNU_col"].get<double>(), "DSNU, column part");
  agree(g.dsnu_e.pixel, ref["DSNU_pixel"].get<double>(), "DSNU, pixel part");
  agree(g.prnu.total, ref["PRNU"].get<double>(), "PRNU");
  agree(g.prnu.column, ref["PRNU_col"].get<double>(), "PRNU, column part");
  agree(g.prnu.pixel, ref["PRNU_pixel"].get<double>(), "PRNU, pixel part");
  ASSERT_TRUE(g.responsivity);
  agree(*g.responsivity, ref["R"].get<double>(), "responsivity R");
  // The datasheet's derived figures, each within 4 standard errors propagated from the estimates it derives from
  // (first order, relative).
  const calibrate::Sensitivity f = calibrate::sensitivity(g);
  auto rel = [](const calibrate::Estimate& e) { return e.standard_error / e.value; };
  auto close = [&](double ours, double theirs, double relative_se, const std::string& what) {
    EXPECT_LE(std::abs(ours - theirs), kSigmasPerItem * relative_se * std::abs(ours)) << what << ": calibrate " << ours << ", reference " << theirs;
  };
  close(f.inverse_gain, ref["inverse_K"].get<double>(), rel(g.gain_dn_per_e), "1/K");
  close(f.dark_sigma_dn, ref["sigma_y_dark"].get<double>(), std::hypot(rel(g.dark_noise_e), rel(g.gain_dn_per_e)), "σ_y.dark (DN)");
  const double threshold_rel = std::hypot(rel(g.dark_noise_e), rel(g.gain_dn_per_e));
  close(f.threshold_e, ref["u_e_min"].get<double>(), threshold_rel, "μe.min");
  ASSERT_TRUE(f.threshold_photons);
  close(*f.threshold_photons, ref["u_p_min"].get<double>(), std::hypot(threshold_rel, rel(*g.quantum_efficiency)), "μp.min");
  ASSERT_TRUE(g.saturation_photons);
  EXPECT_NEAR(*g.saturation_photons, ref["u_p_sat"].get<double>(), 1e-9 * *g.saturation_photons);  // the same step's photons
  close(f.snr_max, ref["SNR_max"].get<double>(), rel(g.saturation_capacity_e) / 2, "SNR_max");
  close(f.dynamic_range, ref["DR"].get<double>(), std::hypot(rel(g.saturation_capacity_e), threshold_rel), "dynamic range");
  close(f.dsnu_dn, ref["DSNU_DN"].get<double>(), std::hypot(rel(g.dsnu_e.total), rel(g.gain_dn_per_e)), "DSNU (DN)");
  // The linearity's extremes: the same weighted fit (the standard's 5–95 % range) on the same means, but at half
  // saturation the reference's temporal mean is its first pair's where calibrate's is all eight flats': they differ
  // by that pair's temporal noise, a relative standard error of √(σ²_y/(2n))/(μ_y − μ_y.dark) for n pixels.
  ASSERT_TRUE(g.linearity);
  const auto half = std::find_if(g.points.begin(), g.points.end(), [](const calibrate::TransferPoint& p) { return p.exposure_s == 0.5; });
  ASSERT_NE(half, g.points.end());
  const double pair_se = std::sqrt(half->variance_dn2 / (2.0 * kSize * kSize)) / (half->mean_dn - half->dark_mean_dn);
  EXPECT_NEAR(g.linearity->min, ref["LE_min"].get<double>(), kSigmasPerItem * pair_se);
  EXPECT_NEAR(g.linearity->max, ref["LE_max"].get<double>(), kSigmasPerItem * pair_se);
}

// Frames made by the EMVA 1288 package's own camera simulator (not chromatrace's), through calibrate and through the
// reference implementation (emva1288.process), for three cameras: the standard one, one with a 3 % compressive
// response, and one that subtracts its dark offset on chip (tests/calibrate/emva1288_simulated_camera.py). Every
// parameter agrees within 1 % of the reference's value or 3 of calibrate's standard errors (the reference gives none),
// the linearity error within 0.1 percentage points; and a fourth camera, whose dark variance lies under the 0.24 DN²
// quantisation limit, is reported as the upper limit the reference gives.
struct SimulatedByEmva1288 {
  calibrate::Calibration calibration;
  Json reference;
};
SimulatedByEmva1288 simulated_by_emva1288(const test::TempDir& dir, const std::string& camera) {
  const char* python = std::getenv("CHROMATRACE_EMVA1288_PYTHON");
  const fs::path out = dir.file(camera);
  const auto r = test::run_program(python, {std::string(CHROMATRACE_SOURCE_DIR) + "/tests/calibrate/emva1288_simulated_camera.py", out.string(), camera});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const Json made = Json::parse(r.out);
  // The simulator writes 32-bit integer TIFFs and says the exposure time in its descriptor: as a camera would give them,
  // 16-bit TIFFs with EXIF's ExposureTime.
  calibrate::CalibrationInput in;
  double brightest = 0;
  for (const Json& f : made["frames"]) {
    const fs::path source = f["file"].get<std::string>(), tiff = fs::path(source).replace_extension(".exif.tif");
    auto file = OIIO::ImageInput::open(source.string());
    EXPECT_TRUE(file) << source;
    const OIIO::ImageSpec& spec = file->spec();
    std::vector<std::int32_t> values(static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height));
    EXPECT_TRUE(file->read_image(0, 0, 0, 1, OIIO::TypeDesc::INT32, values.data()));
    std::vector<std::uint16_t> dn(values.begin(), values.end());
    OIIO::ImageSpec written(spec.width, spec.height, 1, OIIO::TypeDesc::UINT16);
    const double t = f["exposure_s"].get<double>();
    written.attribute("ExposureTime", static_cast<float>(t));
    auto output = OIIO::ImageOutput::create(tiff.string());
    EXPECT_TRUE(output->open(tiff.string(), written) && output->write_image(OIIO::TypeDesc::UINT16, dn.data()));
    output->close();
    if (f["kind"] == "b") {
      in.flats.push_back(tiff);
      // The photons per pixel and second, from the brightest step (the descriptor's photons are rounded to 0.001).
      if (f["photons"].get<double>() > brightest) brightest = f["photons"].get<double>(), in.photons_per_s = brightest / t;
    } else {
      in.darks.push_back(tiff);
    }
  }
  return {calibrate::calibrate(in), made["reference"]};
}

TEST(CalibrateAgainstEmva1288, FramesOfTheStandardsOwnSimulatorGiveTheReferencesResults) {
  const char* python = std::getenv("CHROMATRACE_EMVA1288_PYTHON");
  if (!python || !*python || !fs::exists(python))
    GTEST_SKIP() << "the EMVA 1288 reference implementation is not installed (./setup.sh puts it in build/emva1288-venv)";
  test::TempDir dir;
  for (const std::string camera : {"standard", "compressive", "subtracted"}) {
    SCOPED_TRACE(camera);
    const auto [cal, ref] = simulated_by_emva1288(dir, camera);
    ASSERT_EQ(cal.channels.size(), 1u);
    const calibrate::ChannelCalibration& c = cal.channels[0];
    auto agree = [&](const calibrate::Estimate& ours, const char* key, double scale = 1) {
      if (ref[key].is_null()) return;  // a part the reference cannot split off
      const double theirs = ref[key].get<double>() * scale;
      EXPECT_LE(std::abs(ours.value - theirs), std::max(0.01 * std::abs(theirs), 3 * ours.standard_error))
          << key << ": calibrate " << ours.value << " ± " << ours.standard_error << ", reference " << theirs;
    };
    agree(c.gain_dn_per_e, "K");
    ASSERT_TRUE(c.quantum_efficiency);
    agree(*c.quantum_efficiency, "QE");
    agree(c.dark_noise_e, "sigma_d");
    agree(c.dark_current_e_per_s, "dark_current_mean");
    ASSERT_TRUE(c.dark_current_from_variance_e_per_s);
    agree(*c.dark_current_from_variance_e_per_s, "dark_current_var");
    agree(c.dsnu_e.total, "DSNU");
    agree(c.dsnu_e.row, "DSNU_row");
    agree(c.dsnu_e.column, "DSNU_col");
    agree(c.dsnu_e.pixel, "DSNU_pixel");
    agree(c.prnu.total, "PRNU");
    agree(c.prnu.row, "PRNU_row");
    agree(c.prnu.column, "PRNU_col");
    agree(c.prnu.pixel, "PRNU_pixel");
    agree(c.saturation_capacity_e, "u_e_sat");
    const double reference_le = (ref["LE_max"].get<double>() - ref["LE_min"].get<double>()) / 2;
    EXPECT_NEAR(c.linearity_error, reference_le, 0.001) << "linearity error, calibrate against the reference";
    std::cerr << fmt::format("{}: K {:.4f} (reference {:.4f}), σ_d {:.3f} ({:.3f}), dark current {:.1f} and {:.1f} e⁻/s ({:.1f} and "
                             "{:.1f}), LE {:.2f} % ({:.2f} %)\n",
                             camera, c.gain_dn_per_e.value, ref["K"].get<double>(), c.dark_noise_e.value, ref["sigma_d"].get<double>(),
                             c.dark_current_e_per_s.value, c.dark_current_from_variance_e_per_s->value,
                             ref["dark_current_mean"].get<double>(), ref["dark_current_var"].get<double>(), 100 * c.linearity_error,
                             100 * reference_le);
  }
  // Under the quantisation limit: the upper limit, as the reference gives it (its σ_y.dark held at √0.24).
  const auto [cal, ref] = simulated_by_emva1288(dir, "quantised");
  const calibrate::ChannelCalibration& c = cal.channels[0];
  EXPECT_TRUE(c.dark_noise_upper_limit);
  EXPECT_NEAR(ref["sigma_y_dark"].get<double>(), std::sqrt(0.24), 1e-12);
  EXPECT_LE(std::abs(c.dark_noise_e.value - ref["sigma_d"].get<double>()),
            std::max(0.01 * ref["sigma_d"].get<double>(), 3 * c.dark_noise_e.value * c.gain_dn_per_e.standard_error / c.gain_dn_per_e.value));
}

}  // namespace
}  // namespace ct

namespace ct {
namespace {

// analyze --camera-config: the clusters are judged against the camera's own noise. On a capture of two flat patches
// by a camera with known settings, the noise σ along each principal axis of each patch's cluster is the model's,
// √(Σ u_c² var_c), var_c = K²(σ_read² + DSNU²) + 1/12 + K·μ_c + (PRNU·μ_c)² at the patch's mean (within 1 %: the
// noise bands' means lie near it); the noise measured on the image without the settings agrees with the model within
// 10 % (Immerkær's estimator on ~2 000 pixels per band). A file not in digital numbers is refused.
TEST_F(Calibrate, AnalyzeJudgesClustersAgainstTheCamerasCalibratedNoise) {
  const Camera c{0.6, 0.25, 100, 20000, 5, 100, 2, 0.01, 0, 0, 16};
  const double per_e = c.qe * photons_per_radiance_second() * 0.1;  // electrons per unit radiance in 0.1 s
  const fs::path scene = dir_.file("patches.exr"), settings = dir_.file("camera.json"), capture = dir_.file("capture.exr");
  test::write_radiance(scene, kBand, 128, 64, [&](int x, int, std::size_t) { return static_cast<float>((x < 64 ? 4000 : 12000) / per_e); });
  const Json patch = {{"optics", {{"f_number", kFNumber}, {"cos4", false}}},
                      {"exposure", {{"time_s", 0.1}}},
                      {"pixel", {{"pitch_um", kPitchUm}}},
                      {"spectral_response", {{"camera", flat_camera_.string()}, {"basis", "photon"}, {"peak_qe", c.qe}}},
                      {"noise", {{"enabled", true}, {"read_e", c.read}, {"dsnu_e", c.dsnu}, {"prnu", c.prnu}, {"seed", 5}, {"pattern_seed", 7}}},
                      {"full_well", {{"enabled", true}, {"electrons", c.full_well}}},
                      {"adc", {{"enabled", true}, {"gain_dn_per_e", c.gain}, {"black_level_dn", c.black}, {"bits", c.bits}}},
                      {"display", {{"enabled", false}}}};
  { std::ofstream(settings) << patch.dump(); }
  test::run_sensor(scene, capture, test::config_of(patch));

  auto analyse = [&](const std::string& out, bool calibrated) {
    std::vector<std::string> args = {"analyze", capture.string(), "-o", dir_.file(out).string(), "--rect", "4,4,56,56", "--rect", "68,4,56,56",
                                      "--no-plots", "--no-report", "-q"};
    if (calibrated) args.insert(args.end(), {"--camera-config", settings.string()});
    const auto r = test::run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return read_json(dir_.file(out) / "analysis.json");
  };
  const Json calibrated = analyse("calibrated", true), measured = analyse("measured", false);
  EXPECT_NE(calibrated["image_noise"]["estimator"].get<std::string>().find("the camera's calibration"), std::string::npos);
  int checked = 0;
  for (std::size_t i = 0; i < calibrated["regions"].size(); ++i) {
    const Json& region = calibrated["regions"][i];
    if (region["source"] != "rect") continue;
    const Json& shape = region["shape"];
    for (int k = 0; k < 3; ++k) {
      double variance = 0;
      for (int ch = 0; ch < 3; ++ch) {
        const double mu = shape["mean"][ch].get<double>(), u = shape["axes"][k][ch].get<double>();
        variance += u * u * (c.gain * c.gain * (c.read * c.read + c.dsnu * c.dsnu) + 1.0 / 12 + c.gain * mu + std::pow(c.prnu * mu, 2));
      }
      const double model = std::sqrt(variance), ours = shape["noise_sigma"][k].get<double>();
      EXPECT_NEAR(ours, model, 0.01 * model) << region["name"] << ", axis " << k;
      const double estimated = measured["regions"][i]["shape"]["noise_sigma"][k].get<double>();
      EXPECT_NEAR(estimated, model, 0.1 * model) << region["name"] << ", axis " << k << ": measured on the image";
      ++checked;
    }
  }
  EXPECT_EQ(checked, 6);

  // The simulator's picture (normalised values) is not in the camera's digital numbers.
  Json rendered = patch;
  rendered["rendering"] = {{"enabled", true}};
  const fs::path picture = dir_.file("picture.exr");
  test::run_sensor(scene, picture, test::config_of(rendered));
  const auto r = test::run_chromatrace({"analyze", picture.string(), "-o", dir_.file("refused").string(), "--camera-config", settings.string(), "-q"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("values are in normalised, but the camera's noise is in its digital numbers"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_.file("refused")));
}

}  // namespace
}  // namespace ct
