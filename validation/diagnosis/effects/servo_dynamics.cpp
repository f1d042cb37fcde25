// The servo loop's dynamics differ from the manifest's: the crossover, and in its natural form
// the phase margin and the pendulum frequency with it (docs/effects.md, "Loop dynamics").
#include "validation/diagnosis/effects/common.hpp"

namespace vrelab::validation {

namespace {
// The manifest's nominal dynamics as the instrument's: the crossover x ratio, the phase margin +
// change, the open-loop pendulum frequency x ratio; the servo designed for them (the plant
// refuses a loop the design cannot build: the fit leaves such values out).
void change_loop(ParameterValues v, plant::Dynamics& d) {
  d.loop_bandwidth_Hz *= v[0];
  d.phase_margin_deg += v[1];
  d.pendulum_frequency_Hz *= v[2];
}
}  // namespace

Effect effect_servo_dynamics() {
  Effect e;
  e.name = "servo_dynamics";
  e.rank = 5;
  e.acts_on = ActsOn::instrument;
  e.changes_dynamics = true;
  e.physics = "the servo loop's dynamics differ from the manifest's (a lab's estimate): the crossover, and with it "
              "the phase margin and the pendulum frequency; the rebalance current's response near the crossover, and "
              "with it the loop-placed terms' rectification, moves in frequency (crossover) and in peaking (margin); "
              "no effect at low frequency";
  EffectParameter p("bandwidth_ratio", "1");
  p.example = 0.7;
  p.nominal = 1;
  p.grid = effects::geometric(0.5, 2.0, 41);
  // The natural form. The margin: the closed loop's peaking at the crossover, pinned by runs near
  // it. Prior width 10 deg: a lab's margin is known to a few degrees; the drawn changes reach 20.
  EffectParameter m("phase_margin_change_deg", "deg");
  m.nominal = 0, m.lower = -32, m.upper = 32, m.example = -15;
  m.prior_sigma = 10, m.step = 0.05;
  // The pendulum's open-loop frequency: with the servo designed for it (gain for |L| = 1 at the
  // crossover, lead for the margin) it changes the loop only below the crossover, where the
  // loop gain is high and the output follows the input; the shaker runs rarely pin it and it is
  // then held with its prior (10 %: a pendulum frequency is measured to a few %).
  EffectParameter w("pendulum_frequency_ratio", "1");
  w.nominal = 1, w.lower = 0.8, w.upper = 1.25, w.example = 1.05;
  w.prior_sigma = 0.1, w.step = 1e-3;
  e.parameters = {p, m, w};
  e.hypothesis = [](ParameterValues v, plant::PlantConfig& c, TableMotion&) { change_loop(v, c.dynamics); };
  // The instrument's servo is designed for its own dynamics (written out: the truth does not
  // share the hypothesis' helper).
  e.truth = [](ParameterValues v, VirtualLab& lab) {
    lab.instrument.dynamics.loop_bandwidth_Hz *= v[0];
    lab.instrument.dynamics.phase_margin_deg += v[1];
    lab.instrument.dynamics.pendulum_frequency_Hz *= v[2];
  };
  e.draw = [](std::mt19937_64& rng) {
    effects::random_sign(rng);
    return std::vector<double>{effects::coin(rng) ? effects::log_uniform(rng, 0.6, 0.85) : effects::log_uniform(rng, 1.15, 1.6)};
  };
  // The natural form: the margin 4-20 deg either way, the pendulum frequency 2-5 % either way.
  e.draw_form = [](std::mt19937_64& rng) {
    const double sm = effects::random_sign(rng);
    const double margin = sm * effects::log_uniform(rng, 4, 20);
    const double sw = effects::random_sign(rng);
    return std::vector<double>{margin, 1 + sw * std::uniform_real_distribution<double>(0.02, 0.05)(rng)};
  };
  e.check = [name = e.name](ParameterValues v, std::string* why) {
    if (!(v[0] > 0)) {
      if (why) *why = name + " is a ratio of loop bandwidths, > 0, got " + std::to_string(v[0]);
      return false;
    }
    if (!(v[2] > 0)) {
      if (why) *why = name + ": pendulum_frequency_ratio must be positive, got " + std::to_string(v[2]);
      return false;
    }
    return true;
  };
  return e;
}

}  // namespace vrelab::validation
