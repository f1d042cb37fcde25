#pragma once
// io/formats/settings_toml.hpp -- a described settings struct (core/settings_description.hpp)
// read from a TOML table: each key a field's name, of the field's type and in its range.
//
// read_settings_table(t, s, fail) sets the fields of s that t holds, leaving the others as
// they are; for an unknown key, a value of the wrong type or out of range it calls
// fail(node, key, what) (never returning: the caller throws its error, with its file, the
// node's line, its table and the key as data), `what` the sentence naming the key:
// "key: unknown key", "key: expected a number", "key = 1.5: must be in (0, 1]". A field whose
// type is described is a subtable, its keys named "field.key". A field set_by elsewhere is no
// key; a scaled field's key holds the written value (the member gets it times the scale).
//
// read_settings_fields does the same without the unknown-key check, for a table whose keys
// several descriptions share (check_settings_keys<S1, S2>, the union, subtables included).
// Only for sources of vrelab_formats (toml++ is private to it).
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <toml++/toml.h>

#include "core/settings_description.hpp"

namespace vrelab::io {

// fail(node, key, "key: unknown key") for a key of t that none of S... describes; a subtable
// that one of them describes is checked likewise against the union of its keys (its keys
// named "table.key"). `path`: the subtable's place below the descriptions' own tables.
template <class... S, class Fail>
void check_settings_keys(const toml::table& t, const Fail& fail, const std::vector<std::string>& path = {}) {
  std::vector<core::TableKey> keys;
  (core::append_table_keys<S>(path, &keys), ...);
  std::string prefix;
  for (const std::string& p : path) prefix += p + ".";
  for (auto&& [k, v] : t) {
    const std::string name(k.str());
    bool known = false, table = false;
    for (const core::TableKey& key : keys)
      if (key.name == name) known = true, table = table || key.table;
    if (!known) fail(&v, prefix + name, prefix + name + ": unknown key");
    if (table && v.is_table()) {
      std::vector<std::string> sub = path;
      sub.push_back(name);
      check_settings_keys<S...>(*v.as_table(), fail, sub);
    }
  }
}

namespace settings_toml_internal {
// A finite number at n, else fail (the sentence naming `what`: the key, or an entry of it).
template <class Fail>
double finite_number(const toml::node* n, const std::string& key, const Fail& fail, const std::string& what) {
  if (!n->is_number()) fail(n, key, what + ": expected a number");
  const double d = n->value<double>().value();
  if (!std::isfinite(d)) fail(n, key, what + ": must be finite");
  return d;
}
template <class Fail>
double finite_number(const toml::node* n, const std::string& key, const Fail& fail) {
  return finite_number(n, key, fail, key);
}
}  // namespace settings_toml_internal

template <class S, class Fail>
void read_settings_fields(const toml::table& t, S& s, const Fail& fail) {
  using settings_toml_internal::finite_number;
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    if (!f.in_table()) return;
    const toml::node* n = t.get(f.name);
    if (!n) return;
    const std::string key(f.name);
    T& x = s.*f.member;
    if constexpr (core::Described<T>) {
      if (!n->is_table()) fail(n, key, key + ": expected a table");
      const auto sub_fail = [&](const toml::node* m, const std::string& sub, const std::string& what) {
        fail(m, key + "." + sub, key + "." + what);
      };
      read_settings_fields(*n->as_table(), x, sub_fail);
    } else if constexpr (std::is_same_v<T, bool>) {
      if (!n->is_boolean()) fail(n, key, key + ": expected true or false");
      x = n->value<bool>().value();
    } else if constexpr (std::is_floating_point_v<T>) {
      const double d = finite_number(n, key, fail);
      if (!core::admissible_value(f, static_cast<T>(d))) fail(n, key, core::range_error_written(f, static_cast<T>(d)));
      x = core::held(f, static_cast<T>(d));
    } else if constexpr (std::is_integral_v<T>) {
      const std::string whole = key + ": expected a whole number" + (f.unit.empty() ? "" : " of " + std::string(f.unit));
      if (!n->is_integer()) fail(n, key, whole);
      const std::int64_t i = n->value<std::int64_t>().value();
      if (std::is_unsigned_v<T> && i < 0) fail(n, key, whole + ", not negative");
      if constexpr (sizeof(T) < sizeof(std::int64_t))
        if (i > static_cast<std::int64_t>(std::numeric_limits<T>::max()) ||
            i < static_cast<std::int64_t>(std::numeric_limits<T>::min()))
          fail(n, key, whole + " that fits");
      if (!core::admissible(f, static_cast<T>(i))) fail(n, key, core::range_error(f, static_cast<T>(i)));
      x = static_cast<T>(i);
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!n->is_string()) fail(n, key, key + ": expected a string");
      x = n->value<std::string>().value();
    } else if constexpr (core::is_number_list<T>) {
      const toml::array* a = n->as_array();
      if (!a || a->empty()) fail(n, key, key + ": expected a non-empty array of numbers");
      T w;
      for (auto&& e : *a) {
        w.push_back(finite_number(&e, key, fail));
        if (!core::admissible_value(f, w.back())) fail(&e, key, core::range_error_written(f, w));
      }
      x = core::held(f, w);
    } else if constexpr (core::FixedVector<T>) {
      constexpr int kSize = T::SizeAtCompileTime;
      const toml::array* a = n->as_array();
      if (!a || static_cast<int>(a->size()) != kSize)
        fail(n, key, key + ": expected an array of " + std::to_string(kSize) + " numbers" + (kSize == 3 ? " [IA, PA, OA]" : ""));
      T w;
      for (int i = 0; i < kSize; ++i) w[i] = finite_number(a->get(static_cast<std::size_t>(i)), key, fail);
      if (!core::admissible_value(f, w)) fail(n, key, core::range_error_written(f, w));
      x = w;
    } else if constexpr (core::is_vector_list<T>) {
      using V = typename T::value_type;
      constexpr int kSize = V::SizeAtCompileTime;
      const std::string vector = "an array of " + std::to_string(kSize) + " numbers" + (kSize == 3 ? " [IA, PA, OA]" : "");
      const toml::array* a = n->as_array();
      if (!a || a->empty()) fail(n, key, key + ": expected a non-empty array, each entry " + vector);
      T w;
      for (auto&& e : *a) {
        const toml::array* ea = e.as_array();
        const std::string at = key + "[" + std::to_string(w.size()) + "]";
        if (!ea || static_cast<int>(ea->size()) != kSize) fail(&e, key, at + ": expected " + vector);
        V v;
        for (int i = 0; i < kSize; ++i) v[i] = finite_number(ea->get(static_cast<std::size_t>(i)), key, fail, at);
        w.push_back(v);
        if (!core::admissible_value(f, w)) fail(&e, key, core::range_error_written(f, w));
      }
      x = w;
    } else if constexpr (core::is_string_list<T>) {
      const toml::array* a = n->as_array();
      if (!a || a->empty()) fail(n, key, key + ": expected a non-empty array of strings");
      T w;
      for (auto&& e : *a) {
        if (!e.is_string()) fail(&e, key, key + "[" + std::to_string(w.size()) + "]: expected a string");
        w.push_back(e.value<std::string>().value());
      }
      x = w;
    } else {
      // A type of its own (a position, a named vector): only a field set_by elsewhere, never a key.
      throw std::logic_error("read_settings_fields: " + key + " is of a type TOML cannot hold; it must be set_by");
    }
  });
}

template <class S, class Fail>
void read_settings_table(const toml::table& t, S& s, const Fail& fail) {
  check_settings_keys<S>(t, fail);
  read_settings_fields(t, s, fail);
}

}  // namespace vrelab::io
