// SPDX-License-Identifier: Apache-2.0
#include "tests/analyzer/statement_audit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <regex>
#include <set>

#include <Eigen/Dense>
#include <fmt/format.h>

namespace ct::test {
namespace {

using nlohmann::json;
using V3 = Eigen::Vector3d;
constexpr double kDegrees = 180.0 / std::numbers::pi;

V3 v3(const json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }
double degrees_between(const V3& a, const V3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * kDegrees;
}
bool positive_octant(const V3& v) { return v.minCoeff() >= 0; }
// Directions are quoted with their components summing to at least 0 (towards brighter).
V3 brighter(const V3& v) { return v.sum() < 0 ? V3(-v) : v; }

// Every kind of statement there is, with the claims its words make: the claims it must carry. A kind not listed
// is itself a failure, so that no new kind of sentence goes unaudited.
const std::map<std::string, std::set<std::string>>& required_claims() {
  static const std::map<std::string, std::set<std::string>> required = {
      {"body_colour", {"reaches_black"}},
      {"no_body_colour", {"misses_black"}},
      {"no_body_colour.not_a_colour", {"reaches_black_not_a_colour"}},
      {"body_reach_unknown", {}},
      {"mean_colour", {}},
      {"highlight.no_light", {}},
      {"highlight.light_unknown", {}},
      {"plane.light_unknown", {}},
      {"clipping.faces", {}},
      {"clipping.few", {}},
      {"separate_areas", {}},
      {"curve", {}},
      {"stored_class", {}},
      {"light_paths", {}},
      {"bend", {}},
      {"process.none", {}},
      {"process.clipped", {}},
      {"process.mixed", {}},
      {"process.line", {}},
      {"process.thickened_line", {}},
      {"process.fork", {}},
      {"process.gamma", {}},
      {"process.curved", {}},
      {"process.thickened", {}},
      {"process.volume", {}},
      {"process.superposed", {}},
      {"process.planar", {}},
      {"process.highlight_unknown", {}},
      {"process.matte_below_clipping", {"reaches_black", "top_clipped"}},
      {"highlight.light", {"light_highlight"}},
      {"highlight.not_light", {"not_light_highlight"}},
      {"highlight.not_a_colour", {"not_light_highlight"}},
      {"plane.model", {"on_model_plane"}},
      {"plane.off_model", {"off_model_plane"}},
      {"clipping.none", {"nothing_clipped"}},
      {"at_black.dim", {"at_black_dim"}},
      {"at_black.bright", {"at_black_bright"}},
      {"thickness.thick", {"thick"}},
      {"thickness.flat", {"flat"}},
      {"gamma.measured", {"gamma_measured"}},
      {"gamma.not_measured", {"gamma_not_measured"}},
      {"light_coloured", {"light_coloured"}},
      {"process.point", {"within_noise"}},
      {"process.matte_alone", {"reaches_black", "no_top_clipping"}},
      {"process.matte", {"reaches_black", "top_clipped"}},
      {"process.offset_line", {"misses_black"}},
      {"process.light_highlight", {"light_highlight"}},
      {"process.highlight", {"not_light_highlight"}},
  };
  return required;
}

// Recomputes a region's premises.
class RegionAudit {
 public:
  RegionAudit(const json& analysis, const json& region, std::vector<float> stored)
      : analysis_(analysis), region_(region), stored_(std::move(stored)), criteria_(analysis["criteria"]) {
    const json& linear = region["linear_light"];
    const json& whole = linear.is_object() ? linear : region["shape"];
    read_ = &whole;
    if (whole["class"] == "clipped" && whole.contains("unclipped") && whole["unclipped"]["samples"].get<std::size_t>() > 0)
      read_ = &whole["unclipped"];
    min_angle_ = criteria_["min_line_angle_deg"].get<double>();
    noise_factor_ = criteria_["noise_factor"].get<double>();
    const json& light = analysis["illuminant"]["estimate"];
    light_ = v3(light["rgb"]);
    light_reliable_ = light["reliable"].get<bool>() && light_.norm() > 0;
    light_se_ = light["uncertainty_deg"].is_number() ? light["uncertainty_deg"].get<double>() : 0.0;
    count_limits();
  }

  // nullopt: the claim is unknown to the audit (itself a failure).
  std::optional<bool> holds(const std::string& claim) const {
    if (claim == "reaches_black") return body_reaches();
    if (claim == "misses_black") return body_misses();
    if (claim == "reaches_black_not_a_colour") {
      const auto r = reach();
      return r && r->measured && r->angle <= r->allowed && !body_direction_is_colour();
    }
    if (claim == "light_highlight") return branch_is_light();
    if (claim == "not_light_highlight") return branch_is_not_light();
    if (claim == "within_noise") return within_noise();
    if (claim == "no_top_clipping") return total(at_top_) == 0;
    if (claim == "top_clipped") return total(at_top_) > 0;
    if (claim == "nothing_clipped") return total(at_top_) == 0 && total(at_black_) == 0;
    if (claim == "at_black_dim") return at_black_dim() == std::optional<bool>(true);
    if (claim == "at_black_bright") return at_black_dim() == std::optional<bool>(false);
    if (claim == "on_model_plane") return on_model_plane() == std::optional<bool>(true);
    if (claim == "off_model_plane") return on_model_plane() == std::optional<bool>(false);
    if (claim == "thick") return thickness() && *thickness() > noise_factor_;
    if (claim == "flat") return thickness() && *thickness() <= noise_factor_;
    if (claim == "gamma_measured") return gamma_measured() == std::optional<bool>(true);
    if (claim == "gamma_not_measured") return gamma_measured() == std::optional<bool>(false);
    if (claim == "light_coloured") return light_coloured();
    return std::nullopt;
  }

  // The body line: a two-line fit's for an L or skewed-T, else the robust body line, else the line.
  const json* body_line() const {
    const std::string c = (*read_)["class"];
    if ((c == "L" || c == "skewed-T") && read_->value("two_lines", json()).is_object()) return &(*read_)["two_lines"]["body"];
    if (read_->value("body_line", json()).is_object()) return &(*read_)["body_line"];
    if (read_->value("line", json()).is_object()) return &(*read_)["line"];
    return nullptr;
  }

  // The line's angle from black seen from its brightest end, and the angle within which it reaches black:
  // the larger of min_line_angle_deg and twice the standard error of its closest point to black.
  struct Reach {
    double angle = 0, allowed = 0;
    bool measured = false;  // its uncertainty within min_line_angle_deg
  };
  std::optional<Reach> reach() const {
    const json* line = body_line();
    if (!line) return std::nullopt;
    const V3 p = v3((*line)["point"]), d = v3((*line)["direction"]).normalized();
    const double t0 = (*line)["t_min"], t1 = (*line)["t_max"], rms = (*line)["rms"];
    const double n = std::max(1.0, (*line)["inliers"].get<double>());
    // The closest point to black is p − (p·d) d; the brightest end lies (p·d + t1) along d from it.
    const V3 closest = p - p.dot(d) * d;
    const V3 brightest = p + t1 * d;
    Reach r;
    r.angle = std::atan2(closest.norm(), brightest.dot(d)) * kDegrees;
    // A centroid known to rms/√n, and a tilt of rms/(√n·σ_t) (σ_t² = (t1 − t0)²/12 for samples spread evenly along
    // it) carried over the distance p·d from the centroid to the closest point.
    const double spread = (t1 - t0) / std::sqrt(12.0);
    const double se = spread > 0 ? rms / std::sqrt(n) * std::hypot(1.0, p.dot(d) / spread) : std::numeric_limits<double>::infinity();
    const double uncertainty = std::atan2(se, brightest.norm()) * kDegrees;
    r.allowed = std::max(min_angle_, 2 * uncertainty);
    r.measured = std::isfinite(se) && uncertainty <= min_angle_;
    return r;
  }
  bool body_direction_is_colour() const {
    const json* line = body_line();
    return line && positive_octant(brighter(v3((*line)["direction"])));
  }
  bool body_reaches() const {
    const auto r = reach();
    return r && r->measured && r->angle <= r->allowed && body_direction_is_colour();
  }
  bool body_misses() const {
    const auto r = reach();
    return r && r->measured && r->angle > r->allowed;
  }

  std::optional<V3> branch() const {
    if (read_->value("highlight_branch", json()).is_object()) return brighter(v3((*read_)["highlight_branch"]["direction"]));
    const std::string c = (*read_)["class"];
    if ((c == "L" || c == "skewed-T" || c == "P") && read_->value("two_lines", json()).is_object())
      return brighter(v3((*read_)["two_lines"]["highlight"]["direction"]));
    return std::nullopt;
  }
  // Twice the branch's and the light's standard errors combined, at least min_line_angle_deg. A highlight line without
  // a regression is known to rms / (√n · σ_t) radians, σ_t² = (t_max − t_min)²/12.
  double branch_allowed() const {
    double se = 90;
    if (read_->value("highlight_branch", json()).is_object()) {
      se = (*read_)["highlight_branch"]["uncertainty_deg"].get<double>();
    } else {
      const json& h = (*read_)["two_lines"]["highlight"];
      const double spread = (h["t_max"].get<double>() - h["t_min"].get<double>()) / std::sqrt(12.0);
      if (spread > 0) se = std::atan(h["rms"].get<double>() / (std::sqrt(std::max(1.0, h["inliers"].get<double>())) * spread)) * kDegrees;
    }
    return std::max(min_angle_, 2 * std::hypot(se, light_se_));
  }
  bool branch_is_light() const {
    const auto b = branch();
    return b && light_reliable_ && positive_octant(*b) && degrees_between(*b, light_) <= branch_allowed();
  }
  bool branch_is_not_light() const {
    const auto b = branch();
    if (!b) return false;
    if (!positive_octant(*b)) return true;
    return light_reliable_ && degrees_between(*b, light_) > branch_allowed();
  }

  bool within_noise() const {
    if (!read_->value("sigma", json()).is_array() || !read_->value("noise_sigma", json()).is_array()) return false;
    const V3 sigma = v3((*read_)["sigma"]), noise = v3((*read_)["noise_sigma"]);
    for (int k = 0; k < 3; ++k)
      if (sigma[k] > noise_factor_ * noise[k]) return false;
    return true;
  }

  std::optional<double> thickness() const {
    if (!read_->value("plane", json()).is_object() || read_->value("significant_axes", 0) < 2) return std::nullopt;
    const double noise = v3((*read_)["noise_sigma"])[2];
    if (!(noise > 0)) return std::nullopt;  // a noise-free image: nothing to be thick against
    return v3((*read_)["sigma"])[2] / noise;
  }

  std::optional<bool> on_model_plane() const {
    // Only a reliable light can say whether the plane holds it.
    if (!read_->value("dichromatic_plane", json()).is_object() || !light_reliable_) return std::nullopt;
    const V3 normal = v3((*read_)["dichromatic_plane"]["normal"]).normalized();
    const double off = std::asin(std::min(1.0, std::abs(normal.dot(light_.normalized())))) * kDegrees;
    const auto t = thickness();
    // … and the cluster lies within its noise of the plane through black (rms distance over the noise across it).
    if (!t) return std::nullopt;
    const double off_black = (*read_)["dichromatic_plane"]["rms"].get<double>() / v3((*read_)["noise_sigma"])[2];
    return off <= std::max(min_angle_, 2 * light_se_) && *t <= noise_factor_ && off_black <= noise_factor_;
  }

  std::optional<bool> gamma_measured() const {
    const json& g = region_["gamma_against_declared"];
    if (!g.is_object()) return std::nullopt;
    const double fitted = g["fitted_gamma"], se = g["gamma_se"];
    // The search covers [0.2, 5]; within 1 % of an end the fit found no minimum inside it.
    const bool at_end = fitted <= 0.2 * 1.01 || fitted >= 5.0 / 1.01;
    return !at_end && se > 0 && fitted - 2 * se > 0.2 && fitted + 2 * se < 5.0;
  }

  bool light_coloured() const {
    const json& in = region_["interpretation"];
    const json& colour = in["body_colour"].is_array() ? in["body_colour"] : in["mean_colour"];
    if (!colour.is_array()) return false;
    const json& il = analysis_["illuminant"];
    std::optional<std::pair<V3, double>> sharp;
    for (const char* key : {"dichromatic_planes", "highlight_lines"}) {
      const json& e = il[key];
      if (!e.is_object() || !e["reliable"].get<bool>() || !e["uncertainty_deg"].is_number()) continue;
      const double se = e["uncertainty_deg"];
      if (se <= min_angle_ && (!sharp || se < sharp->second)) sharp = std::pair{v3(e["rgb"]), se};
    }
    return sharp && degrees_between(v3(colour), sharp->first) <= std::max(min_angle_, 2 * sharp->second);
  }

  // Of the pixels at black in the channel with most of them: is their brightest channel's median under a quarter of
  // the top of the range?
  std::optional<bool> at_black_dim() const {
    int c = 0;
    for (int k = 1; k < 3; ++k)
      if (at_black_[static_cast<std::size_t>(k)] > at_black_[static_cast<std::size_t>(c)]) c = k;
    if (at_black_[static_cast<std::size_t>(c)] == 0) return std::nullopt;
    std::vector<double> brightest;
    for (std::size_t i = 0; i + 2 < stored_.size(); i += 3)
      if (at_black(i, c)) brightest.push_back(std::max({stored_[i], stored_[i + 1], stored_[i + 2]}));
    // numpy's "lower" median: the element of rank ⌊(n − 1)/2⌋.
    std::sort(brightest.begin(), brightest.end());
    const double median = brightest[(brightest.size() - 1) / 2];
    double top = 0;
    for (const double level : high_) if (std::isfinite(level)) top = std::max(top, level);
    if (!(top > 0)) for (const float v : stored_) if (std::isfinite(v)) top = std::max(top, double(v));
    return median < 0.25 * top;
  }

  const std::array<std::size_t, 3>& at_top() const { return at_top_; }
  const std::array<std::size_t, 3>& at_black_counts() const { return at_black_; }

 private:
  bool at_black(std::size_t i, int c) const {
    const auto k = static_cast<std::size_t>(c);
    if (!(stored_[i + k] <= low_[k])) return false;
    for (std::size_t o = 0; o < 3; ++o)
      if (stored_[i + o] > low_[o]) return true;
    return false;
  }
  void count_limits() {
    for (std::size_t c = 0; c < 3; ++c) {
      const json& h = analysis_["clipping_levels"][c];
      high_[c] = h.is_number() ? h.get<double>() : std::numeric_limits<double>::infinity();
      low_[c] = analysis_["clipping_low_levels"][c].get<double>();
    }
    // Each channel's largest value stands for a limit the file does not state: a few pixels there are no clipping.
    const bool known = analysis_.value("clipping_levels_source", "") != "channel maxima";
    for (std::size_t i = 0; i + 2 < stored_.size(); i += 3)
      for (int c = 0; c < 3; ++c) {
        const auto k = static_cast<std::size_t>(c);
        if (known && stored_[i + k] >= high_[k]) ++at_top_[k];
        if (at_black(i, c)) ++at_black_[k];
      }
  }
  static std::size_t total(const std::array<std::size_t, 3>& a) { return a[0] + a[1] + a[2]; }

  const json& analysis_;
  const json& region_;
  std::vector<float> stored_;
  const json& criteria_;
  const json* read_ = nullptr;
  double min_angle_ = 3, noise_factor_ = 3;
  V3 light_ = V3::Zero();
  bool light_reliable_ = false;
  double light_se_ = 0;
  std::array<double, 3> high_{}, low_{};
  std::array<std::size_t, 3> at_top_{}, at_black_{};
};

// Every "(a, b, c)" of numbers in a text.
std::vector<V3> quoted_triples(const std::string& text) {
  static const std::regex triple(R"(\((-?[0-9.]+(?:e[-+]?[0-9]+)?), (-?[0-9.]+(?:e[-+]?[0-9]+)?), (-?[0-9.]+(?:e[-+]?[0-9]+)?)\))");
  std::vector<V3> out;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), triple); it != std::sregex_iterator(); ++it)
    out.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]));
  return out;
}

bool has_statement(const json& statements, const std::string& kind) {
  return std::any_of(statements.begin(), statements.end(), [&](const json& s) { return s["kind"] == kind; });
}

}  // namespace

std::vector<std::string> audit_statements(const json& analysis, const RegionPixels& pixels) {
  std::vector<std::string> wrong;
  for (std::size_t r = 0; r < analysis["regions"].size(); ++r) {
    const json& region = analysis["regions"][r];
    const json& in = region["interpretation"];
    const std::string name = region["name"];
    auto fail = [&](const std::string& what) { wrong.push_back(name + ": " + what); };
    if (!in.is_object()) {
      fail("no interpretation");
      continue;
    }
    const RegionAudit audit(analysis, region, pixels(r));
    const std::string text = in["text"];
    auto check_claims = [&](const std::string& kind, const std::string& sentence, const json& claims) {
      std::set<std::string> made;
      for (const json& c : claims) {
        made.insert(c.get<std::string>());
        const std::optional<bool> ok = audit.holds(c.get<std::string>());
        if (!ok) fail(fmt::format("claim '{}' is unknown to the audit: \"{}\"", c.get<std::string>(), sentence));
        else if (!*ok) fail(fmt::format("premise '{}' is false for \"{}\"", c.get<std::string>(), sentence));
      }
      const auto& required = required_claims();
      const auto it = required.find(kind);
      if (it == required.end()) {
        fail(fmt::format("a statement of a kind the audit does not know, '{}': \"{}\"", kind, sentence));
        return;
      }
      for (const std::string& c : it->second)
        if (!made.contains(c)) fail(fmt::format("a {} statement without its premise '{}': \"{}\"", kind, c, sentence));
    };
    // A clipped cluster's process describes its pixels off the faces too: their kind's claims are required.
    const bool rest = in.value("process_rest_kind", json()).is_string();
    check_claims(rest ? in["process_rest_kind"].get<std::string>() : in["process_kind"].get<std::string>(), in["process"], in["process_claims"]);
    for (const json& s : in["statements"]) {
      check_claims(s["kind"], s["text"], s["claims"]);
      if (text.find(s["text"].get<std::string>()) == std::string::npos) fail("a statement missing from the paragraph: " + s["text"].get<std::string>());
    }
    // No colour or direction quoted with a negative component.
    for (const V3& v : quoted_triples(text))
      if (!positive_octant(v)) fail(fmt::format("quotes ({}, {}, {}), which has a negative component", v[0], v[1], v[2]));
    // Sentences that must be there.
    const json& statements = in["statements"];
    const json& read = region["linear_light"].is_object() ? region["linear_light"] : region["shape"];
    if (read["samples"].get<std::size_t>() == 0) continue;
    if (audit.body_reaches() && !has_statement(statements, "body_colour")) fail("its line reaches black, but no body colour is quoted");
    if (!audit.body_reaches() && has_statement(statements, "body_colour")) fail("a body colour is quoted of a line that does not reach black");
    if (audit.body_misses() && !has_statement(statements, "no_body_colour")) fail("its line misses black, and no sentence says so");
    for (int c = 0; c < 3; ++c) {
      const char channel = "RGB"[c];
      const auto k = static_cast<std::size_t>(c);
      if (audit.at_top()[k] > 0 && text.find(fmt::format("{} high at", channel)) == std::string::npos &&
          text.find(fmt::format("with {} at its top", channel)) == std::string::npos)
        fail(fmt::format("{} pixels have {} at its top level, and no sentence names them", audit.at_top()[k], channel));
      if (audit.at_black_counts()[k] > 0 && text.find(fmt::format("{} low at", channel)) == std::string::npos &&
          text.find(fmt::format("with {} at black", channel)) == std::string::npos)
        fail(fmt::format("{} pixels have {} at black, and no sentence names them", audit.at_black_counts()[k], channel));
    }
    if (const auto m = audit.gamma_measured()) {
      if (*m != has_statement(statements, "gamma.measured")) fail(*m ? "γ was measured, and not quoted" : "γ is quoted, and was not measured");
    }
  }
  return wrong;
}

}  // namespace ct::test
