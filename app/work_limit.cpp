// app/work_limit.cpp -- a case's run estimated before it starts (rectification/simulation/
// work_estimate.hpp): the case's keys mapped to the simulated time, the drive frequency and
// the number of runs of each command that simulates. Refused beyond the limits with the key
// that drives the estimate and the flag --no-work-limit.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "app/commands.hpp"
#include "rectification/simulation/work_estimate.hpp"

namespace vrelab::app {
namespace {

using rectification::WorkRequest;

Vec3 static_g(const io::Case& c) { return c.orientation_g.value_or(Vec3::UnitX()); }

double harmonic_factor(const io::Case& c) {
  int order = 1;
  for (const auto& h : c.shaker.harmonics) order = std::max(order, h.order);
  return order;
}

// Settling before a run: ln(1/decay) slowest time constants (shake.cpp).
double settle_s(const io::Case& c, const rectification::PlantTimescales& p) {
  return std::log(1 / c.shake.settle_decay) * p.slowest_time_constant_s;
}

// Measuring time of a sine run at f: whole periods, at least min_measure_s and `blocks` periods.
double measure_s(const io::Case& c, double f_Hz) { return std::max(c.shake.min_measure_s, c.shake.blocks / f_Hz); }

void check(const io::Case& c, const WorkRequest& r, const Vec3& a) {
  const auto p = rectification::plant_timescales(c.plant, a);
  try {
    rectification::check_work(rectification::estimate_work(r, p));
  } catch (const std::invalid_argument& e) {
    std::string keys = r.time_key;
    if (!r.runs_key.empty()) keys += ", " + r.runs_key;
    if (!r.samples_extra_key.empty()) keys += ", " + r.samples_extra_key;
    throw io::InputError(c.path + ": " + e.what() + " (simulated time set by " + keys + ")");
  }
}

}  // namespace

void check_shake_work(const io::Case& c) {
  if (!c.vibration || !c.coefficients) return;  // the command reports the missing table
  const io::VibrationSpec& v = *c.vibration;
  const auto p = rectification::plant_timescales(c.plant, static_g(c));
  WorkRequest r;
  r.sample_rate_Hz = c.shake.readout.active() ? c.shake.readout.sample_rate_Hz : 0.0;
  double drive = 0;
  if (rectification::has_sine_tone(v.type)) drive = v.sine.frequency_Hz * harmonic_factor(c);
  if (v.psd)
    for (const auto& t : v.psd->psd)
      if (t && !t->rows.empty()) drive = std::max(drive, t->rows.back().frequency_Hz);
  if (v.swept) drive = std::max(v.swept->start_frequency_Hz, v.swept->end_frequency_Hz) * harmonic_factor(c);
  r.drive_Hz = drive;
  r.drive_key = v.swept ? "[vibration] start/end_frequency_Hz" : v.psd ? "[vibration] psd_* frequencies" : "[vibration] frequency_Hz";
  if (v.type == rectification::VibrationKind::sine) {
    r.simulated_s = settle_s(c, p) + measure_s(c, v.sine.frequency_Hz);
    r.time_key = "[shake] min_measure_s, blocks and settle_decay";
  } else {
    r.simulated_s = settle_s(c, p) + v.duration_s;
    r.time_key = v.swept ? "the sweep's range and rate" : "[vibration] duration_s";
  }
  check(c, r, static_g(c));
}

void check_sweep_work(const io::Case& c) {
  if (!c.sweep || !c.coefficients) return;
  const auto& g = *c.sweep;
  const auto [fmin, fmax] = std::minmax_element(g.frequencies_Hz.begin(), g.frequencies_Hz.end());
  const auto p = rectification::plant_timescales(c.plant, g.orientations_g.front());
  WorkRequest r;
  r.sample_rate_Hz = c.shake.readout.active() ? c.shake.readout.sample_rate_Hz : 0.0;
  r.drive_Hz = *fmax * harmonic_factor(c);
  r.drive_key = "[sweep] frequencies";
  r.simulated_s = settle_s(c, p) + measure_s(c, *fmin);
  r.time_key = "[shake] min_measure_s, blocks and settle_decay, at the lowest [sweep] frequency";
  r.runs = static_cast<double>(g.frequencies_Hz.size() * g.amplitudes_g.size() * g.directions.size() * g.orientations_g.size());
  r.runs_key = "[sweep] grid (frequencies x amplitudes x directions x orientations_g)";
  check(c, r, g.orientations_g.front());
}

void check_reproduce_work(const io::Case& c) {
  if (!c.reproduce || !c.coefficients) return;
  const auto& s = *c.reproduce;
  double fmax = s.frequency_Hz, fmin = s.frequency_Hz;
  for (double f : s.departure_frequencies_Hz) fmax = std::max(fmax, f), fmin = std::min(fmin, f);
  const Vec3 a = s.orientations.empty() ? Vec3::UnitX() : s.orientations.front().v;
  const auto p = rectification::plant_timescales(c.plant, a);
  WorkRequest r;
  r.sample_rate_Hz = c.shake.readout.active() ? c.shake.readout.sample_rate_Hz : 0.0;
  r.drive_Hz = fmax;
  r.drive_key = "[reproduce] frequency_Hz / departure_frequencies_Hz";
  r.simulated_s = settle_s(c, p) + std::max(measure_s(c, fmin), s.confirmation.record_s);
  r.time_key = "[shake] min_measure_s and settle_decay, [reproduce.confirmation] record_s";
  r.runs = static_cast<double>(s.amplitudes_g.size() * s.directions.size() * s.orientations.size() *
                               (1 + s.departure_frequencies_Hz.size()) + 1);
  r.runs_key = "[reproduce] amplitudes_g x directions x orientations_g x frequencies";
  check(c, r, a);
}

void check_frequency_work(const io::Case& c) {
  if (!c.frequency_study || !c.coefficients || c.frequency_study->ode_frequencies_Hz.empty()) return;
  const auto& f = c.frequency_study->ode_frequencies_Hz;
  const auto p = rectification::plant_timescales(c.plant, static_g(c));
  WorkRequest r;
  r.drive_Hz = *std::max_element(f.begin(), f.end());
  r.drive_key = "[frequency_study] to_Hz";
  r.simulated_s = settle_s(c, p) + measure_s(c, *std::min_element(f.begin(), f.end()));
  r.time_key = "[shake] min_measure_s and settle_decay, at [frequency_study] from_Hz";
  r.runs = static_cast<double>(f.size());
  r.runs_key = "[frequency_study] ode_points";
  check(c, r, static_g(c));
}

void check_identify_work(const io::Case& c, int monte_carlo) {
  if (!c.dividing_head || !c.coefficients) return;
  const auto& h = *c.dividing_head;
  const double readings = static_cast<double>(h.positions.size()) * h.errors.repeats;
  WorkRequest r;
  r.runs = 0;  // model (1): no ODE
  r.samples_extra = readings * (1.0 + monte_carlo);
  r.samples_extra_key = "--monte-carlo and [dividing_head] positions x repeats";
  r.time_key = "--monte-carlo";
  if (h.from_ode) {
    // Each reading of the ODE source is a settled run of 30 slowest time constants.
    const auto p = rectification::plant_timescales(c.plant, Vec3::UnitX());
    r.runs = readings * (1.0 + monte_carlo);
    r.runs_key = "--monte-carlo x [dividing_head] readings (source = \"ode\")";
    r.simulated_s = 30 * p.slowest_time_constant_s;
  }
  check(c, r, Vec3::UnitX());
}

void check_campaign_work(const io::Case& c) {
  if (!c.campaign || !c.coefficients) return;  // write_virtual_campaign reports the missing table
  const validation::CampaignDesign& d = c.campaign->design;
  if (d.frequencies_Hz.empty() || d.orientations_g.empty()) return;
  const auto [fmin, fmax] = std::minmax_element(d.frequencies_Hz.begin(), d.frequencies_Hz.end());
  const auto p = rectification::plant_timescales(c.plant, d.orientations_g.front());
  WorkRequest r;
  r.drive_Hz = *fmax * harmonic_factor(c);
  r.drive_key = "[campaign] frequencies_Hz";
  r.simulated_s = settle_s(c, p) + std::max(measure_s(c, *fmin), d.raw_sample_rate_Hz > 0 ? d.raw_record_s : 0.0);
  r.time_key = "[shake] min_measure_s and settle_decay, [campaign] raw_record_s";
  r.sample_rate_Hz = d.raw_sample_rate_Hz > 0 ? std::max(d.raw_sample_rate_Hz, 20 * *fmax) : 0.0;  // raised to 20 per period
  r.runs = static_cast<double>(d.frequencies_Hz.size() * d.amplitudes_g.size() * d.directions.size() *
                               d.orientations_g.size());
  r.runs_key = "[campaign] frequencies_Hz x amplitudes_g x directions x orientations_g";
  check(c, r, d.orientations_g.front());
}

}  // namespace vrelab::app
