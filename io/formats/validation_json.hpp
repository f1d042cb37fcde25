#pragma once
// io/formats/validation_json.hpp -- JsonValue (io/formats/settings_json.hpp) for the
// validation layer's field types, so a settings struct holding them is written and read back
// by its description.
//
// FixedSet: {name: value} for each coefficient held fixed (the names of plant/model1.hpp),
// the others absent; an unknown name or a value that is not a number is refused by name.
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "io/formats/settings_json.hpp"
#include "plant/model1.hpp"
#include "validation/identification/identification.hpp"

namespace vrelab::io {

template <>
struct JsonValue<validation::FixedSet> {
  static nlohmann::json to(const validation::FixedSet& x) {
    nlohmann::json j = nlohmann::json::object();
    for (int i = 0; i < plant::kNumCoefficients; ++i)
      if (x[static_cast<std::size_t>(i)]) j[std::string(plant::coefficient_name(i))] = *x[static_cast<std::size_t>(i)];
    return j;
  }
  static void from(const nlohmann::json& j, validation::FixedSet& x) {
    if (!j.is_object()) throw std::invalid_argument("expected an object {coefficient: value}");
    validation::FixedSet out{};
    for (const auto& [k, v] : j.items()) {
      int index = -1;
      for (int i = 0; i < plant::kNumCoefficients; ++i)
        if (plant::coefficient_name(i) == k) index = i;
      if (index < 0) throw std::invalid_argument("'" + k + "' is not a coefficient");
      if (!v.is_number()) throw std::invalid_argument("'" + k + "': expected a number");
      out[static_cast<std::size_t>(index)] = v.get<double>();
    }
    x = out;
  }
};

}  // namespace vrelab::io
