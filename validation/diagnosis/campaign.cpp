#include "validation/diagnosis/campaign.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>

#include "plant/effects/effects.hpp"
#include "rectification/simulation/shake.hpp"
#include "vibration/decorators.hpp"
#include "vibration/excitation.hpp"

namespace vrelab::validation {

CampaignDesign default_design() {
  CampaignDesign d;
  constexpr double arcsec = std::numbers::pi / (180 * 3600);
  d.errors.initial_error_rad = Vec3(3, -2, 4) * arcsec;
  d.errors.angle_sigma_rad = 0.5 * arcsec;
  d.errors.noise_sigma_g = 0.5e-6;
  d.errors.repeats = 2;
  d.frequencies_Hz = {10, 40, 100, 200, 400, 800, 1500};
  d.amplitudes_g = {1, 2, 4};
  d.directions = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 0).normalized()};
  d.orientations_g = {Vec3(1, 0, 1).normalized(), Vec3(-1, 0, 1).normalized()};  // a_IA = +-0.71 g
  return d;
}

bool is_out_of_library(const std::string& name) { return name == "readout_clipping" || name == "shaker_third_harmonic"; }

Campaign simulate_campaign(const plant::PlantConfig& truth, const std::vector<HiddenEffect>& hidden,
                           const CampaignDesign& design, std::uint64_t seed, int threads) {
  for (const auto& h : hidden) {
    if (!find_effect(h.name) && !is_out_of_library(h.name))
      throw std::invalid_argument("campaign: unknown hidden effect '" + h.name + "'");
    // These two are hypotheses (present or not), not scalable: the truth takes 0 or 1.
    if ((h.name == "pendulum_geometry" || h.name == "nonlinearity_at_input") && h.parameter != 0 && h.parameter != 1)
      throw std::invalid_argument("campaign: " + h.name + " is present (1) or not (0), got " + std::to_string(h.parameter));
    if ((h.name == "shaker_harmonic_distortion" || h.name == "shaker_third_harmonic") && !(h.parameter >= 0 && h.parameter < 1))
      throw std::invalid_argument("campaign: " + h.name + " is a harmonic's ratio to the fundamental, in [0, 1), got " + std::to_string(h.parameter));
    if (h.name == "readout_clipping" && !(h.parameter > 0))
      throw std::invalid_argument("campaign: readout_clipping is the DAQ's full scale in g, > 0, got " + std::to_string(h.parameter));
  }
  Campaign c;
  c.dynamics = truth.dynamics;
  c.fixed[plant::k_PP] = 0.0;  // the one coefficient a 1 g test cannot separate (its common part)
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;

  // The truth plant with its hidden effects (those that live in the plant); the static test
  // reads it without those that live in the shaker runs' data acquisition.
  plant::PlantConfig plant = truth, static_plant = truth;
  for (const auto& h : hidden) {
    if (h.name == "shaker_third_harmonic") continue;  // the table's motion, below
    if (h.name == "readout_clipping") {  // the shaker runs' DAQ; the static test is read apart
      plant.effects.push_back(std::make_shared<plant::ReadoutClipping>(h.parameter));
      continue;
    }
    const EffectModel& e = *find_effect(h.name);
    TableMotion dummy;
    e.apply(h.parameter, plant, dummy);
    if (!e.shaker_runs_only) e.apply(h.parameter, static_plant, dummy);
  }

  // Static test: the plant settled in each position.
  const std::vector<Position> positions = equally_spaced_positions(design.positions_per_series);
  const double K1 = plant.coefficients[plant::K1];
  const OutputSource source = [&static_plant, K1](const Vec3& a) { return K1 * plant::settled_output_g(static_plant, a); };
  const std::vector<Reading> readings = simulate_static_test(source, K1, positions, design.errors, rng);
  // The readings' sigma as a lab states it: noise and set-angle error through the scale
  // factor alone (nothing of the truth's nonlinearity or hidden effects).
  plant::Coefficients scale_only;
  scale_only[plant::K1] = K1;
  const ReadingBudget budget = reading_budget(scale_only, positions, readings, design.errors);
  for (std::size_t i = 0; i < readings.size(); ++i)
    c.statics.push_back({positions[static_cast<std::size_t>(readings[i].position)].nominal_g, readings[i].output,
                         std::sqrt(budget.variance[i]), ""});

  // Shaker runs.
  for (const Vec3& o : design.orientations_g)
    for (const Vec3& dir : design.directions)
      for (double a : design.amplitudes_g)
        for (double f : design.frequencies_Hz) {
          RunRecord r;
          r.id = "run" + std::to_string(c.runs.size() + 1);
          r.frequency_Hz = f, r.amplitude_g = a, r.direction = dir.normalized(), r.orientation_g = o;
          r.sigma_g = design.run_sigma_g;
          c.runs.push_back(r);
        }
  std::vector<double> noise(c.runs.size());
  for (double& x : noise) x = n01(rng);
  const bool raw = design.raw_sample_rate_Hz > 0;
  if (raw) c.raw.resize(c.runs.size());
  std::atomic<std::size_t> next{0};
  std::vector<std::string> failures(c.runs.size());
  auto worker = [&] {
    for (std::size_t k = next++; k < c.runs.size(); k = next++) {
      RunRecord& r = c.runs[k];
      const vibration::SineVibration commanded = r.vibration();
      TableMotion table = table_motion(r);
      for (const auto& h : hidden) {
        if (h.name == "shaker_third_harmonic") table.harmonics.push_back({3, h.parameter, 0.0});
        if (is_out_of_library(h.name)) continue;
        plant::PlantConfig unused = truth;
        find_effect(h.name)->apply(h.parameter, unused, table);  // the shaker's own motion
      }
      const std::shared_ptr<const vibration::Excitation> motion = table.excitation();
      try {
        if (raw) {
          rectification::ShakeSettings ss;
          ss.readout.sample_rate_Hz = std::max(design.raw_sample_rate_Hz, 20 * r.frequency_Hz);
          ss.readout.noise_sigma_g = design.raw_noise_sigma_g;
          ss.readout.seed = seed * 1000003u + k;
          ss.min_measure_s = design.raw_record_s;
          ss.blocks = 8;
          RawRecord& rec = c.raw[k];
          const rectification::ShakeResult s = rectification::shake_sine(
              plant, r.orientation_g, commanded, ss,
              [&rec](double t, const Vec3&, double u) {
                rec.t_s.push_back(t);
                rec.output.push_back(u);
              },
              motion.get());
          // Windows half a sample clear of the samples they hold ([from, to), as SeriesMeasurer).
          const double dt = 1 / s.sample_rate_Hz;
          rec.rest_from_s = rec.t_s.front() - dt / 2, rec.rest_to_s = -dt / 2;
          rec.on_from_s = s.settle_s - dt / 2, rec.on_to_s = rec.t_s.back();  // [from, to): the last sample out
          r.measured_g = s.measured_g, r.sigma_g = s.sigma_g;
        } else {
          const rectification::ShakeResult s = rectification::shake_sine(plant, r.orientation_g, commanded, {}, {}, motion.get());
          r.measured_g = s.measured_g + r.sigma_g * noise[k];
        }
      } catch (const std::exception& e) {
        failures[k] = e.what();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::max(1, threads); ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  for (std::size_t k = 0; k < failures.size(); ++k)
    if (!failures[k].empty()) throw std::runtime_error("campaign: " + c.runs[k].id + ": " + failures[k]);
  return c;
}

}  // namespace vrelab::validation
