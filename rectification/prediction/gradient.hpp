#pragma once
// rectification/prediction/gradient.hpp -- the gradient of a prediction in the coefficients of model (1).
//
// Takes: a prediction f (coefficients -> vibration error, g) that is linear in the rectifying
//        coefficients (k1_asym, k2, k3, k4, k_IP, k_IO, k_PO, k_PP, k_OO: eq. (3) and its
//        frequency-dependent forms are), and the coefficients c it is taken at.
// Gives: g_i = d f / d c_i for the rectifying coefficients (g per coefficient unit), as
//        f(c with only coefficient i = h) / h - f(c with none) over a small h; the other
//        entries 0 (f does not depend on them linearly, and the callers hold them).
#include <array>
#include <functional>

#include "plant/accelerometer.hpp"

namespace vrelab::rectification {

std::array<double, plant::kNumCoefficients> prediction_gradient(const std::function<double(const plant::Coefficients&)>& f,
                                                               const plant::Coefficients& c);

}  // namespace vrelab::rectification
