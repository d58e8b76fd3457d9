// SPDX-License-Identifier: Apache-2.0
// Spectra and bands: Planck's law, Wien's peak, band averages and resampling against analytic answers.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "core/band_plan.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/spectrum.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

TEST(Planck, IntegratesToStefanBoltzmann) {
  // ∫ B(λ, T) dλ = σ T⁴ / π, with σ = 2π⁵k⁴ / (15 h³ c²) (exact in SI since 2019).
  const double sigma = 2.0 * std::pow(std::numbers::pi, 5) * std::pow(kBoltzmann, 4) /
                       (15.0 * std::pow(kPlanck, 3) * kLightSpeed * kLightSpeed);
  EXPECT_NEAR(sigma, 5.670374419e-8, 1e-16);  // CODATA 2018 value
  const double lo = 50.0, hi = 200050.0;
  const Bands bands = Bands::uniform(lo, hi, 100.0);
  for (double t : {1000.0, 3200.0, 6500.0}) {
    const std::vector<double> avg = band_averages([t](double nm) { return planck(nm, t); }, bands);
    const double in_range = integrate_band_values(avg, bands);
    // The far-infrared tail beyond `hi`: with x = hc / λkT, ∫ B dλ = (2k⁴T⁴ / h³c²) ∫₀^xc x³ / (eˣ − 1) dx,
    // whose integrand is x² − x³/2 + x⁴/12 − x⁶/720 + … for small x (1.9e-5 of the total at 1000 K). The
    // tail below `lo` is below e^-280 of it.
    const double xc = kPlanck * kLightSpeed / (hi * 1e-9 * kBoltzmann * t);
    const double series = std::pow(xc, 3) / 3 - std::pow(xc, 4) / 8 + std::pow(xc, 5) / 60 - std::pow(xc, 7) / 5040;
    const double tail = 2 * std::pow(kBoltzmann * t, 4) / (std::pow(kPlanck, 3) * kLightSpeed * kLightSpeed) * series;
    EXPECT_NEAR((in_range + tail) / (sigma * std::pow(t, 4) / std::numbers::pi), 1.0, 1e-9) << "T = " << t;
  }
}

TEST(Planck, PeaksAtWiensWavelength) {
  for (double t : {2856.0, 5000.0, 6504.0}) {
    // Golden-section search for the maximum of B(λ).
    double a = 100.0, b = 3000.0;
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int i = 0; i < 200; ++i) {
      const double c = b - g * (b - a), d = a + g * (b - a);
      if (planck(c, t) > planck(d, t)) b = d;
      else a = c;
    }
    const double peak_nm = 0.5 * (a + b);
    EXPECT_NEAR(peak_nm, kWien / t * 1e9, 1e-6 * peak_nm) << "T = " << t;
  }
}

TEST(Planck, NormalisedBlackbodyPeaksAtOne) {
  const PiecewiseLinearSpectrum bb = blackbody(5000.0, 300.0, 830.0, 1.0, true);
  double peak = 0.0;
  for (double v : bb.values()) peak = std::max(peak, v);
  EXPECT_NEAR(peak, 1.0, 1e-9);
  EXPECT_THROW(blackbody(-5.0), InputError);
}

TEST(Spectrum, InterpolatesLinearlyAndExtrapolatesAsAsked) {
  const PiecewiseLinearSpectrum zero({400, 500, 600}, {1, 3, 2});
  EXPECT_DOUBLE_EQ(zero(450), 2.0);
  EXPECT_DOUBLE_EQ(zero(575), 2.25);
  EXPECT_DOUBLE_EQ(zero(399), 0.0);
  EXPECT_DOUBLE_EQ(zero(601), 0.0);
  const PiecewiseLinearSpectrum clamp({400, 500, 600}, {1, 3, 2}, Extrapolation::Clamp);
  EXPECT_DOUBLE_EQ(clamp(300), 1.0);
  EXPECT_DOUBLE_EQ(clamp(700), 2.0);
}

TEST(Spectrum, IntegralIsExactForPiecewiseLinear) {
  const PiecewiseLinearSpectrum s({400, 500, 600}, {1, 3, 2});
  // Trapezoids: 100·(1+3)/2 + 100·(3+2)/2 = 450.
  EXPECT_DOUBLE_EQ(s.integral(300, 700), 450.0);
  // Partial: from 450 (value 2) to 550 (value 2.5): 50·(2+3)/2 + 50·(3+2.5)/2 = 262.5.
  EXPECT_DOUBLE_EQ(s.integral(450, 550), 262.5);
  const PiecewiseLinearSpectrum c({400, 500, 600}, {1, 3, 2}, Extrapolation::Clamp);
  EXPECT_DOUBLE_EQ(c.integral(300, 700), 450.0 + 100.0 * 1 + 100.0 * 2);
}

TEST(Spectrum, RejectsNonIncreasingWavelengths) {
  try {
    PiecewiseLinearSpectrum({400, 500, 500}, {1, 2, 3}, Extrapolation::Zero, "spectra.paint.samples");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("spectra.paint.samples"), std::string::npos);
  }
  EXPECT_THROW(PiecewiseLinearSpectrum({400, 500}, {1, NAN}), InputError);
}

TEST(BandAverages, OfAConstantIsTheConstantForAnyBands) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> width(0.01, 60.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> edges{std::uniform_real_distribution<double>(200.0, 500.0)(rng)};
    for (int i = 0; i < 12; ++i) edges.push_back(edges.back() + width(rng));
    const Bands bands = Bands::from_edges(edges);
    const double k = std::uniform_real_distribution<double>(-3.0, 3.0)(rng);
    for (double v : band_averages(PiecewiseLinearSpectrum::constant(k), bands)) EXPECT_NEAR(v, k, 1e-12 * std::abs(k));
    for (double v : band_averages([k](double) { return k; }, bands)) EXPECT_NEAR(v, k, 1e-12 * std::abs(k));
  }
}

TEST(BandAverages, AreExactIntegralsOfTheLinearSegments) {
  const PiecewiseLinearSpectrum ramp({400, 700}, {0.0, 3.0});  // value = (λ − 400) / 100
  const Bands bands = Bands::parse("400:700:30");
  const std::vector<double> avg = band_averages(ramp, bands);
  for (std::size_t i = 0; i < bands.size(); ++i) EXPECT_NEAR(avg[i], (bands.centre(i) - 400.0) / 100.0, 1e-12);
}

TEST(Bands, ParseUniformAndCentres) {
  const Bands b = Bands::parse("380:780:10");
  EXPECT_EQ(b.size(), 40u);
  EXPECT_DOUBLE_EQ(b.lo(0), 380.0);
  EXPECT_DOUBLE_EQ(b.hi(39), 780.0);
  EXPECT_DOUBLE_EQ(b.centre(17), 555.0);
  EXPECT_THROW(Bands::parse("380:785:10"), InputError);  // not a whole number of bands
  EXPECT_THROW(Bands::parse("380-780-10"), InputError);
  EXPECT_THROW(Bands::parse("780:380:10"), InputError);
  EXPECT_THROW(Bands::from_edges({400, 400}), InputError);

  // Centres 5 nm apart: edges halfway between, outer bands symmetric about their centres.
  const Bands c = Bands::from_centres({380, 385, 390});
  EXPECT_EQ(c.edges(), (std::vector<double>{377.5, 382.5, 387.5, 392.5}));
  EXPECT_THROW(Bands::from_centres({380, 380}), InputError);
}

TEST(Resample, PreservesIntegralsOfSmoothSpectra) {
  // A Gaussian of width σ tabulated finely, resampled to a grid of spacing h. The box averages followed by
  // linear interpolation integrate to the original up to the composite-rule error, which for a function
  // whose derivative vanishes at both ends is (b − a)·h⁴/720·max|f⁗| (the h² terms cancel at the ends).
  const double sigma = 40.0, mu = 550.0;
  auto gauss = [&](double nm) { return std::exp(-0.5 * std::pow((nm - mu) / sigma, 2)); };
  std::vector<double> fine_l, fine_v;
  for (double nm = 300.0; nm <= 800.0; nm += 0.25) {
    fine_l.push_back(nm);
    fine_v.push_back(gauss(nm));
  }
  const PiecewiseLinearSpectrum fine(fine_l, fine_v);
  for (double h : {5.0, 10.0, 20.0}) {
    std::vector<double> grid;
    for (double nm = 300.0; nm <= 800.0 + 1e-9; nm += h) grid.push_back(nm);
    const PiecewiseLinearSpectrum coarse = resample(fine, grid);
    const double max_f4 = 3.0 / std::pow(sigma, 4);  // max |f⁗| of a unit Gaussian is 3/σ⁴
    const double bound = 500.0 * std::pow(h, 4) / 720.0 * max_f4 + 1e-9;
    EXPECT_NEAR(coarse.integral(300, 800), fine.integral(300, 800), bound) << "h = " << h;
  }
}

TEST(IntegralOfProduct, IsExactForLinearFactors) {
  const PiecewiseLinearSpectrum f({0, 10}, {1, 3});   // 1 + 0.2x
  const PiecewiseLinearSpectrum g({0, 10}, {2, -1});  // 2 − 0.3x
  const PiecewiseLinearSpectrum h({0, 10}, {0, 5});   // 0.5x
  // (1 + 0.2x)(2 − 0.3x) = 2 + 0.1x − 0.06x², whose integral over [0, 10] is 20 + 5 − 20 = 5.
  EXPECT_NEAR(integral_of_product(f, g, 0, 10), 5.0, 1e-12);
  // ∫ (2 + 0.1x − 0.06x²)(0.5x) = ∫ x + 0.05x² − 0.03x³ = 50 + 16.6667 − 75 = −8.3333.
  EXPECT_NEAR(integral_of_product(f, g, h, 0, 10), 50.0 + 50.0 / 3.0 - 75.0, 1e-12);
}


// A reconstruction that gives each 1 nm fine band the value of the band it lies in is the step function itself: the
// weights of any curve through it are the step function's, to rounding.
TEST(BandReconstruction, TheStepFunctionAsAMatrixGivesTheStepWeights) {
  const Bands bands = Bands::from_edges({380, 430, 520, 600, 780});
  BandReconstruction r{380, 1, 400, {}};
  for (std::size_t j = 0; j < r.fine; ++j)
    for (std::size_t i = 0; i < bands.size(); ++i) r.matrix.push_back(bands.lo(i) <= 380.0 + j && 380.0 + j < bands.hi(i));
  const Bands with = bands.with_reconstruction(r);
  ASSERT_NE(with.reconstruction(), nullptr);
  EXPECT_FALSE(with == bands);
  EXPECT_EQ(with.without_reconstruction(), bands);
  const auto step = xyz_band_weights(bands), rec = xyz_band_weights(with);
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < bands.size(); ++i) EXPECT_NEAR(rec[c][i], step[c][i], 1e-12 * std::abs(step[c][i]) + 1e-15);
}

// Band values through a reconstruction are its fine spectrum: the weights integrate the curve against the fine
// values Σ_i R_ji·b_i. With a curve that is 1 on one fine band and 0 elsewhere the weights are that band's row.
TEST(BandReconstruction, WeightsOfAFineBandsIndicatorAreItsRow) {
  const Bands bands = Bands::from_edges({400, 500, 600, 700});
  BandReconstruction r{400, 10, 30, {}};
  for (std::size_t k = 0; k < r.fine * bands.size(); ++k) r.matrix.push_back(std::sin(0.7 * static_cast<double>(k)));
  const Bands with = bands.with_reconstruction(r);
  const std::size_t j = 17;  // [570, 580)
  const auto w = band_weights(with, [&](double lo, double hi) { return lo >= 570 - 1e-9 && hi <= 580 + 1e-9 ? hi - lo : 0.0; });
  const std::vector<double>& held = with.reconstruction()->matrix;  // at float precision
  for (std::size_t i = 0; i < bands.size(); ++i) EXPECT_NEAR(w[i], 10 * held[j * bands.size() + i], 1e-12);
}

TEST(BandReconstruction, BadMatricesNameTheField) {
  const Bands bands = Bands::from_edges({400, 500, 600});
  auto message = [&](BandReconstruction r) {
    try {
      bands.with_reconstruction(std::move(r), "plan.json: reconstruction");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message({400, 1, 3, {1, 2, 3, 4, 5}}).find("needs 3 fine bands × 2 bands = 6"), std::string::npos);
  EXPECT_NE(message({400, 1, 1, {1, std::nan("")}}).find("plan.json: reconstruction: matrix entry [0][1] is not finite"),
            std::string::npos);
  EXPECT_NE(message({400, 0, 1, {1, 2}}).find("positive start and step"), std::string::npos);
  EXPECT_NE(message({400, 1, 1, {1e300, 2}}).find("matrix entry [0][0] is not finite"), std::string::npos);  // beyond a float
}

// The band-plan file carries the reconstruction and reads back the same; a row of the wrong length is named.
TEST(BandReconstruction, BandPlanFileRoundTripsAndNamesABadRow) {
  const fs::path dir = fs::temp_directory_path() / ("ct-band-plan-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Bands bands = Bands::from_edges({400, 550, 700}).with_reconstruction({400, 50, 6, {1, 0, 1, 0, 1, 0, 0.5, 0.5, 0, 1, 0, 1}});
  {
    std::ofstream(dir / "plan.json") << band_plan_document(bands).dump(1);
  }
  EXPECT_EQ(read_band_plan(dir / "plan.json"), bands);
  Json doc = band_plan_document(bands);
  doc["reconstruction"]["matrix"][2] = Json::array({0.5});
  {
    std::ofstream(dir / "bad.json") << doc.dump(1);
  }
  try {
    read_band_plan(dir / "bad.json");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reconstruction.matrix[2]: 1 entries, needs one per band (2)"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ct
