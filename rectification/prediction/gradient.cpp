#include "rectification/prediction/gradient.hpp"

namespace vrelab::rectification {
namespace {

constexpr int kRectifying[] = {plant::k1_asym, plant::k2,   plant::k3,   plant::k4,  plant::k_IP,
                               plant::k_IO,    plant::k_PO, plant::k_PP, plant::k_OO};

}  // namespace

std::array<double, plant::kNumCoefficients> prediction_gradient(const std::function<double(const plant::Coefficients&)>& f,
                                                               const plant::Coefficients& c) {
  plant::Coefficients zero = c;
  for (int i : kRectifying) zero[i] = 0.0;
  const double f0 = f(zero);
  std::array<double, plant::kNumCoefficients> g{};
  // The predictions are linear in these coefficients; the step only has to stay small
  // enough for the plant (a model (1) term of 1e-6 per g^n is a small nonlinearity).
  constexpr double h = 1e-6;
  for (int i : kRectifying) {
    plant::Coefficients one = zero;
    one[i] = h;
    g[i] = (f(one) - f0) / h;
  }
  return g;
}

}  // namespace vrelab::rectification
