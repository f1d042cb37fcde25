// The discretised random path (rectification/simulation/discretised.hpp) against CVODE on the
// same realisation: GEVS 20 Hz - 2 kHz along IA (14.1 g rms), the shipped random case's plant
// (cases/shake-random-gevs.toml), continuous integral or a readout at RATE Hz.
// Usage: vrelab_random_compare MEASURE_S RATE_HZ(0 = continuous) RTOL... ; prints measured,
// sigma and thread CPU per run, the exponential integrator first.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "rectification/simulation/shake.hpp"
#include "bench/gevs.hpp"
#include "vibration/sampled.hpp"

using namespace vrelab;

namespace {
double cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s MEASURE_S RATE_HZ [RTOL...]\n", argv[0]);
    return 2;
  }
  const double measure_s = std::atof(argv[1]), rate = std::atof(argv[2]);
  plant::PlantConfig cfg;
  const double c[] = {1.25, 1.5e-3, 2.0e-5, 1.5e-5, 1.0e-6, 2.0e-7, 1.0e-4, -5.0e-5, 8.0e-6, -5.0e-6, 3.0e-6, 4.0e-6, 0.0};
  const int idx[] = {plant::K1, plant::k0, plant::k1_asym, plant::k2, plant::k3, plant::k4, plant::delta_OA,
                     plant::delta_PA, plant::k_IP, plant::k_IO, plant::k_PO, plant::k_PP, plant::k_OO};
  for (int i = 0; i < 13; ++i) cfg.coefficients[idx[i]] = c[i];
  const vibration::RandomExcitation ex(bench::gevs_along_ia(), 16000, 1);
  const Vec3 a(0.5, std::sqrt(0.75), 0);
  auto run = [&](bool exponential, double rtol) {
    rectification::ShakeSettings s;
    s.relative_tolerance = rtol;
    s.blocks = 16;
    s.readout.sample_rate_Hz = rate;
    s.exponential_integrator = exponential;
    const double t0 = cpu_s();
    const auto r = rectification::shake_excitation(cfg, a, ex, measure_s, s);
    const double cpu = cpu_s() - t0;
    std::printf("%-24s rtol %-7.0e measured %.9e g  sigma %.3e g  steps %ld  cpu %.4f s  %.1f s/CPU s\n",
                r.path.c_str(), rtol, r.measured_g, r.sigma_g, r.steps, cpu, r.simulated_s / cpu);
    return r.measured_g;
  };
  const double e = run(true, 1e-4);
  for (int i = 3; i < argc; ++i) {
    const double m = run(false, std::atof(argv[i]));
    std::printf("  exponential - CVODE: %.3e g\n", e - m);
  }
  return 0;
}
