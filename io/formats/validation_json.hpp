#pragma once
// io/formats/validation_json.hpp -- JsonValue (io/formats/settings_json.hpp) for the
// validation layer's field types, so a settings struct holding them is written and read back
// by its description.
//
// FixedSet: {name: value} for each coefficient held fixed (the names of plant/model1.hpp),
// the others absent; an unknown name or a value that is not a number is refused by name.
// Position: {"series", "angle_rad", "nominal_g"} (series 0: a position given as a vector).
// NamedVector: {"name", "vector"}. A list of either is an array (settings_json.hpp).
#include <cstdint>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "io/formats/settings_json.hpp"
#include "plant/model1.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"
#include "validation/reproduce/reproduce.hpp"

namespace vrelab::io {

namespace validation_json_internal {
inline nlohmann::json vec3(const Vec3& v) { return nlohmann::json::array({v[0], v[1], v[2]}); }
// v from j, an array of 3 numbers; else std::invalid_argument naming `key`.
inline void vec3_from(const nlohmann::json& j, const char* key, Vec3& v) {
  if (!j.is_array() || j.size() != 3) throw std::invalid_argument(std::string(key) + ": expected an array of 3 numbers");
  for (std::size_t i = 0; i < 3; ++i) {
    if (!j[i].is_number()) throw std::invalid_argument(std::string(key) + ": expected an array of 3 numbers");
    v[static_cast<int>(i)] = j[i].get<double>();
  }
}
// j's member `key`, which must be there; else std::invalid_argument naming it.
inline const nlohmann::json& member(const nlohmann::json& j, const char* key) {
  if (!j.is_object() || !j.contains(key)) throw std::invalid_argument(std::string("expected an object with '") + key + "'");
  return j.at(key);
}
}  // namespace validation_json_internal

template <>
struct JsonValue<validation::Position> {
  static nlohmann::json to(const validation::Position& p) {
    return {{"series", p.series}, {"angle_rad", p.angle_rad}, {"nominal_g", validation_json_internal::vec3(p.nominal_g)}};
  }
  static void from(const nlohmann::json& j, validation::Position& p) {
    using namespace validation_json_internal;
    validation::Position out;
    const nlohmann::json& s = member(j, "series");
    if (!s.is_number_integer() || s.get<std::int64_t>() < 0 || s.get<std::int64_t>() > 3)
      throw std::invalid_argument("series: expected 0 (a vector), 1, 2 or 3");
    out.series = s.get<int>();
    const nlohmann::json& a = member(j, "angle_rad");
    if (!a.is_number()) throw std::invalid_argument("angle_rad: expected a number");
    out.angle_rad = a.get<double>();
    vec3_from(member(j, "nominal_g"), "nominal_g", out.nominal_g);
    p = out;
  }
};

template <>
struct JsonValue<validation::NamedVector> {
  static nlohmann::json to(const validation::NamedVector& x) {
    return {{"name", x.name}, {"vector", validation_json_internal::vec3(x.v)}};
  }
  static void from(const nlohmann::json& j, validation::NamedVector& x) {
    using namespace validation_json_internal;
    validation::NamedVector out;
    const nlohmann::json& n = member(j, "name");
    if (!n.is_string()) throw std::invalid_argument("name: expected a string");
    out.name = n.get<std::string>();
    vec3_from(member(j, "vector"), "vector", out.v);
    x = out;
  }
};

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
