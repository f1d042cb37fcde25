#pragma once
// validation/diagnosis/internal/response_cache.hpp -- the loop responses and tables the
// diagnosis computes once per identified plant.
//
// Takes: the identified plant (coefficients and nominal dynamics), then per request a plant
//        (the nominal one with an effect's hypothesis applied), a key naming the effect and
//        its values, and a frequency (Hz).
// Gives: the plant's loop response at that frequency (rectification::LoopResponse), computed
//        once per (key, frequency) and per linear part of the plant, with the servo its
//        dynamics imply designed once per dynamics; and the store of the run tables and of
//        what the static test takes up (filled by tabulate and identification), forgotten when
//        a different plant is bound.
//
// A plant without a servo of its own gets the one its dynamics imply, designed once per
// dynamics here rather than in every loop_response (design_servo scans 3000 frequencies:
// designed in every loop_response it would be ~85 % of a diagnosis with random runs, whose PSD
// grid asks for hundreds of frequencies per effect value). The servo is the same function of
// the same numbers, so the responses are bit for bit those loop_response gives.
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "plant/accelerometer.hpp"
#include "rectification/prediction/frequency.hpp"
#include "rectification/prediction/random.hpp"
#include "vibration/random.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"

namespace vrelab::validation::internal {

// What the static test took up of an effect that acts at rest, per unit of (p - nominal)
// (taken_up_by_static_test), by effect name: subtracted from the identified coefficients
// under the effect.
using Absorbed = std::map<std::string, plant::Coefficients>;

// The entry of `map` (a std::map shared by threads, guarded by `lock`) at `key`, made by
// make() when missing, without the lock, so that other threads' look-ups go on meanwhile. Two
// threads that make the same entry make the same value (every entry is a function of its key
// alone): the first stored is kept. Entries are not erased while in use, so the reference
// stays valid.
template <class Map, class Key, class Make>
const typename Map::mapped_type& find_or_make(std::mutex& lock, Map& map, const Key& key, Make&& make) {
  {
    const std::lock_guard<std::mutex> g(lock);
    const auto it = map.find(key);
    if (it != map.end()) return it->second;
  }
  typename Map::mapped_type value = make();
  const std::lock_guard<std::mutex> g(lock);
  return map.try_emplace(key, std::move(value)).first->second;
}

class ResponseCache {
 public:
  // The tables (tabulate) and what the static test takes up, per effect and value, for one
  // identified plant and one set of runs' physics (their sigma is not an input): the
  // diagnose() wrapper's second pass (the sigma scaled) asks for the same ones again. bind()
  // forgets everything when the plant differs from the one bound (exactly).
  //
  // Thread-safe: the effects' fits share one cache across threads (score_effects). Every entry
  // is a function of its key alone, so a value computed by two threads at once is the same
  // numbers and the first stored is kept; entries are never erased while bound, so a
  // reference returned stays valid.
  void bind(const plant::PlantConfig& plant);
  // The table stored for `key` (nullptr: none).
  std::shared_ptr<const Table> table(const std::string& key);
  void store_table(const std::string& key, std::shared_ptr<const Table> t);
  // Filled by the identification before any fit runs (one thread).
  Absorbed absorbed_;

  // (A response is computed for the first plant that asks for its key and frequency, as
  // loop_response would compute it; the plant is linearised once for every frequency asked of
  // a linear part alike (rectification::LoopResponder: the same numbers).)
  const rectification::LoopResponse& get(const plant::PlantConfig& cfg, const std::string& key, double f);

  // A random part's covariances through the loop (rectification::random_response of `p`,
  // turned by `turn`, with the responses get(cfg, key, .)), computed once per (key, profile,
  // turn, quadrature): every table of an effect that leaves the dynamics alone (the empty key),
  // at every value, gradient point and fold, takes the same one. The quadrature's points are
  // kept per (profile, quadrature), turned per call, and the responses asked for all at once (one look-up
  // of the key, the plant linearised once): the same numbers as computed afresh.
  const rectification::RandomResponse& random_response(const plant::PlantConfig& cfg, const std::string& key,
                                                       const vibration::RandomProfile& p, const Eigen::Matrix3d& turn,
                                                       const rectification::RandomQuadrature& q);
  // The same kept for any damping of a film (rectification::damped_random_spectrum, h and
  // h_twice the responses of `key` without the film and with its damping doubled): every
  // value of the film and every table take the same one per run.
  const rectification::DampedRandomSpectrum& damped_random_spectrum(const std::string& key, const vibration::RandomProfile& p,
                                                                    const Eigen::Matrix3d& turn,
                                                                    const rectification::RandomQuadrature& q,
                                                                    const rectification::ResponseAt& h,
                                                                    const rectification::ResponseAt& h_twice);

  // A pickoff nonlinearity's moments for its second order (rectification::gaussian_pickoff_moments
  // with the responses h of `key`), once per (key, profile, turn): they do not depend on p2.
  const rectification::GaussianPickoffMoments& pickoff_moments(const plant::PlantConfig& cfg, const std::string& key,
                                                               const vibration::RandomProfile& p, const Eigen::Matrix3d& turn,
                                                               const rectification::ResponseAt& h);

 private:
  // Every field of plant::Dynamics (design_servo's only input).
  using DynamicsKey = std::tuple<double, double, double, double, double, bool, double, double>;
  static DynamicsKey key(const plant::Dynamics& d);
  const plant::Servo& servo(const plant::Dynamics& d);
  // What loop_response reads of a plant (with its servo).
  static std::vector<double> linear_part(const plant::PlantConfig& cfg);
  const rectification::LoopResponder& responder(const plant::PlantConfig& cfg, const std::string& key);
  // The same with the servo cfg's dynamics imply when cfg has none (servo()).
  const rectification::LoopResponder& responder_with_servo(const plant::PlantConfig& cfg, const std::string& key);
  // get(cfg, key, f) for every f, the key looked up once and the missing ones computed together.
  std::vector<const rectification::LoopResponse*> responses(const plant::PlantConfig& cfg, const std::string& key,
                                                            const std::vector<double>& frequency_Hz);
  std::map<std::string, std::map<double, rectification::LoopResponse>, std::less<>> cache_;
  std::map<std::pair<std::string, std::vector<double>>, std::unique_ptr<rectification::LoopResponder>> responders_;
  std::map<DynamicsKey, plant::Servo> servos_;
  // By the key's and the profile's bytes; the measured matrix (compared by address) is held
  // so that its address is not reused while the entry lives.
  struct RandomEntry {
    std::shared_ptr<const vibration::CrossSpectralMatrix> measured;
    rectification::RandomResponse response;
  };
  std::map<std::string, RandomEntry, std::less<>> random_;
  struct GridEntry {
    std::shared_ptr<const vibration::CrossSpectralMatrix> measured;
    rectification::RandomGrid grid;      // every point (random_grid)
    rectification::RandomGrid unturned;  // turned_grid(grid, identity): the points with power
  };
  std::map<std::string, GridEntry, std::less<>> grids_;
  struct DampedEntry {
    std::shared_ptr<const vibration::CrossSpectralMatrix> measured;
    rectification::DampedRandomSpectrum spectrum;
  };
  std::map<std::string, DampedEntry, std::less<>> damped_;
  struct PickoffEntry {
    std::shared_ptr<const vibration::CrossSpectralMatrix> measured;
    rectification::GaussianPickoffMoments moments;
  };
  std::map<std::string, PickoffEntry, std::less<>> pickoff_;
  static std::string random_key(const std::string& key, const vibration::RandomProfile& p, const Eigen::Matrix3d& turn,
                                const rectification::RandomQuadrature& q);
  std::map<std::string, std::shared_ptr<const Table>> tables_;
  plant::PlantConfig plant_;
  bool bound_ = false;
  std::mutex mutex_;  // over every member, held for look-ups and insertions (computed without it)
};

}  // namespace vrelab::validation::internal
