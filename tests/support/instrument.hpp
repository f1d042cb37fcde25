#pragma once
// The tests' instruments, defined once: the paper-like instrument (the shipped case's
// coefficients, cases/paper-static.toml, with k_PP = k_OO = 0) and its linear form (its
// scale factor K1 = 1.25 and no other term of model (1)), to which a test adds the terms it
// studies. A test whose values differ on purpose keeps its own; the case files written by
// tests (TOML text) spell their coefficients out as a case file does.
#include "plant/accelerometer.hpp"
#include "plant/model1.hpp"

namespace vrelab::test {

inline plant::Coefficients paper_like_coefficients() {
  plant::Coefficients c;
  c[plant::K1] = 1.25, c[plant::k0] = 1.5e-3, c[plant::k1_asym] = 2e-5, c[plant::k2] = 1.5e-5, c[plant::k3] = 1e-6;
  c[plant::k4] = 2e-7, c[plant::delta_OA] = 1e-4, c[plant::delta_PA] = -5e-5, c[plant::k_IP] = 8e-6;
  c[plant::k_IO] = -5e-6, c[plant::k_PO] = 3e-6;
  return c;
}

// The paper-like instrument with the default dynamics (from_coefficients, no effects).
inline plant::PlantConfig paper_like_plant() {
  plant::PlantConfig p;
  p.coefficients = paper_like_coefficients();
  return p;
}

// The paper-like instrument's scale factor alone: a plant that does not rectify.
inline plant::PlantConfig paper_like_linear_plant() {
  plant::PlantConfig p;
  p.coefficients[plant::K1] = paper_like_coefficients()[plant::K1];
  return p;
}

}  // namespace vrelab::test
