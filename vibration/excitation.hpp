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

class Excitation {
 public:
  virtual ~Excitation() = default;
  virtual Vec3 acceleration_g(double t_s) const = 0;
  // Highest frequency present, Hz: bounds the integrator's step and the sample rates.
  virtual double max_frequency_Hz() const = 0;
  // A one-line description for reports.
  virtual std::string describe() const = 0;
};

// The sine of profile.hpp as an Excitation: w_i sin(2 pi f t + phase_i) on each axis.
class SineExcitation final : public Excitation {
 public:
  explicit SineExcitation(const SineVibration& v);
  Vec3 acceleration_g(double t_s) const override;
  double max_frequency_Hz() const override { return v_.frequency_Hz; }
  std::string describe() const override;
  const SineVibration& sine() const { return v_; }

 private:
  SineVibration v_;
};

}  // namespace vrelab::vibration
