#include "validation/diagnosis/internal/response_cache.hpp"

#include <complex>
#include <cstdint>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

namespace vrelab::validation::internal {

using plant::PlantConfig;

void ResponseCache::bind(const PlantConfig& plant) {
  const std::lock_guard<std::mutex> g(mutex_);
  const bool same = bound_ && plant.coefficients.v == plant_.coefficients.v && key(plant.dynamics) == key(plant_.dynamics);
  if (same) return;
  plant_ = plant, bound_ = true;
  tables_.clear(), absorbed_.clear(), cache_.clear(), responders_.clear(), random_.clear(), grids_.clear(), damped_.clear(), pickoff_.clear();
}

std::string ResponseCache::random_key(const std::string& key, const vibration::RandomProfile& p, const Eigen::Matrix3d& turn,
                                      const rectification::RandomQuadrature& q) {
  std::string k = key;
  k += '\0';
  const auto put = [&k](double x) { k.append(reinterpret_cast<const char*>(&x), sizeof x); };
  for (const auto& table : p.psd) {
    put(table ? static_cast<double>(table->rows.size()) : -1.0);
    if (!table) continue;
    for (const vibration::PsdRow& row : table->rows) {
      put(row.frequency_Hz);
      put(row.psd_g2_per_Hz ? 1.0 : 0.0), put(row.psd_g2_per_Hz.value_or(0.0));
      put(row.slope_dB_per_octave ? 1.0 : 0.0), put(row.slope_dB_per_octave.value_or(0.0));
    }
  }
  put(static_cast<double>(static_cast<int>(p.coupling)));
  const auto address = reinterpret_cast<std::uintptr_t>(p.measured.get());
  k.append(reinterpret_cast<const char*>(&address), sizeof address);
  for (Eigen::Index i = 0; i < 9; ++i) put(turn(i));
  put(q.max_log_step), put(q.common_grid ? 1.0 : 0.0);
  return k;
}

const rectification::RandomResponse& ResponseCache::random_response(const PlantConfig& cfg, const std::string& key,
                                                                    const vibration::RandomProfile& p, const Eigen::Matrix3d& turn,
                                                                    const rectification::RandomQuadrature& q) {
  // (Made without the lock: the grid and the responses take it for their look-ups.)
  return find_or_make(mutex_, random_, random_key(key, p, turn, q),
                      [&] {
                        const GridEntry& entry =
                            find_or_make(mutex_, grids_, random_key(std::string(), p, Eigen::Matrix3d::Identity(), q), [&] {
                              rectification::RandomGrid raw = rectification::random_grid(p, q);
                              rectification::RandomGrid untouched = rectification::turned_grid(raw, Eigen::Matrix3d::Identity());
                              return GridEntry{p.measured, std::move(raw), std::move(untouched)};
                            });
                        // (Most effects leave the motion unturned: their grid is kept as it is.)
                        std::optional<rectification::RandomGrid> turned;
                        if (!turn.isIdentity(0.0)) turned = rectification::turned_grid(entry.grid, turn);
                        const rectification::RandomGrid& grid = turned ? *turned : entry.unturned;
                        return RandomEntry{p.measured, rectification::random_response(grid, responses(cfg, key, grid.frequency_Hz))};
                      })
      .response;
}

const rectification::DampedRandomSpectrum& ResponseCache::damped_random_spectrum(
    const std::string& key, const vibration::RandomProfile& p, const Eigen::Matrix3d& turn, const rectification::RandomQuadrature& q,
    const rectification::ResponseAt& h, const rectification::ResponseAt& h_twice) {
  return find_or_make(mutex_, damped_, random_key(key, p, turn, q),
                      [&] { return DampedEntry{p.measured, rectification::damped_random_spectrum(p, h, h_twice, q, turn)}; })
      .spectrum;
}

const rectification::GaussianPickoffMoments& ResponseCache::pickoff_moments(const PlantConfig& cfg, const std::string& key,
                                                                            const vibration::RandomProfile& p,
                                                                            const Eigen::Matrix3d& turn, const rectification::ResponseAt& h) {
  // (The key's dynamics are cfg's; the quadrature's place in the key holds the grid's size.)
  return find_or_make(mutex_, pickoff_, random_key(key, p, turn, {4096, false}),
                      [&] { return PickoffEntry{p.measured, rectification::gaussian_pickoff_moments(cfg, p, h, turn)}; })
      .moments;
}

std::shared_ptr<const Table> ResponseCache::table(const std::string& key) {
  const std::lock_guard<std::mutex> g(mutex_);
  const auto it = tables_.find(key);
  return it == tables_.end() ? nullptr : it->second;
}

void ResponseCache::store_table(const std::string& key, std::shared_ptr<const Table> t) {
  const std::lock_guard<std::mutex> g(mutex_);
  tables_[key] = std::move(t);
}

const rectification::LoopResponse& ResponseCache::get(const PlantConfig& cfg, const std::string& key, double f) {
  {
    const std::lock_guard<std::mutex> g(mutex_);
    // (By key, then frequency: the key is not copied for every look-up.)
    const auto by_key = cache_.find(key);
    if (by_key != cache_.end()) {
      const auto it = by_key->second.find(f);
      if (it != by_key->second.end()) return it->second;
    }
  }
  // Computed without the lock, so that other threads' look-ups go on meanwhile.
  if (!(f > 0)) throw std::invalid_argument("frequency_Hz must be positive");
  rectification::LoopResponse response = responder_with_servo(cfg, key)(f);
  const std::lock_guard<std::mutex> g(mutex_);
  return cache_[key].try_emplace(f, std::move(response)).first->second;
}

std::vector<const rectification::LoopResponse*> ResponseCache::responses(const PlantConfig& cfg, const std::string& key,
                                                                         const std::vector<double>& frequency_Hz) {
  std::vector<const rectification::LoopResponse*> out(frequency_Hz.size(), nullptr);
  std::vector<std::size_t> missing;
  {
    const std::lock_guard<std::mutex> g(mutex_);
    const auto by_key = cache_.find(key);
    for (std::size_t k = 0; k < frequency_Hz.size(); ++k) {
      if (by_key != cache_.end())
        if (const auto it = by_key->second.find(frequency_Hz[k]); it != by_key->second.end()) {
          out[k] = &it->second;
          continue;
        }
      missing.push_back(k);
    }
  }
  if (missing.empty()) return out;
  std::vector<rectification::LoopResponse> computed;
  computed.reserve(missing.size());
  const rectification::LoopResponder& responder = responder_with_servo(cfg, key);
  for (const std::size_t k : missing) {
    if (!(frequency_Hz[k] > 0)) throw std::invalid_argument("frequency_Hz must be positive");
    computed.push_back(responder(frequency_Hz[k]));
  }
  const std::lock_guard<std::mutex> g(mutex_);
  auto& by_f = cache_[key];
  for (std::size_t m = 0; m < missing.size(); ++m)
    out[missing[m]] = &by_f.try_emplace(frequency_Hz[missing[m]], std::move(computed[m])).first->second;
  return out;
}

ResponseCache::DynamicsKey ResponseCache::key(const plant::Dynamics& d) {
  return {d.pendulum_frequency_Hz, d.pendulum_damping_ratio, d.angle_gain_rad_per_s2_per_g, d.loop_bandwidth_Hz,
          d.phase_margin_deg,      d.integrator,             d.integrator_zero_ratio,       d.antialias_Hz};
}

const plant::Servo& ResponseCache::servo(const plant::Dynamics& d) {
  return find_or_make(mutex_, servos_, key(d), [&] { return plant::design_servo(d); });
}

// What loop_response reads of a plant (with its servo): the coefficients its linear plant
// keeps, the locations, the dynamics, the servo, and the linear effects (their
// transmissibility at a probe frequency; the key names the effect and its values).
std::vector<double> ResponseCache::linear_part(const PlantConfig& cfg) {
  std::vector<double> v;
  for (int c : {plant::K1, plant::k0, plant::delta_OA, plant::delta_PA}) v.push_back(cfg.coefficients[c]);
  for (const plant::Location l : cfg.location) v.push_back(static_cast<double>(l));
  const DynamicsKey d = key(cfg.dynamics);
  std::apply([&](auto... x) { (v.push_back(static_cast<double>(x)), ...); }, d);
  v.push_back(cfg.torquer_c2_per_g), v.push_back(cfg.torquer_c3_per_g2);
  const plant::Servo& sv = *cfg.servo;
  for (double x : {sv.gain_g_per_rad, sv.lead_zero_rad_per_s, sv.lead_pole_rad_per_s, sv.integrator_rad_per_s}) v.push_back(x);
  for (const auto& e : cfg.effects)
    if (e->kept_in_linearisation()) {
      for (int j = 0; j < 3; ++j) {
        const std::complex<double> t = e->transmissibility(j, 2 * std::numbers::pi * 1234.5);
        v.push_back(t.real()), v.push_back(t.imag());
      }
    }
  return v;
}

const rectification::LoopResponder& ResponseCache::responder_with_servo(const PlantConfig& cfg, const std::string& key) {
  if (cfg.servo) return responder(cfg, key);
  PlantConfig with_servo = cfg;
  with_servo.servo = servo(cfg.dynamics);
  return responder(with_servo, key);
}

const rectification::LoopResponder& ResponseCache::responder(const PlantConfig& cfg, const std::string& key) {
  return *find_or_make(mutex_, responders_, std::make_pair(key, linear_part(cfg)),
                       [&] { return std::make_unique<rectification::LoopResponder>(cfg); });
}

}  // namespace vrelab::validation::internal
