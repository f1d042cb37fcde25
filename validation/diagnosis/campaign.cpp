#include "validation/diagnosis/campaign.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>

#include "core/parallel.hpp"
#include "rectification/prediction/random.hpp"
#include "rectification/simulation/shake.hpp"
#include "vibration/decorators.hpp"
#include "vibration/excitation.hpp"
#include "vibration/sampled.hpp"

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

bool is_out_of_library(const std::string& name) {
  const Effect* e = find_effect(name);
  return e && !e->in_library;
}

void validate(const HiddenEffect& h) {
  const Effect* e = find_effect(h.name);
  if (!e) throw std::invalid_argument("campaign: unknown hidden effect '" + h.name + "'");
  std::string why;
  if (!h.form.empty() && h.form.size() + 1 != e->parameters.size())
    throw std::invalid_argument("campaign: " + h.name + " takes " + std::to_string(e->parameters.size() - 1) + " further parameter(s)");
  if (!e->is_valid(h.values(*e), &why)) throw std::invalid_argument("campaign: " + why);
}

HiddenEffect draw_hidden(const Effect& e, std::mt19937_64& rng) {
  if (!e.draw) throw std::invalid_argument("blind: no parameter range for " + e.name);
  return {e.name, e.draw(rng).front(), {}};
}

HiddenEffect draw_hidden_natural(const Effect& e, std::mt19937_64& rng) {
  HiddenEffect h = draw_hidden(e, rng);
  if (e.draw_form) h.form = e.draw_form(rng);
  return h;
}

std::vector<double> HiddenEffect::values(const Effect& e) const {
  std::vector<double> v = e.values_at(parameter);
  for (std::size_t i = 0; i < form.size() && i + 1 < v.size(); ++i) v[i + 1] = form[i];
  return v;
}

namespace {

// The virtual lab's truth for one run (zero amplitude: the static test), every hidden
// effect's truth hook applied in turn.
VirtualLab truth_lab(const plant::PlantConfig& truth, const std::vector<HiddenEffect>& hidden, const RunRecord* run) {
  VirtualLab lab;
  lab.instrument = truth;
  if (run) {
    lab.table = run->vibration();
    lab.commanded_amplitude_g = run->amplitude_g;
    lab.static_gravity_g = run->orientation_g;
  }
  for (const HiddenEffect& h : hidden) {
    const Effect& e = *find_effect(h.name);
    e.truth(h.values(e), lab);
  }
  return lab;
}

// The design's random and sine-on-random runs appended to c.runs (a random run described by
// its PSD); std::invalid_argument for what the virtual lab does not make.
void add_random_runs(const CampaignDesign& design, bool raw, Campaign& c) {
  if (design.random_runs.empty()) return;
  if (raw) throw std::invalid_argument("campaign: random_runs: raw records of random runs are not made (summaries only)");
  if (!(design.random_record_s > 0)) throw std::invalid_argument("campaign: random_record_s: must be positive");
  for (const RandomRunDesign& rd : design.random_runs) {
    vibration::validate(rd.profile);
    RunRecord r;
    r.id = "run" + std::to_string(c.runs.size() + 1);
    r.random = rd.profile;
    r.sine_part = rd.sine_part;
    r.orientation_g = rd.orientation_g;
    if (rd.sine_part) {
      if (!(rd.frequency_Hz > 0) || !(rd.amplitude_g > 0) || !(rd.direction.norm() > 0))
        throw std::invalid_argument("campaign: random_runs: a sine on random needs a positive frequency, amplitude and direction");
      r.frequency_Hz = rd.frequency_Hz, r.amplitude_g = rd.amplitude_g, r.direction = rd.direction.normalized();
    } else {
      describe_random_motion(r);
    }
    r.sigma_g = design.run_sigma_g;
    c.runs.push_back(r);
  }
}

// A random or sine-on-random run on the ODE plant: the plant and acquisition effects as for a
// sine run, the table-motion effects on the sine part, the fixture's turn on the random part
// too (VirtualLab::random_turn); the random part synthesised at 8 x its top frequency from `seed`, measured over record_s in 8 blocks.
rectification::ShakeResult shake_random_run(const plant::PlantConfig& truth, const std::vector<HiddenEffect>& hidden,
                                            const RunRecord& r, double record_s, std::uint64_t seed) {
  const VirtualLab lab = truth_lab(truth, hidden, r.sine_part ? &r : nullptr);
  const double top_Hz = vibration::max_frequency_Hz(*r.random);
  std::shared_ptr<const vibration::Excitation> motion = std::make_shared<vibration::RandomExcitation>(
      *r.random, 8 * top_Hz, seed, vibration::RandomExcitation::kDefaultBlockLength, lab.random_turn);
  if (r.sine_part)
    motion = std::make_shared<vibration::SumExcitation>(std::vector<std::shared_ptr<const vibration::Excitation>>{lab.excitation(), motion});
  rectification::ShakeSettings ss;
  ss.blocks = 8;
  return rectification::shake_excitation(lab.run_plant(), r.orientation_g, *motion, record_s, ss);
}

}  // namespace

CampaignDesign within_output_range(CampaignDesign design, const plant::PlantConfig& truth, const std::vector<HiddenEffect>& hidden,
                                   double range_g) {
  if (!(range_g > 0)) throw std::invalid_argument("within_output_range: range_g must be positive");
  for (RandomRunDesign& rd : design.random_runs) {
    RunRecord r;
    r.random = rd.profile, r.sine_part = rd.sine_part, r.orientation_g = rd.orientation_g;
    r.frequency_Hz = rd.frequency_Hz, r.amplitude_g = rd.amplitude_g, r.direction = rd.direction.normalized();
    const VirtualLab lab = truth_lab(truth, hidden, rd.sine_part ? &r : nullptr);
    plant::PlantConfig p = lab.run_plant();
    if (!p.servo) p.servo = plant::design_servo(p.dynamics);
    const rectification::LoopResponder loop(p);
    const rectification::RandomResponse rr = rectification::random_response(rd.profile, loop, {}, lab.random_turn);
    const double sigma_g = std::sqrt(rr.covariance(rectification::RandomResponse::kCurrent, rectification::RandomResponse::kCurrent));
    double sine_g = 0;
    if (rd.sine_part) {
      const rectification::LoopResponse h = loop(rd.frequency_Hz);
      std::complex<double> current = 0;
      for (int i = 0; i < 3; ++i) current += h.current[static_cast<std::size_t>(i)] * (rd.amplitude_g * r.direction[i]);
      sine_g = std::abs(current);
    }
    if (3 * sigma_g + sine_g > range_g && range_g > sine_g) vibration::scale_levels(rd.profile, std::pow((range_g - sine_g) / (3 * sigma_g), 2));
  }
  return design;
}

Campaign simulate_campaign(const plant::PlantConfig& truth, const std::vector<HiddenEffect>& hidden,
                           const CampaignDesign& design, std::uint64_t seed, int threads,
                           const std::function<void()>& run_done, std::vector<double>* run_noise_g) {
  for (const auto& h : hidden) validate(h);
  Campaign c;
  c.dynamics = truth.dynamics;
  c.fixed[plant::k_PP] = 0.0;  // the one coefficient a 1 g test cannot separate (its common part)
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;

  // The truth instrument with its hidden effects, as the static test reads it (the shaker
  // runs' data acquisition is not in it).
  const plant::PlantConfig static_plant = truth_lab(truth, hidden, nullptr).instrument;

  // Static test: the plant settled in each position.
  const std::vector<Position> positions = equally_spaced_positions(design.positions_per_series);
  const double K1 = static_plant.coefficients[plant::K1];
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
  // Random and sine-on-random runs, after the sine runs (their noise draws come after the sine
  // runs': a design without them draws as before).
  const bool raw = design.raw_sample_rate_Hz > 0;
  add_random_runs(design, raw, c);
  std::vector<double> noise(c.runs.size());
  for (double& x : noise) x = n01(rng);
  if (raw) c.raw.resize(c.runs.size());
  std::vector<std::string> failures(c.runs.size());
  // Each run's own failure is kept and the others still run; all are reported after.
  const auto run = [&](std::size_t k) {
    RunRecord& r = c.runs[k];
    const vibration::SineVibration commanded = r.vibration();
    try {
      if (r.random) {
        const rectification::ShakeResult s = shake_random_run(truth, hidden, r, design.random_record_s, seed * 1000003u + k);
        r.measured_g = s.measured_g + design.run_sigma_g * noise[k];
        r.sigma_g = std::hypot(s.sigma_g, design.run_sigma_g);
        return;
      }
      const VirtualLab lab = truth_lab(truth, hidden, &r);
      const plant::PlantConfig run_plant = lab.run_plant();
      const std::shared_ptr<const vibration::Excitation> motion = lab.excitation();
      if (raw) {
        rectification::ShakeSettings ss;
        ss.readout.sample_rate_Hz = std::max(design.raw_sample_rate_Hz, 20 * r.frequency_Hz);
        ss.readout.noise_sigma_g = design.raw_noise_sigma_g;
        ss.readout.seed = seed * 1000003u + k;
        ss.min_measure_s = design.raw_record_s;
        ss.blocks = 8;
        RawRecord& rec = c.raw[k];
        const rectification::ShakeResult s = rectification::shake_sine(
            run_plant, r.orientation_g, commanded, ss,
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
        const rectification::ShakeResult s = rectification::shake_sine(run_plant, r.orientation_g, commanded, {}, {}, motion.get());
        r.measured_g = s.measured_g + r.sigma_g * noise[k];
      }
    } catch (const std::exception& e) {
      failures[k] = e.what();
    }
  };
  core::parallel_for(c.runs.size(), threads, run, [&](std::size_t) {
    if (run_done) run_done();
  });
  for (std::size_t k = 0; k < failures.size(); ++k)
    if (!failures[k].empty()) throw std::runtime_error("campaign: " + c.runs[k].id + ": " + failures[k]);
  if (run_noise_g) {
    run_noise_g->resize(c.runs.size());
    for (std::size_t k = 0; k < c.runs.size(); ++k) (*run_noise_g)[k] = raw ? NAN : design.run_sigma_g * noise[k];
  }
  return c;
}

}  // namespace vrelab::validation
