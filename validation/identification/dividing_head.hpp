#pragma once
// validation/identification/dividing_head.hpp -- the virtual static test on a dividing head.
//
// Takes: the true model (1) coefficients, a set of test positions, the error sources of
//        the test (each switchable), and a seeded random generator.
// Gives: the nominal orientation of each position (gravity in sensor axes, g), the
//        simulated readings U (output units), and the first-order sensitivity of every
//        reading to the error sources (the paper's Delta U expression).
//
// Position convention (paper-notes.md; docs/dividing-head.md has the table): in series s
// the two sensor axes that lie in the vertical plane take (-cos phi, -sin phi) g:
//   series 1 (rotation about OA): (a_IA, a_PA) = (-cos phi, -sin phi), a_OA = 0
//   series 2 (rotation about PA): (a_IA, a_OA) = (-cos phi, -sin phi), a_PA = 0
//   series 3 (rotation about IA): (a_PA, a_OA) = (-cos phi, -sin phi), a_IA = 0
// The paper's test is 8 positions per series, phi = (j - 1) * 45 deg, j = 1..8.
//
// Error sources:
//  - initial orientation error: a fixed small rotation alpha (rad, about [IA, PA, OA]) of
//    the sensor frame relative to the head, the same in every position:
//    a_sensor = R(alpha)^T a_head;
//  - set-angle error: each visit of a position sets phi + N(0, sigma); for a position given
//    as an explicit vector, a rotation with N(0, sigma) about each sensor axis;
//  - reading noise: each reading (one visit's mean output) gets N(0, (K1 sigma_g)^2);
//  - repeats: each position is visited `repeats` times, each visit with fresh errors.
#include <cstdint>
#include <functional>
#include <random>
#include <utility>
#include <string>
#include <vector>

#include "core/settings_description.hpp"
#include "plant/model1.hpp"

namespace vrelab::validation {

struct Position {
  int series = 0;          // 1, 2, 3; 0 for an explicit orientation vector
  double angle_rad = 0.0;  // set angle phi (series positions)
  Vec3 nominal_g = Vec3::Zero();
};

// Gravity in sensor axes for series s at angle phi, g (convention above).
Vec3 series_orientation(int series, double angle_rad);
// The same from an angle in degrees, exact at multiples of 90 deg (cos 90 deg = 0, not
// 6e-17): a rounding column would otherwise look like a real one to the identification.
Vec3 series_orientation_deg(int series, double angle_deg);
// cos and sin of an angle in degrees, reduced exactly to [-45, 45] deg first.
std::pair<double, double> cos_sin_deg(double angle_deg);
// N equally spaced positions per series, phi = (j - 1) 360/N deg, for the given series
// (computed in radians, as the shipped results are: the identification decides its rank on
// the unscaled design, where the 1e-16 rounding columns count as zero).
std::vector<Position> equally_spaced_positions(int per_series, const std::vector<int>& series = {1, 2, 3});
Position series_position(int series, double angle_rad);
Position series_position_deg(int series, double angle_deg);  // exact at multiples of 90 deg
Position vector_position(const Vec3& a_g);  // unit vector expected
// True when `p` is the paper's 3 x 8 set in the paper's order.
bool is_paper_set(const std::vector<Position>& p);

// The test's error sources (above). Describe lists each field once
// (core/settings_description.hpp), in the units held: the record of the settings used and
// IsValid. A case's [dividing_head] writes them in arcsec and ug.
struct StaticTestErrors {
  Vec3 initial_error_rad = Vec3::Zero();
  double angle_sigma_rad = 0.0;
  double noise_sigma_g = 0.0;  // per reading, input-equivalent
  int repeats = 1;

  template <class V>
  static void Describe(V& v) {
    using S = StaticTestErrors;
    using core::field;
    v(field("initial_error_rad", &S::initial_error_rad, "rad", core::finite(),
            "Initial orientation error: the sensor frame's rotation about [IA, PA, OA], the same in every position"));
    v(field("angle_sigma_rad", &S::angle_sigma_rad, "rad", core::at_least(0), "Set-angle error of each visit (sigma)"));
    v(field("noise_sigma_g", &S::noise_sigma_g, "g", core::at_least(0), "Reading noise, input-equivalent (sigma)"));
    v(field("repeats", &S::repeats, "visits", core::closed(1, 100000), "Visits of each position"));
  }
  bool IsValid(std::string* why) const { return core::validate(*this, why); }
};

struct Reading {
  int position = 0;     // index into the position set
  double output = 0.0;  // U, output units
};

// The orientation actually realised: nominal position, systematic rotation, angle error
// (for series positions the angle error `d_angle[0]` is about the head axis; for vector
// positions `d_angle` is a small rotation about the sensor axes).
Vec3 realised_orientation(const Position& p, const Vec3& initial_error_rad, const Vec3& d_angle_rad);

// What the instrument reads (output units, noise-free) in a realised orientation (g).
using OutputSource = std::function<double(const Vec3& a_g)>;
// Model (1) with the given coefficients as the source.
OutputSource model1_source(const plant::Coefficients& truth);

// One complete test: positions.size() * repeats readings, position-major. K1 scales the
// reading noise (given in g).
std::vector<Reading> simulate_static_test(const OutputSource& source, double K1,
                                          const std::vector<Position>& positions,
                                          const StaticTestErrors& errors, std::mt19937_64& rng);
inline std::vector<Reading> simulate_static_test(const plant::Coefficients& truth,
                                                 const std::vector<Position>& positions,
                                                 const StaticTestErrors& errors, std::mt19937_64& rng) {
  return simulate_static_test(model1_source(truth), truth[plant::K1], positions, errors, rng);
}

// First-order error budget of each reading of `readings`, for coefficients `c` (in a lab,
// the estimated ones): the variance from noise and set-angle errors (output units^2) and
// the bias from the initial orientation error (output units).
struct ReadingBudget {
  std::vector<double> variance;
  std::vector<double> bias;
};
ReadingBudget reading_budget(const plant::Coefficients& c, const std::vector<Position>& positions,
                             const std::vector<Reading>& readings, const StaticTestErrors& errors);

}  // namespace vrelab::validation
