// Uses the installed vrelab: model (1)'s output and eq. (3)'s vibration error of a k2
// instrument under a 3 g sine along IA, k2 A^2 / 2 = 6.75e-5 g (checked here, exit 1 if not).
#include <cmath>
#include <cstdio>

#include "io/formats/output.hpp"
#include "plant/model1.hpp"
#include "rectification/prediction/eq3.hpp"
#include "vrelab_version.hpp"

int main() {
  using namespace vrelab;
  plant::Coefficients c;
  c[plant::K1] = 1.25;
  c[plant::k2] = 1.5e-5;
  const Vec3 a_g(1, 0, 0);
  vibration::SineVibration v;
  v.amplitude_g = Vec3(3, 0, 0);
  v.frequency_Hz = 100;
  const double u = plant::output(c, a_g);
  const double e = rectification::sine_rectification(c, a_g, v).total_g();
  std::printf("vrelab %s (%s)\n", kProgramVersion, io::program_record().at("git").get<std::string>().c_str());
  std::printf("model (1) output at 1 g along IA: %.12g\n", u);
  std::printf("eq. (3) vibration error, 3 g sine along IA: %.12g g\n", e);
  const bool ok = std::abs(u - 1.25 * (1 + 1.5e-5)) < 1e-14 && std::abs(e - 1.5e-5 * 9 / 2) < 1e-15;
  std::printf("%s\n", ok ? "consumer: ok" : "consumer: WRONG VALUES");
  return ok ? 0 : 1;
}
