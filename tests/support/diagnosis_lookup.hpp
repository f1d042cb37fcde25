#pragma once
// Test support: a campaign's run by its id, a fitted effect's parameter by its name (both throw
// when there is none, so a test's ASSERT cannot read past the end).
#include <stdexcept>
#include <string>

#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::test {

inline const validation::RunRecord& run_with_id(const validation::Campaign& c, const std::string& id) {
  for (const auto& r : c.runs)
    if (r.id == id) return r;
  throw std::runtime_error("no run " + id);
}

inline const validation::FittedParameter& parameter_named(const validation::EffectFit& e, const std::string& name) {
  for (const validation::FittedParameter& q : e.parameters)
    if (q.name == name) return q;
  throw std::logic_error(e.name + " has no parameter " + name);
}

}  // namespace vrelab::test
