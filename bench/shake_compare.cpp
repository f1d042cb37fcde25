// Accuracy of shake_sine's periodic-steady-state paths against its transient path (the
// settle-then-measure integration that main's shake does), per condition: prints
// f, transient, steady-state, difference (g), path, shooting iterations, steps of each.
// Run: build/vrelab_shake_compare [k2|paper|squeeze] [amplitude_g] [points] [transient path's rtol] [one frequency]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "plant/effects/squeeze_film_damping.hpp"
#include "rectification/simulation/shake.hpp"

using namespace vrelab;

int main(int argc, char** argv) {
  const std::string which = argc > 1 ? argv[1] : "k2";
  const double amp = argc > 2 ? std::atof(argv[2]) : 5.0;
  plant::PlantConfig cfg;
  cfg.coefficients[plant::K1] = 1.25;
  if (which == "k2") {
    cfg.coefficients[plant::k0] = 1.5e-3;
    cfg.coefficients[plant::k2] = 1.5e-5;
  } else if (which == "paper") {
    cfg.coefficients[plant::k0] = 1.5e-3, cfg.coefficients[plant::k1_asym] = 2e-5, cfg.coefficients[plant::k2] = 1.5e-5;
    cfg.coefficients[plant::k3] = 1e-6, cfg.coefficients[plant::k4] = 2e-7, cfg.coefficients[plant::delta_OA] = 1e-4;
    cfg.coefficients[plant::delta_PA] = -5e-5, cfg.coefficients[plant::k_IP] = 8e-6;
  } else if (which == "squeeze") {
    const plant::Dynamics& d = cfg.dynamics;
    const double c0 = 2 * d.pendulum_damping_ratio * 2 * M_PI * d.pendulum_frequency_Hz;
    cfg.effects.push_back(std::make_shared<plant::SqueezeFilmDamping>(1.1e-3, c0, d.angle_gain_rad_per_s2_per_g));
  }
  const Vec3 a = which == "squeeze" ? Vec3(Vec3(1, 0, 1).normalized()) : Vec3(0.5, std::sqrt(0.75), 0);
  rectification::ShakeSettings old_path;
  old_path.periodic_steady_state = false;
  if (argc > 4) old_path.relative_tolerance = std::atof(argv[4]);
  double worst = 0;
  const int n = argc > 3 ? std::atoi(argv[3]) : 100;
  for (int i = 0; i < n; ++i) {
    vibration::SineVibration v;
    v.amplitude_g = Vec3(amp, 0, 0);
    v.frequency_Hz = argc > 5 ? std::atof(argv[5]) : std::pow(10.0, std::log10(5000.0) * i / (n - 1.0));
    const auto o = rectification::shake_sine(cfg, a, v, old_path);
    const auto p = rectification::shake_sine(cfg, a, v);
    worst = std::max(worst, std::abs(p.measured_g - o.measured_g));
    std::printf("%9.3f %.12e %.12e %+.2e %-20s %d %6ld %6ld\n", v.frequency_Hz, o.measured_g, p.measured_g,
                p.measured_g - o.measured_g, p.path.c_str(), p.shooting_iterations, o.steps, p.steps);
  }
  std::printf("max |difference| %.3e g\n", worst);
}
