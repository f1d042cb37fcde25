#pragma once
// vibration/excitation.hpp -- the interface between the shaker and the plant.
//
// An Excitation is the dynamic part of the specific force the accelerometer feels, in
// sensor axes [IA, PA, OA], in g, as a function of time in seconds: the total input is the
// static orientation (gravity in sensor axes, part of every run) plus acceleration_g(t).
// Shaker imperfections that change the gravity projection (rocking) contribute here too.
#include <memory>
#include <string>

#include "plant/model1.hpp"
#include "vibration/profile.hpp"

namespace vrelab::vibration {

class RandomExcitation;  // vibration/sampled.hpp

class Excitation {
 public:
  virtual ~Excitation() = default;
  virtual Vec3 acceleration_g(double t_s) const = 0;
  // Highest frequency present, Hz: bounds the integrator's step and the sample rates.
  virtual double max_frequency_Hz() const = 0;
  // A one-line description for reports.
  virtual std::string describe() const = 0;
  // The excitation as a stream of Gaussian random samples, which a plant may step through
  // sample by sample (rectification/simulation/discretised.hpp); nullptr when it is not one
  // (a sum holding one is not: its other parts are not sampled).
  virtual const RandomExcitation* random_samples() const { return nullptr; }
  // The motion's deterministic mean, g: zero for a tone, its harmonics and a random part (a
  // record's sample mean is random, not the motion's); a rocking fixture's turned gravity and
  // centripetal acceleration are not zero-mean (rectification::shake_excitation gives its
  // linear output back).
  virtual Vec3 mean_g() const { return Vec3::Zero(); }
};

// A tone: A_i sin(theta(t) + phase_i) on axis i, one carrier phase theta(t) for all axes
// (a fixed sine, theta = 2 pi f t, or a sweep). The imperfection decorators that need the
// carrier (exact transverse phase shift, harmonics, rocking) take a ToneExcitation.
struct CarrierState {
  double phase_rad = 0.0;      // theta(t)
  double frequency_Hz = 0.0;   // theta'(t) / (2 pi)
  double rate_Hz_per_s = 0.0;  // theta''(t) / (2 pi)
};

class ToneExcitation : public Excitation {
 public:
  virtual CarrierState carrier(double t_s) const = 0;
  virtual Vec3 amplitude_g() const = 0;  // A_i, peak, >= 0
  virtual Vec3 phase_rad() const = 0;    // phase_i
  Vec3 acceleration_g(double t_s) const override;  // A_i sin(theta(t) + phase_i)
};

// The sine of profile.hpp as an Excitation: w_i sin(2 pi f t + phase_i) on each axis.
class SineExcitation final : public ToneExcitation {
 public:
  explicit SineExcitation(const SineVibration& v);
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override { return v_.frequency_Hz; }
  std::string describe() const override;
  const SineVibration& sine() const { return v_; }
  CarrierState carrier(double t_s) const override;
  Vec3 amplitude_g() const override { return v_.amplitude_g; }
  Vec3 phase_rad() const override { return v_.phase_rad; }

 private:
  SineVibration v_;
};

}  // namespace vrelab::vibration
