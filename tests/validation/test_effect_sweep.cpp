// Every library effect's prediction (its hypothesis through the frequency-dependent eq. (3),
// validation::predict_run_g) against the ODE (its truth hook through the virtual shaker),
// swept over 10 Hz - 2 kHz (log-spaced) and over its parameter's range: the values blind
// hides (the extremes of 400 draws of Effect::draw, each sign drawn) and, for a parameter the
// fit explores on a grid, the grid's ends (the fit must be right where it looks). A test at
// two frequencies and one value cannot see a prediction that fails on part of the band (a
// mode above the drive predicted as no response at all; issue 15). The run: 4 g along IA+PA
// (every effect acts), the static a_IA +0.71 g, the paper-like instrument. Compared: the
// change each makes (with the effect less without), so the first-order model's own error
// without any effect (< 0.01 ug here) is not charged to the effect; the prediction as the
// diagnosis makes it (from the statically identified coefficients, what the static test took
// up given back).
//
// Tolerance, per effect: |predicted - ODE| <= rel |ODE change| + floor. The floor, 0.02 ug,
// is 1/15 of a campaign run's sigma (0.3 ug) and ~4x the first-order model's own error on
// this run. rel (argued per effect, checked against what this sweep measures):
//  - 1 %: the default, the bound. Effects the prediction models exactly to first
//    order in the nonlinearities (the remainder is of relative order (k w)^2 < 1e-6; the
//    ODE's quadrature 1e-9): measured <= 0.4 %, the largest where theta is largest.
//  - squeeze_film_damping 2 %: solved by harmonic balance up to the 31st harmonic
//    (rectification::film_harmonic_balance; the describing function alone erred by 5 % at
//    130 Hz over the drawn range 833-1000 /rad and needed 15 %). Measured 0.03 % at 130 Hz
//    and 0.06 % at 206 Hz over the drawn range, 1 % at the grid's end (3000 /rad, 96 Hz:
//    test_squeeze_film_harmonic_balance.cpp, which checks that end).
// A value or frequency where the effect changes less than the floor is still run (the
// bound holds trivially there) but a test whose every case is below the floor could not
// fail: each effect must change at least 10 floors somewhere in its sweep.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "rectification/simulation/shake.hpp"
#include "support/effect_check.hpp"
#include "support/instrument.hpp"
#include "validation/diagnosis/campaign.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/effect.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"

namespace test_effect_sweep {

using namespace vrelab;
using namespace vrelab::validation;
using vrelab::test::identified_by_static_test;
using vrelab::test::strong_run;

namespace {

constexpr double kFloor_g = 0.02e-6;

double relative_tolerance(const std::string& name) {
  static const std::map<std::string, double> rel{{"squeeze_film_damping", 0.02}};
  const auto it = rel.find(name);
  return it == rel.end() ? 0.01 : it->second;
}

// The values of the effect's (first) parameter to sweep: the extremes of what blind draws
// (per sign) and the fit grid's ends away from the nominal.
std::vector<double> sweep_values(const Effect& e, bool whole_range) {
  std::mt19937_64 rng(15);
  std::map<int, std::pair<double, double>> by_sign;  // sign -> (min |p|, max |p|), signed
  for (int k = 0; k < 400; ++k) {
    const double p = e.draw(rng).front();
    const int s = p < 0 ? -1 : 1;
    auto [it, fresh] = by_sign.try_emplace(s, p, p);
    if (!fresh) {
      if (std::abs(p) < std::abs(it->second.first)) it->second.first = p;
      if (std::abs(p) > std::abs(it->second.second)) it->second.second = p;
    }
  }
  std::vector<double> v;
  if (!whole_range) {  // the strongest drawn value only
    double strongest = 0;
    for (const auto& [s, mm] : by_sign)
      if (std::abs(mm.second) > std::abs(strongest)) strongest = mm.second;
    return {strongest};
  }
  for (const auto& [s, mm] : by_sign) v.push_back(mm.first), v.push_back(mm.second);
  const EffectParameter& q = e.fitted();
  // The squeeze film's grid runs to 3000 /rad (a gap of 0.33 mrad, a third of the swing the
  // strong run makes without it): there the describing function erred by 75 % (96 Hz); the
  // harmonic balance is checked at that end by test_squeeze_film_harmonic_balance.cpp (1 %
  // at 96, 130, 206 Hz); swept here over what blind hides (833-1000 /rad) only.
  if (!q.grid.empty() && e.name != "squeeze_film_damping") {
    std::vector<double> g;
    for (double x : q.grid)
      if (x != q.nominal) g.push_back(x);
    if (!g.empty()) v.push_back(g.front()), v.push_back(g.back());
  }
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// The sweep's points: each value above with the further parameters nominal (the default form)
// and, for an effect with a natural form, the same values with forms blind draws
// (Effect::draw_form, 3 draws; the discrete ones forced through each of their values, so a
// mode is swept along IA, PA and OA) -- at the strongest drawn value only in the short sweep.
std::vector<std::vector<double>> sweep_points(const Effect& e, bool whole_range) {
  std::vector<std::vector<double>> pts;
  const std::vector<double> firsts = sweep_values(e, whole_range);
  for (double p : firsts) pts.push_back(e.values_at(p));
  if (!e.draw_form) return pts;
  std::mt19937_64 rng(16);
  std::vector<std::vector<double>> forms;
  for (int k = 0; k < 3; ++k) forms.push_back(e.draw_form(rng));
  for (std::size_t j = 1; j < e.parameters.size(); ++j)
    if (e.parameters[j].discrete)
      for (std::size_t k = 0; k < forms.size() && k < e.parameters[j].starts.size(); ++k) forms[k][j - 1] = e.parameters[j].starts[k];
  const std::vector<double> at = whole_range ? firsts : std::vector<double>{sweep_values(e, false).front()};
  for (double p : at)
    for (const auto& form : forms) {
      std::vector<double> v = e.values_at(p);
      std::copy(form.begin(), form.end(), v.begin() + 1);
      pts.push_back(v);
    }
  return pts;
}

struct Point {
  double predicted_g, ode_g;
};

// As the diagnosis meets an effect: its hypothesis applied to the coefficients the static test
// identified from the truth instrument with the effect, less what the static test took up of
// an effect that acts at rest (the hypotheses of quadratic_cross_axis and the readout terms
// give that part back), against the nominal prediction from the instrument without it.
struct Identified {
  plant::PlantConfig base, with;
};
Identified identified(const Effect& e, const std::vector<double>& values) {
  const double p = values.front();
  const plant::PlantConfig truth = test::paper_like_plant();
  static const plant::Coefficients base = identified_by_static_test(truth);
  Identified out;
  out.base.coefficients = base;
  VirtualLab at_rest;
  at_rest.instrument = truth;
  e.truth(values, at_rest);
  // An effect of the table's motion or of the runs' acquisition leaves the static test's
  // instrument, and so its identification, unchanged.
  out.with.coefficients = e.acts_on == ActsOn::instrument ? identified_by_static_test(at_rest.instrument) : base;
  if (e.acts_at_rest) {
    const std::vector<Position> positions = equally_spaced_positions(12);
    FixedSet fixed{};
    fixed[plant::k_PP] = 0.0;
    const plant::Coefficients taken =
        taken_up_by_static_test(e, out.with, positions, std::vector<double>(positions.size(), 1.0), fixed);
    for (int i = 0; i < plant::kNumCoefficients; ++i) out.with.coefficients[i] -= (p - e.fitted().nominal) * taken[i];
  }
  return out;
}

Point compare(const Effect& e, const std::vector<double>& values, const Identified& id, double frequency_Hz,
              std::map<double, double>& ode_without) {
  const plant::PlantConfig truth = test::paper_like_plant();
  const RunRecord r = strong_run(frequency_Hz);
  VirtualLab lab;
  lab.instrument = truth;
  lab.table = r.vibration();
  lab.commanded_amplitude_g = r.amplitude_g;
  lab.static_gravity_g = r.orientation_g;
  e.truth(values, lab);
  auto it = ode_without.find(frequency_Hz);
  if (it == ode_without.end())
    it = ode_without.emplace(frequency_Hz, rectification::shake_sine(truth, r.orientation_g, r.vibration()).measured_g).first;
  const double ode =
      rectification::shake_sine(lab.run_plant(), r.orientation_g, r.vibration(), {}, {}, lab.excitation().get()).measured_g - it->second;
  return {predict_run_g(id.with, r, e, values) - predict_run_g(id.base, r), ode};
}

void sweep(const std::vector<double>& frequencies, bool whole_range) {
  std::map<double, double> ode_without;
  for (const Effect& e : effect_library()) {
    const double rel = relative_tolerance(e.name);
    double largest = 0, worst_ratio = 0;
    std::string worst;
    for (const std::vector<double>& values : sweep_points(e, whole_range)) {
      const double p = values.front();
      std::string form;  // the natural form's further parameters, for the messages
      for (std::size_t j = 1; j < values.size(); ++j) form += std::string(" ").append(e.parameters[j].name).append("=").append(std::to_string(values[j]));
      Identified id;
      for (double f : frequencies) {
        Point x{};
        try {
          if (f == frequencies.front()) id = identified(e, values);
          x = compare(e, values, id, f, ode_without);
        } catch (const std::invalid_argument& why) {
          // A grid end the plant cannot be (servo_dynamics' margin +32 deg needs more phase lead
          // than one network gives): the fit skips it too. Never a drawn value.
          EXPECT_TRUE(whole_range) << e.name << " = " << p << ": " << why.what();
          std::printf("  %-28s %g: no such plant (%s)\n", e.name.c_str(), p, why.what());
          break;
        }
        const double err = std::abs(x.predicted_g - x.ode_g);
        EXPECT_LE(err, rel * std::abs(x.ode_g) + kFloor_g)
            << e.name << " = " << p << form << " at " << f << " Hz: predicted " << x.predicted_g * 1e6 << " ug, ODE " << x.ode_g * 1e6 << " ug";
        largest = std::max(largest, std::abs(x.ode_g));
        const double ratio = err / (std::abs(x.ode_g) + kFloor_g);
        if (ratio > worst_ratio) {
          worst_ratio = ratio;
          char buf[160];
          std::snprintf(buf, sizeof buf, "%g%s at %g Hz (%.4g vs %.4g ug)", p, form.c_str(), f, x.predicted_g * 1e6, x.ode_g * 1e6);
          worst = buf;
        }
      }
    }
    EXPECT_GT(largest, 10 * kFloor_g) << e.name << ": the sweep never sees it (the test could not fail)";
    std::printf("  %-28s worst |pred - ODE| / (|ODE| + floor) = %.2e at %s; largest change %.4g ug\n", e.name.c_str(), worst_ratio,
                worst.c_str(), largest * 1e6);
  }
}

std::vector<double> log_spaced(double from, double to, int n) {
  std::vector<double> v;
  for (int k = 0; k < n; ++k) v.push_back(from * std::pow(to / from, k / (n - 1.0)));
  return v;
}

}  // namespace

// The short sweep (campaign too: 10-25 s under ASan; the sanitizers see the same code in the
// fast EffectRegistry.*): the sweep's two ends (10 Hz, 2 kHz) and the pendulum's swing's peak
// (130 Hz, where the squeeze film acts) at the strongest drawn value. (The 40 and 400 Hz
// points at the example values are test_diagnose.cpp's.)
TEST(EffectSweepCampaign, EveryEffectAtTheBandsEndsMatchesTheOde) { sweep({10.0, 130.0, 2000.0}, false); }

// The whole sweep (label "long": `ctest -L long`, 76 s in Release): 8 frequencies log-spaced 10 Hz - 2 kHz, the drawn
// extremes and the grid's ends.
TEST(EffectSweepLong, EveryEffectOverItsRangeAndTheBandMatchesTheOde) { sweep(log_spaced(10, 2000, 8), true); }

}  // namespace test_effect_sweep
