#pragma once
// io/formats/settings_toml.hpp -- a described settings struct (core/settings_description.hpp)
// read from a TOML table: each key a field's name, of the field's type and in its range.
//
// read_settings_table(t, s, fail) sets the fields of s that t holds, leaving the others as
// they are; for an unknown key, a value of the wrong type or out of range it calls
// fail(node, key, what) (never returning: the caller throws its error, with its file, the
// node's line, its table and the key as data), `what` the sentence naming the key:
// "key: unknown key", "key: expected a number", "key = 1.5: must be in (0, 1]". A field whose type is described is a subtable, its keys
// named "field.key". Only for sources of vrelab_formats (toml++ is private to it).
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>

#include <toml++/toml.h>

#include "core/settings_description.hpp"

namespace vrelab::io {

template <class S, class Fail>
void read_settings_table(const toml::table& t, S& s, const Fail& fail) {
  for (auto&& [k, v] : t) {
    const std::string name(k.str());  // a copy: clang 14 cannot capture a structured binding
    bool known = false;
    core::for_each_field<S>([&](const auto& f) { known = known || f.name == name; });
    if (!known) fail(&v, name, name + ": unknown key");
  }
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    const toml::node* n = t.get(f.name);
    if (!n) return;
    const std::string key(f.name);
    T& x = s.*f.member;
    if constexpr (core::Described<T>) {
      if (!n->is_table()) fail(n, key, key + ": expected a table");
      read_settings_table(*n->as_table(), x, [&](const toml::node* m, const std::string& sub, const std::string& what) {
        fail(m, key + "." + sub, key + "." + what);
      });
    } else if constexpr (std::is_same_v<T, bool>) {
      if (!n->is_boolean()) fail(n, key, key + ": expected true or false");
      x = n->value<bool>().value();
    } else if constexpr (std::is_floating_point_v<T>) {
      if (!n->is_number()) fail(n, key, key + ": expected a number");
      const double d = n->value<double>().value();
      if (!std::isfinite(d)) fail(n, key, key + ": must be finite");
      if (!core::admissible(f, static_cast<T>(d))) fail(n, key, core::range_error(f, static_cast<T>(d)));
      x = static_cast<T>(d);
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
    } else {
      static_assert(sizeof(T) == 0, "read_settings_table: a field type TOML cannot hold");
    }
  });
}

}  // namespace vrelab::io
