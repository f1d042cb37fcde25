// Speed of the virtual shaker (issue: "Speed"), with Google Benchmark:
//  - SineConditionLogSweep/1 (periodic steady state) and /0 (transient path): one sine
//    condition measured to the default tolerance (~1e-9 g or better), over a 100-point log
//    sweep 1 Hz - 5 kHz, default plant, k2 = 15 ug/g^2, 5 g along IA; counters: median and
//    maximum CPU milliseconds (the run's thread) per condition;
//  - RandomGevs20kHz/1/60 (exponential integrator, 60 s) and /0/4 (CVODE, 4 s): GEVS
//    20-2000 Hz along IA with the output sampled at 20 kHz, the shipped random-case
//    tolerance (1e-4); counter: simulated seconds per CPU second of the run's thread.
//  - CvodeJacobian/<case>/<analytic>: the CVODE paths with the plant's Jacobian
//    (ShakeSettings::analytic_jacobian = 1) or CVODE's difference quotients (0). Cases:
//    0 the transient sine path at 2 Hz (settle 16 time constants, 4 periods, rtol 1e-10),
//    default plant; 1 the same with effects (pendulum geometry, pickoff p2 = 20 /rad, squeeze
//    film); 2 GEVS 20-2000 Hz with the pickoff nonlinearity (the random path's CVODE fallback,
//    rtol 1e-4, 2 s); 3 sine-on-random-like: 5 g at 80 Hz on the default plant through
//    CVODE's transient path at 1 kHz. Counters: CPU ms per run and right-hand sides per run.
// Run: taskset -c 0 build/vrelab_bench   (Release build; one core; docs/performance.md)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <vector>

#include "plant/effects/effects.hpp"
#include "rectification/simulation/shake.hpp"
#include "bench/gevs.hpp"
#include "vibration/sampled.hpp"

using namespace vrelab;

namespace {

plant::PlantConfig default_plant() {
  plant::PlantConfig cfg;
  cfg.coefficients[plant::K1] = 1.25;
  cfg.coefficients[plant::k0] = 1.5e-3;
  cfg.coefficients[plant::k2] = 1.5e-5;
  return cfg;
}

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// state.range(0): 1 = the periodic steady state (default), 0 = the transient path (settle
// 16 time constants, measure 4 periods: the fallback, ShakeSettings::periodic_steady_state
// = false).
void SineConditionLogSweep(benchmark::State& state) {
  const plant::PlantConfig cfg = default_plant();
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  rectification::ShakeSettings s;
  s.periodic_steady_state = state.range(0) != 0;
  std::vector<double> ms;
  for (auto _ : state) {
    ms.clear();
    for (int i = 0; i < 100; ++i) {
      vibration::SineVibration v;
      v.amplitude_g = Vec3(5, 0, 0);
      v.frequency_Hz = std::pow(10.0, std::log10(5000.0) * i / 99.0);
      const double t0 = thread_cpu_ms();
      const auto r = rectification::shake_sine(cfg, a, v, s);
      benchmark::DoNotOptimize(r.measured_g);
      ms.push_back(thread_cpu_ms() - t0);
    }
  }
  std::sort(ms.begin(), ms.end());
  state.counters["median_cpu_ms_per_condition"] = ms[ms.size() / 2];
  state.counters["max_cpu_ms_per_condition"] = ms.back();
}
BENCHMARK(SineConditionLogSweep)->Arg(1)->Arg(0)->Iterations(3)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// state.range(0): 1 = the exponential integrator (rectification/simulation/discretised.hpp),
// 0 = CVODE (ShakeSettings::exponential_integrator = false); state.range(1): seconds measured.
void RandomGevs20kHz(benchmark::State& state) {
  const plant::PlantConfig cfg = default_plant();
  const vibration::RandomExcitation ex(bench::gevs_along_ia(), 16000, 1);
  rectification::ShakeSettings s;
  s.relative_tolerance = 1e-4;
  s.readout.sample_rate_Hz = 20000;
  s.blocks = 16;
  s.exponential_integrator = state.range(0) != 0;
  const double measure_s = static_cast<double>(state.range(1));
  double simulated = 0, cpu_ms = 0;
  for (auto _ : state) {
    const double t0 = thread_cpu_ms();
    const auto r = rectification::shake_excitation(cfg, Vec3(0.5, std::sqrt(0.75), 0), ex, measure_s, s);
    benchmark::DoNotOptimize(r.measured_g);
    cpu_ms += thread_cpu_ms() - t0;
    simulated += r.simulated_s;
  }
  state.counters["simulated_s_per_cpu_s"] = simulated / (1e-3 * cpu_ms);
}
BENCHMARK(RandomGevs20kHz)->Args({1, 60})->Args({0, 4})->Iterations(3)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

void CvodeJacobian(benchmark::State& state) {
  plant::PlantConfig cfg = default_plant();
  const int which = static_cast<int>(state.range(0));
  if (which == 1 || which == 2) {
    cfg.effects.push_back(std::make_shared<plant::PendulumGeometry>());
    cfg.effects.push_back(std::make_shared<plant::PickoffNonlinearity>(20.0));
  }
  if (which == 1) {
    const double b = cfg.dynamics.angle_gain_rad_per_s2_per_g;
    cfg.effects.push_back(std::make_shared<plant::SqueezeFilmDamping>(5e-3, 2 * 0.3 * 2 * 3.141592653589793 * 50, b));
  }
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  rectification::ShakeSettings s;
  s.analytic_jacobian = state.range(1) != 0;
  s.periodic_steady_state = false;
  double cpu_ms = 0, rhs = 0, steps = 0, runs = 0;
  const vibration::RandomExcitation ex(bench::gevs_along_ia(), 16000, 1);
  for (auto _ : state) {
    const double t0 = thread_cpu_ms();
    rectification::ShakeResult r;
    if (which == 2) {
      rectification::ShakeSettings sr = s;
      sr.relative_tolerance = 1e-4;
      sr.blocks = 16;
      r = rectification::shake_excitation(cfg, a, ex, 2.0, sr);
    } else {
      vibration::SineVibration v;
      v.amplitude_g = Vec3(5, 0, 0);
      v.frequency_Hz = which == 3 ? 1000.0 : 2.0;
      r = rectification::shake_sine(cfg, a, v, s);
    }
    benchmark::DoNotOptimize(r.measured_g);
    cpu_ms += thread_cpu_ms() - t0;
    rhs += static_cast<double>(r.rhs_evaluations);
    steps += static_cast<double>(r.steps);
    runs += 1;
  }
  state.counters["cpu_ms_per_run"] = cpu_ms / runs;
  state.counters["rhs_per_run"] = rhs / runs;
  state.counters["steps_per_run"] = steps / runs;
}
BENCHMARK(CvodeJacobian)
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}})
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

}  // namespace

BENCHMARK_MAIN();
