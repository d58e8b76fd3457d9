// SPDX-License-Identifier: Apache-2.0
#pragma once
// Tick values and their labels for the axes of every plot (analyzer, series, study, calibrate): one rule for a
// nice step, one for the labels of linear axes and one for logarithmic axes.

#include <string>
#include <vector>

namespace ct::plot {

// The step for about `intervals` intervals over `span`: span / intervals rounded to 1, 2, 5 or 10 × a power of
// ten, by Heckbert's nice numbers (Graphics Gems, 1990): a mantissa below 1.5 gives 1, below 3 gives 2, below 7
// gives 5, else 10. So [0, 1] in 5 intervals has the step 0.2, [0, 255] 50, [0, 65535] 10000. 1 for a span that
// is not positive and finite.
double nice_step(double span, int intervals);

// The multiples of `step` inside [lo, hi] (ends included up to a rounding slack of 10⁻⁹ of the range), ascending;
// −0 written as 0.
std::vector<double> multiples_in(double lo, double hi, double step);

// The ticks of a linear axis from lo to hi: its step, nice_step(hi − lo, intervals), and the step's multiples
// inside the range. No values for an empty or non-finite range (or intervals < 1).
struct Ticks {
  double step = 1;
  std::vector<double> values;
  std::string label(double value) const;  // tick_label(value, step)
};
Ticks linear_ticks(double lo, double hi, int intervals = 5);

// A range widened outwards to whole steps of nice_step(hi − lo, intervals), for an axis or a cube that should
// begin and end on a tick (a value within 10⁻⁶ of a step of a multiple counts as on it). A range that is not
// positive is taken as [lo, lo + 1]. The result spans at least one step.
struct NiceRange {
  double lo = 0, hi = 1, step = 0.2;
};
NiceRange nice_range(double lo, double hi, int intervals);

// A tick value of a linear axis with as many decimals as its step needs (0.2 → one, 250 → none), a value
// within 10⁻⁶ of a step of zero written as 0: tick_label(0.30000000000000004, 0.1) is "0.3".
std::string tick_label(double value, double step);

// The ticks of a logarithmic axis over [lo, hi] (0 < lo < hi): the powers of ten inside, and 2 and 5 times them
// when the range spans fewer than three decades; when fewer than two fall inside, the powers of ten just
// outside both ends. std::invalid_argument for any other range (a non-positive lo would never end).
std::vector<double> log_ticks(double lo, double hi);

// A tick value of a logarithmic axis: as a plain number from 0.01 to 1000 ("0.05", "200"), else in powers of
// ten with a caret before the exponent ("10^5", "2x10^-3"); plot/text.h's put_text draws the exponent raised,
// superscript_exponent writes it with superscript digits for SVG and HTML.
std::string log_tick_label(double value);

// "10^5" → "10⁵", "2x10^-3" → "2×10⁻³"; text without a caret unchanged.
std::string superscript_exponent(const std::string& label);

}  // namespace ct::plot
