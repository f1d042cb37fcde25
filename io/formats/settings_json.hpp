#pragma once
// io/formats/settings_json.hpp -- a described settings struct (core/settings_description.hpp)
// as a JSON object: every field by its name (a described field's as a nested object, a list
// or a vector as an array), set_by fields too, each value as written (a scaled field in its
// written unit).
//
// settings_from_json reads such an object back (the fields it holds; the others stay), so a
// record of the settings used can be read and run again; it throws std::invalid_argument
// naming the key for an unknown key or a value of the wrong type, and does not check ranges
// (the struct's IsValid does).
//
// A field of a type of its own (the coefficients held fixed, a position, a named vector) is
// written and read by JsonValue<T>, specialised beside the type's other io
// (io/formats/validation_json.hpp); a struct with such a field is written where that header
// is included (else a compile error names the type). A list of such a type is an array of
// their JSON values (JsonValue<std::vector<T>> here).
#include <concepts>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/settings_description.hpp"

namespace vrelab::io {

// JsonValue<T>::to(x) gives the JSON of x; JsonValue<T>::from(j, x) sets x from it, throwing
// std::invalid_argument saying what is wrong (the caller prefixes the key).
template <class T>
struct JsonValue;
template <class T>
concept HasJsonValue = requires(const T& x, T& y, const nlohmann::json& j) {
  { JsonValue<T>::to(x) } -> std::convertible_to<nlohmann::json>;
  JsonValue<T>::from(j, y);
};

// A list of a type with its own converter: an array of the values' JSON; an entry that does
// not read is named by its index.
template <class T>
  requires HasJsonValue<T>
struct JsonValue<std::vector<T>> {
  static nlohmann::json to(const std::vector<T>& x) {
    nlohmann::json j = nlohmann::json::array();
    for (const T& e : x) j.push_back(JsonValue<T>::to(e));
    return j;
  }
  static void from(const nlohmann::json& j, std::vector<T>& x) {
    if (!j.is_array()) throw std::invalid_argument("expected an array");
    std::vector<T> out(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
      try {
        JsonValue<T>::from(j[i], out[i]);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("[" + std::to_string(i) + "]: " + e.what());
      }
    }
    x = std::move(out);
  }
};

template <class S>
nlohmann::json settings_json(const S& s) {
  nlohmann::json j = nlohmann::json::object();
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    const T& x = s.*f.member;
    if constexpr (core::Described<T>) {
      j[std::string(f.name)] = settings_json(x);
    } else if constexpr (HasJsonValue<T>) {
      j[std::string(f.name)] = JsonValue<T>::to(x);
    } else if constexpr (core::FixedVector<T>) {
      nlohmann::json a = nlohmann::json::array();
      for (int i = 0; i < T::SizeAtCompileTime; ++i) a.push_back(x[i]);
      j[std::string(f.name)] = a;
    } else if constexpr (core::is_vector_list<T>) {
      nlohmann::json a = nlohmann::json::array();
      for (const auto& v : x) {
        nlohmann::json e = nlohmann::json::array();
        for (int i = 0; i < static_cast<int>(v.size()); ++i) e.push_back(v[i]);
        a.push_back(e);
      }
      j[std::string(f.name)] = a;
    } else {
      static_assert(std::is_arithmetic_v<T> || std::is_same_v<T, std::string> || core::is_number_list<T> ||
                        core::is_string_list<T>,
                    "settings_json: a field type without JsonValue<T> (include its io/formats header)");
      j[std::string(f.name)] = core::written(f, x);
    }
  });
  return j;
}

template <class S>
void settings_from_json(const nlohmann::json& j, S& s, const std::string& prefix = "") {
  if (!j.is_object()) throw std::invalid_argument(prefix + "settings: expected a JSON object");
  for (const auto& item : j.items()) {
    const std::string k = item.key();  // a copy: clang 14's lambdas cannot capture a structured binding
    bool known = false;
    core::for_each_field<S>([&](const auto& f) { known = known || f.name == k; });
    if (!known) throw std::invalid_argument(prefix + k + ": unknown key");
  }
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    const std::string key(f.name);
    if (!j.contains(key)) return;
    const nlohmann::json& v = j.at(key);
    T& x = s.*f.member;
    try {
      if constexpr (core::Described<T>) {
        settings_from_json(v, x, prefix + key + ".");
      } else if constexpr (HasJsonValue<T>) {
        try {
          JsonValue<T>::from(v, x);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(prefix + key + ": " + e.what());
        }
      } else if constexpr (core::FixedVector<T>) {
        if (!v.is_array() || static_cast<int>(v.size()) != T::SizeAtCompileTime) throw std::invalid_argument("size");
        for (int i = 0; i < T::SizeAtCompileTime; ++i) x[i] = v[static_cast<std::size_t>(i)].template get<double>();
      } else if constexpr (core::is_vector_list<T>) {
        using V = typename T::value_type;
        if (!v.is_array()) throw std::invalid_argument("type");
        T w(v.size());
        for (std::size_t r = 0; r < v.size(); ++r) {
          const nlohmann::json& e = v[r];
          if (!e.is_array() || static_cast<int>(e.size()) != V::SizeAtCompileTime) throw std::invalid_argument("size");
          for (int i = 0; i < V::SizeAtCompileTime; ++i) w[r][i] = e[static_cast<std::size_t>(i)].template get<double>();
        }
        x = w;
      } else {
        if constexpr (std::is_same_v<T, bool>) {
          if (!v.is_boolean()) throw std::invalid_argument("type");
        } else if constexpr (std::is_arithmetic_v<T>) {
          if (!v.is_number() || (std::is_integral_v<T> && !v.is_number_integer())) throw std::invalid_argument("type");
        }
        x = core::held(f, v.template get<T>());
      }
    } catch (const std::invalid_argument& e) {
      if (std::string(e.what()).find(": ") != std::string::npos) throw;  // a nested key's own message
      throw std::invalid_argument(prefix + key + ": a value of the wrong type or size");
    } catch (const nlohmann::json::exception&) {
      throw std::invalid_argument(prefix + key + ": a value of the wrong type or size");
    }
  });
}

}  // namespace vrelab::io
