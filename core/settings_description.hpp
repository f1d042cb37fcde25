#pragma once
// core/settings_description.hpp -- a settings struct described once, for every reader and
// writer of it (in the manner of Drake's serialisable configs).
//
// A struct S lists its fields in one static member template
//     template <class V> static void Describe(V& v) {
//       v(core::field("threshold_sigma", &S::threshold_sigma, "sigma", core::above(0), "help"));
//       ...
//     }
// each with its name (the TOML key, the JSON key, the Python keyword; the CLI flag is the name
// with '-' for '_'), its member, its unit ("" for a pure number), its range and a help text.
// The default is the member's initialiser (S{}). A visitor is any callable taking each Field
// (a generic lambda); a field whose type is itself described (has Describe) is a nested table.
//
// This header gives what needs no file format: validate (IsValid from the ranges, the
// message naming the field, its value and the rule), format_value, field lookup by member,
// and Overrides<S> (fields set on top of other settings, e.g. from a command line). The
// adapters to TOML, JSON, CLI11 and Python live with those libraries and iterate Describe.
// Standard library only.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

namespace vrelab::core {

// A range of admissible values; each bound absent, closed or open.
struct Range {
  bool has_min = false, has_max = false;
  bool min_open = false, max_open = false;
  double min = 0, max = 0;

  bool contains(double x) const {
    if (has_min && !(min_open ? x > min : x >= min)) return false;
    if (has_max && !(max_open ? x < max : x <= max)) return false;
    return true;
  }
};
inline Range any_value() { return {}; }
inline Range above(double a) { return {true, false, true, false, a, 0}; }     // (a, inf)
inline Range at_least(double a) { return {true, false, false, false, a, 0}; }  // [a, inf)
inline Range closed(double a, double b) { return {true, true, false, false, a, b}; }       // [a, b]
inline Range closed_open(double a, double b) { return {true, true, false, true, a, b}; }   // [a, b)
inline Range open_closed(double a, double b) { return {true, true, true, false, a, b}; }   // (a, b]

// One field of S of type T.
template <class S, class T>
struct Field {
  using Struct = S;
  using Type = T;
  std::string_view name;
  T S::*member;
  std::string_view unit;   // "" for a pure number, a fraction, a flag or a nested table
  Range range;
  std::string_view help;
  std::string_view alias;  // another CLI flag name; for a bool the one that sets the non-default
};

template <class S, class T>
Field<S, T> field(std::string_view name, T S::*member, std::string_view unit, Range range, std::string_view help,
                  std::string_view alias = {}) {
  return {name, member, unit, range, help, alias};
}

struct AnyVisitor {
  template <class F>
  void operator()(const F&) const {}
};
// True when T lists its fields (a nested table when a field's type).
template <class T>
concept Described = requires(AnyVisitor& v) { T::Describe(v); };

// Calls f(field) for each field of S, in the order Describe lists them.
template <class S, class F>
void for_each_field(F&& f) {
  S::Describe(f);
}

// The value as text: the shortest that reads back to it (precision 0) or printf's %.Ng.
template <class T>
std::string format_value(const T& x, int precision = 0) {
  if constexpr (std::is_same_v<T, bool>) {
    return x ? "true" : "false";
  } else if constexpr (std::is_floating_point_v<T>) {
    char buf[64];
    if (precision > 0) {
      std::snprintf(buf, sizeof buf, "%.*g", precision, x);
      return buf;
    }
    // Fixed notation for decimal exponents -4..15, scientific beyond (as fmt's "{}").
    const auto sci = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::scientific);
    const std::string s(buf, sci.ptr);
    const std::size_t e = s.find('e');
    const int exponent = e == std::string::npos ? 0 : std::atoi(s.c_str() + e + 1);
    if (e == std::string::npos || exponent < -4 || exponent >= 16) return s;
    const auto fixed = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::fixed);
    return std::string(buf, fixed.ptr);
  } else {
    return std::to_string(x);
  }
}

// The range as a rule: "a positive number of sigma", "in [0, 1)", ">= 2 Hz".
inline std::string range_text(const Range& r, std::string_view unit) {
  std::string t;
  if (r.has_min && r.has_max) {
    t += "in ";
    t += r.min_open ? '(' : '[';
    t += format_value(r.min);
    t += ", ";
    t += format_value(r.max);
    t += r.max_open ? ')' : ']';
  } else if (r.has_min && r.min == 0) {
    t += r.min_open ? "a positive number" : "a non-negative number";
    if (!unit.empty()) t += " of";
  } else if (r.has_min || r.has_max) {
    t += r.has_min ? (r.min_open ? "> " : ">= ") : (r.max_open ? "< " : "<= ");
    t += format_value(r.has_min ? r.min : r.max);
  } else {
    return "any value";
  }
  if (!unit.empty()) {
    t += ' ';
    t += unit;
  }
  return t;
}

// Whether x is admissible for f: in its range and, for a floating-point field with a range,
// finite.
template <class F>
bool admissible(const F& f, const typename F::Type& x) {
  using T = typename F::Type;
  if constexpr (std::is_same_v<T, bool>) {
    return true;
  } else if constexpr (std::is_arithmetic_v<T>) {
    const bool bounded = f.range.has_min || f.range.has_max;
    if constexpr (std::is_floating_point_v<T>)
      if (bounded && !std::isfinite(x)) return false;
    return f.range.contains(static_cast<double>(x));
  } else {
    return true;
  }
}

// "name = value: must be RULE", the message of a value out of its field's range.
template <class F>
std::string range_error(const F& f, const typename F::Type& x) {
  return std::string(f.name) + " = " + format_value(x) + ": must be " + range_text(f.range, f.unit);
}

// True when each field of s is in its range (nested tables checked through their own
// IsValid, the message prefixed "name."); else false with *why the first field's message.
template <class S>
bool validate(const S& s, std::string* why) {
  std::string w;
  for_each_field<S>([&](const auto& f) {
    if (!w.empty()) return;
    using T = typename std::decay_t<decltype(f)>::Type;
    const T& x = s.*f.member;
    if constexpr (Described<T>) {
      std::string inner;
      if (!x.IsValid(&inner)) w = std::string(f.name) + "." + inner;
    } else if (!admissible(f, x)) {
      w = range_error(f, x);
    }
  });
  if (why) *why = w;
  return w.empty();
}

// The index of the field whose member is m, in Describe's order (-1: none).
template <class S, class T>
int field_index(T S::*m) {
  int i = 0, found = -1;
  for_each_field<S>([&](const auto& f) {
    using U = typename std::decay_t<decltype(f)>::Type;
    if constexpr (std::is_same_v<U, T>)
      if (f.member == m) found = i;
    ++i;
  });
  return found;
}

template <class S>
int field_count() {
  int n = 0;
  for_each_field<S>([&](const auto&) { ++n; });
  return n;
}

// Fields set on top of other settings (a command line's, a Python call's): each one set wins.
template <class S>
class Overrides {
 public:
  template <class T, class U>
  void set(T S::*m, U&& value) {
    const int i = field_index(m);
    if (i < 0 || i >= 64) throw std::logic_error("Overrides::set: a member not in the description (or past 64 fields)");
    values_.*m = static_cast<T>(std::forward<U>(value));
    given_ |= std::uint64_t{1} << i;
  }
  bool given(int index) const { return (given_ >> index) & 1u; }
  bool any() const { return given_ != 0; }
  const S& values() const { return values_; }
  // s with the fields set here replaced.
  void apply(S& s) const {
    int i = 0;
    for_each_field<S>([&](const auto& f) {
      if (given(i++)) s.*f.member = values_.*f.member;
    });
  }

 private:
  S values_{};
  std::uint64_t given_ = 0;
};

}  // namespace vrelab::core
