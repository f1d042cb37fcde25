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
// A field's type: bool, an integer, a floating-point number, a string, a list of numbers
// (std::vector<double>, the range applying to each), a fixed-size vector (Eigen's Vec3,
// written [IA, PA, OA]), a list of such vectors (std::vector<Vec3>, the range applying to each
// element), a list of strings, an array of optional numbers
// (std::array<std::optional<double>, N>, e.g. the coefficients held fixed; the range applying
// to each one set) or a described struct (a nested table: [table.field] in TOML, an object in
// JSON; several descriptions may share it, as they share a table).
// A type of its own (a position, a named vector) is a field too where the adapter that
// writes it has a converter for it (io/formats/settings_json.hpp's JsonValue); its range is
// any_value and its checks are the struct's IsValid's.
//
// Where the file does not hold the member as it is, the description still says so, once:
//  - .scaled(k): the member holds the value as written times k (a [readout] states noise in
//    ug, the struct holds g: scaled(1e-6); numbers and lists); the name, unit and range are
//    the written ones, and the readers and writers (TOML, JSON, CLI) use the written value;
//  - .set_by("..."): the member is not a key of the struct's table (nor a flag or keyword):
//    another table or a reader's conversion sets it (a grid from from_Hz/to_Hz/points, the
//    readout's seed from [run] seed), as the text says; it is still recorded and validated.
// A scale keeps every adapter the same code; a derived field that is a function of several
// keys (a frequency grid) is better described by a small "as written" struct of those keys
// with one conversion function beside the settings (e.g. FrequencyGrid beside
// FrequencyStudySettings): the keys stay plain fields and the conversion has one home.
//
// This header gives what needs no file format: validate (IsValid from the ranges, the
// message naming the field, its value and the rule), format_value, field lookup by member,
// and Overrides<S> (fields set on top of other settings, e.g. from a command line). The
// adapters to TOML, JSON, CLI11 and Python live with those libraries and iterate Describe.
// Standard library only.
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

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
inline Range open(double a, double b) { return {true, true, true, true, a, b}; }           // (a, b)
// Any finite number: bounded by the infinities, so admissible_value refuses inf and NaN.
inline Range finite() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  return {true, true, false, false, -inf, inf};
}

// A fixed-size vector of doubles (Eigen's Vec3), known without including Eigen.
template <class T>
concept FixedVector = requires(const T& v) {
  T::SizeAtCompileTime;
  v[0];
} && (T::SizeAtCompileTime > 0);
template <class T>
inline constexpr bool is_number_list = std::is_same_v<T, std::vector<double>>;
// A list of fixed-size vectors ([[IA, PA, OA], ...]).
template <class T>
inline constexpr bool is_vector_list = false;
template <FixedVector V>
inline constexpr bool is_vector_list<std::vector<V>> = true;
template <class T>
inline constexpr bool is_string_list = std::is_same_v<T, std::vector<std::string>>;
// An array of optional numbers (a value per slot or none).
template <class T>
inline constexpr bool is_optional_numbers = false;
template <std::size_t N>
inline constexpr bool is_optional_numbers<std::array<std::optional<double>, N>> = true;

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
  double scale = 1;        // the member holds the written value times this (see the header's note)
  std::string_view set_by_text;  // non-empty: not a key of the table, set as this says

  Field scaled(double k) const {
    Field f = *this;
    f.scale = k;
    return f;
  }
  Field set_by(std::string_view how) const {
    Field f = *this;
    f.set_by_text = how;
    return f;
  }
  // A key of the struct's table (a flag, a keyword), not set from elsewhere.
  bool in_table() const { return set_by_text.empty(); }
};

// The member's value as written (in the field's unit) and back.
// A scaled value is written to 15 significant digits: x / k's last-bit noise dropped, so a
// value read from a file (w, held as w * k) is written as w again and reads back to x.
template <class F, class T>
T written(const F& f, const T& x) {
  if constexpr (std::is_floating_point_v<T>) {
    if (f.scale == 1) return x;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.15g", static_cast<double>(x / f.scale));
    return static_cast<T>(std::strtod(buf, nullptr));
  } else if constexpr (is_number_list<T>) {
    T w = x;
    for (double& e : w) e = written(f, e);
    return w;
  } else return x;
}
template <class F, class T>
T held(const F& f, const T& w) {
  if constexpr (std::is_floating_point_v<T>) return f.scale == 1 ? w : w * f.scale;
  else if constexpr (is_number_list<T>) {
    T x = w;
    for (double& e : x) e = held(f, e);
    return x;
  } else return w;
}

template <class S, class T>
Field<S, T> field(std::string_view name, T S::*member, std::string_view unit, Range range, std::string_view help,
                  std::string_view alias = {}) {
  return {name, member, unit, range, help, alias, 1, {}};
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
  } else if constexpr (is_number_list<T> || FixedVector<T>) {
    std::string t = "[";
    for (int i = 0; i < static_cast<int>(x.size()); ++i) t += (i ? ", " : "") + format_value(static_cast<double>(x[i]), precision);
    return t + "]";
  } else if constexpr (is_vector_list<T> || is_string_list<T>) {
    std::string t = "[";
    for (std::size_t i = 0; i < x.size(); ++i) t += (i ? ", " : "") + format_value(x[i], precision);
    return t + "]";
  } else if constexpr (is_optional_numbers<T>) {
    std::string t = "[";
    for (std::size_t i = 0; i < x.size(); ++i) t += (i ? ", " : "") + (x[i] ? format_value(*x[i], precision) : std::string("none"));
    return t + "]";
  } else if constexpr (std::is_same_v<T, std::string>) {
    return "\"" + x + "\"";
  } else if constexpr (std::is_arithmetic_v<T>) {
    return std::to_string(x);
  } else {
    return "(a value of its own type)";  // a type with a converter: never out of range here
  }
}

// The range as a rule: "a positive number of sigma", "in [0, 1)", ">= 2 Hz".
inline std::string range_text(const Range& r, std::string_view unit) {
  std::string t;
  if (r.has_min && r.has_max && std::isinf(r.min) && std::isinf(r.max)) {
    t += unit.empty() ? "a finite number" : "a finite number of";
  } else if (r.has_min && r.has_max) {
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

// Whether the written value w is admissible for f: in its range and, for a floating-point
// field with a range, finite; a list of numbers or a vector element by element.
template <class F, class T>
bool admissible_value(const F& f, const T& w) {
  if constexpr (std::is_same_v<T, bool>) {
    return true;
  } else if constexpr (std::is_arithmetic_v<T>) {
    const bool bounded = f.range.has_min || f.range.has_max;
    if constexpr (std::is_floating_point_v<T>)
      if (bounded && !std::isfinite(w)) return false;
    return f.range.contains(static_cast<double>(w));
  } else if constexpr (is_number_list<T> || FixedVector<T>) {
    for (int i = 0; i < static_cast<int>(w.size()); ++i)
      if (!admissible_value(f, static_cast<double>(w[i]))) return false;
    return true;
  } else if constexpr (is_vector_list<T>) {
    for (const auto& v : w)
      if (!admissible_value(f, v)) return false;
    return true;
  } else if constexpr (is_optional_numbers<T>) {
    for (const auto& e : w)
      if (e && !admissible_value(f, *e)) return false;
    return true;
  } else {
    return true;
  }
}
// Whether the member's value x is admissible for f (its written value in the range).
template <class F>
bool admissible(const F& f, const typename F::Type& x) {
  return admissible_value(f, written(f, x));
}

// "name = value: must be RULE", the message of a value out of its field's range (the value
// as written; a list's first element out of range as name[i], a list of vectors' as
// name[i][j]).
template <class F, class T>
std::string range_error_written(const F& f, const T& w) {
  if constexpr (is_number_list<T> || FixedVector<T>) {
    for (int i = 0; i < static_cast<int>(w.size()); ++i)
      if (!admissible_value(f, static_cast<double>(w[i])))
        return std::string(f.name) + "[" + std::to_string(i) + "] = " + format_value(static_cast<double>(w[i])) +
               ": must be " + range_text(f.range, f.unit);
    return std::string(f.name) + ": must be " + range_text(f.range, f.unit);
  } else if constexpr (is_vector_list<T>) {
    for (std::size_t i = 0; i < w.size(); ++i)
      for (int j = 0; j < static_cast<int>(w[i].size()); ++j)
        if (!admissible_value(f, static_cast<double>(w[i][j])))
          return std::string(f.name) + "[" + std::to_string(i) + "][" + std::to_string(j) +
                 "] = " + format_value(static_cast<double>(w[i][j])) + ": must be " + range_text(f.range, f.unit);
    return std::string(f.name) + ": must be " + range_text(f.range, f.unit);
  } else if constexpr (is_optional_numbers<T>) {
    for (std::size_t i = 0; i < w.size(); ++i)
      if (w[i] && !admissible_value(f, *w[i]))
        return std::string(f.name) + "[" + std::to_string(i) + "] = " + format_value(*w[i]) + ": must be " +
               range_text(f.range, f.unit);
    return std::string(f.name) + ": must be " + range_text(f.range, f.unit);
  } else {
    return std::string(f.name) + " = " + format_value(w) + ": must be " + range_text(f.range, f.unit);
  }
}
template <class F>
std::string range_error(const F& f, const typename F::Type& x) {
  return range_error_written(f, written(f, x));
}

// The names of S's fields that are keys of its table (not set_by), in Describe's order.
template <class S>
std::vector<std::string_view> table_keys() {
  std::vector<std::string_view> k;
  for_each_field<S>([&](const auto& f) {
    if (f.in_table()) k.push_back(f.name);
  });
  return k;
}

// A key of a described table: its name, and whether it is a table of its own (a field whose
// type is described).
struct TableKey {
  std::string_view name;
  bool table = false;
};
// The keys of the table that `path` names below S's (each element the name of a nested
// described field; empty: S's own table), appended to *out; none when S has no such table.
template <class S>
void append_table_keys(const std::vector<std::string>& path, std::vector<TableKey>* out, std::size_t depth = 0) {
  for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    if (!f.in_table()) return;
    if (depth == path.size()) {
      out->push_back({f.name, Described<T>});
    } else if constexpr (Described<T>) {
      if (f.name == path[depth]) append_table_keys<T>(path, out, depth + 1);
    }
  });
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
