#pragma once
// io/formats/case_file_internal.hpp -- what the case file's readers share (io/formats/case_file*.cpp):
// a TOML table with the keys it allows, the checks several tables make, and the readers of the
// tables that have their own file. Internal to the readers; the library's reader is case_file.hpp.
//
//   case_file.cpp            read_case, the shared checks, the static test, the studies, [campaign]
//   case_file_vibration.cpp  [vibration] (sine, random PSD, sine on random, swept sine), [shaker]
//   case_file_plant.cpp      [coefficients], [plant] (from coefficients or physical, effects),
//                            [readout], [shake]
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "io/formats/case_file.hpp"
#include "io/formats/settings_toml.hpp"

namespace vrelab::io::internal {

// The number of one-character edits from a to b (a key's closest allowed name).
std::size_t edit_distance(std::string_view a, std::string_view b);

// One TOML table with the keys it allows; every access marks the key as used.
class Table {
 public:
  Table(const toml::table& t, std::string name, const std::string& file)
      : t_(t), name_(std::move(name)), file_(file) {}

  bool has(std::string_view key) const { return t_.contains(key); }
  int line(const toml::node* n) const { return n ? static_cast<int>(n->source().begin.line) : 0; }

  // The key's place (the node's line, else the table's) and why it is wrong.
  [[noreturn]] void fail(const toml::node* n, std::string_view key, const std::string& what) const {
    throw FormatError({.file = file_, .line = line(n ? n : &t_), .table = name_, .key = std::string(key), .kind = KeyKind::toml_key},
                      what);
  }

  const toml::node* get(std::string_view key, bool required) {
    used_.insert(std::string(key));
    const toml::node* n = t_.get(key);
    if (!n && required) {
      // A required key missing is most often a typo of it (k_2 for k2, frequency_hz for
      // frequency_Hz): name the key the file has, on its line, with the match.
      for (auto&& [k, v] : t_) {
        const std::string have(k.str());
        if (used_.count(have)) continue;
        if (normalised(have) == normalised(key) || (key.size() > 3 && edit_distance(have, key) == 1))
          fail(&v, have, "unknown key (did you mean '" + std::string(key) + "'?); " + std::string(key) +
                             " is required");
      }
      fail(nullptr, key, "missing (required)");
    }
    return n;
  }
  // Lower case without '_' and '-': keys that differ only so are the same key mistyped.
  static std::string normalised(std::string_view k) {
    std::string out;
    for (char ch : k)
      if (ch != '_' && ch != '-') out += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return out;
  }

  double number_of(const toml::node* n, std::string_view key) const {
    if (!n->is_number()) fail(n, key, std::string("expected a number, got ") + type_name(*n));
    const double x = n->value<double>().value();
    if (!std::isfinite(x)) fail(n, key, "must be a finite number, got " + std::to_string(x));
    return x;
  }
  double number(std::string_view key) { return number_of(get(key, true), key); }
  std::optional<double> opt_number(std::string_view key) {
    const toml::node* n = get(key, false);
    return n ? std::optional<double>(number_of(n, key)) : std::nullopt;
  }
  double non_negative(std::string_view key, double fallback) {
    const auto x = opt_number(key);
    if (x && *x < 0) fail(t_.get(key), key, "must not be negative, got " + std::to_string(*x));
    return x.value_or(fallback);
  }
  std::int64_t integer(std::string_view key, bool required, std::int64_t fallback, std::int64_t min,
                       std::int64_t max = std::numeric_limits<std::int32_t>::max()) {
    const toml::node* n = get(key, required);
    if (!n) return fallback;
    if (!n->is_integer()) fail(n, key, std::string("expected an integer, got ") + type_name(*n));
    const std::int64_t v = n->as_integer()->get();
    if (v < min) fail(n, key, "must be at least " + std::to_string(min) + ", got " + std::to_string(v));
    if (v > max) fail(n, key, "must be at most " + std::to_string(max) + ", got " + std::to_string(v));
    return v;
  }
  std::string string(std::string_view key, std::string fallback) {
    const toml::node* n = get(key, false);
    if (!n) return fallback;
    if (!n->is_string()) fail(n, key, std::string("expected a string, got ") + type_name(*n));
    return n->as_string()->get();
  }
  Vec3 vec3_of(const toml::node* n, std::string_view key) const {
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) fail(n, key, "expected an array of 3 numbers [IA, PA, OA]");
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = number_of(a->get(static_cast<std::size_t>(i)), key);
    return v;
  }
  Vec3 vec3(std::string_view key) { return vec3_of(get(key, true), key); }
  std::optional<Vec3> opt_vec3(std::string_view key) {
    const toml::node* n = get(key, false);
    return n ? std::optional<Vec3>(vec3_of(n, key)) : std::nullopt;
  }
  std::optional<Table> subtable(std::string_view key, bool required) {
    const toml::node* n = get(key, required);
    if (!n) return std::nullopt;
    if (!n->is_table()) fail(n, key, std::string("expected a table, got ") + type_name(*n));
    return Table(*n->as_table(), name_.empty() ? std::string(key) : name_ + "." + std::string(key), file_);
  }

  // Any key not read is a typo or a key of another version: say so, with the closest match.
  void check_unknown(const std::vector<std::string_view>& allowed) const {
    for (auto&& [k, v] : t_) {
      const std::string key(k.str());
      if (used_.count(key)) continue;
      std::string best;
      std::size_t best_d = 4;
      for (auto a : allowed) {
        const std::size_t d = edit_distance(key, a);
        if (d < best_d) best_d = d, best = std::string(a);
      }
      std::string msg = "unknown key";
      if (!best.empty()) msg += " (did you mean '" + best + "'?)";
      fail(&v, key, msg);
    }
  }

  // The keys of t that the descriptions of S... hold, read into s... (core/settings_description.hpp,
  // io/formats/settings_toml.hpp): an unknown key fails with the closest match, a wrong type
  // or a value out of its range at the value's line, "[table] key = value: must be RULE". A
  // described subtable ([table.sub]) likewise, its keys the union of the descriptions' own.
  template <class... S>
  void read_described(S&... s) {
    check_described<S...>({});
    const auto fail = [&](const toml::node* n, const std::string& key, const std::string& what) {
      fail_described(n, key, what);
    };
    (read_settings_fields(t_, s, fail), ...);
  }

  // A struct's IsValid sentence, "key = value: must be ..." or "key: ...", at that key's line:
  // a nested key "sub.key" at its line in [table.sub], an entry "key[i]" at the entry's.
  [[noreturn]] void fail_sentence(const std::string& why) const {
    const std::string place = why.substr(0, why.find_first_of(" :"));
    const std::string key = place.substr(0, place.find('['));
    const toml::node* n = &t_;
    for (std::size_t from = 0; n && n->is_table() && from <= key.size();) {
      const std::size_t dot = std::min(key.find('.', from), key.size());
      n = n->as_table()->get(std::string_view(key).substr(from, dot - from));
      from = dot + 1;
    }
    for (std::size_t at = key.size(); n && n->is_array() && at < place.size() && place[at] == '[';) {
      const std::size_t i = std::strtoul(place.c_str() + at + 1, nullptr, 10);
      if (i >= n->as_array()->size()) break;
      n = n->as_array()->get(i);
      at = place.find(']', at) + 1;  // npos + 1 = 0: the loop ends
    }
    fail_described(n, key, why);
  }

  const toml::table& raw() const { return t_; }
  const std::string& name() const { return name_; }
  const std::string& file() const { return file_; }

 private:
  // Every key of this table, `path` below the descriptions' own tables, that one of S...
  // describes (else "unknown key" with the closest match); a described subtable's keys
  // likewise, in [table.sub].
  template <class... S>
  void check_described(const std::vector<std::string>& path) {
    std::vector<core::TableKey> keys;
    (core::append_table_keys<S>(path, &keys), ...);
    std::vector<std::string_view> allowed;
    for (const core::TableKey& k : keys) allowed.push_back(k.name), used_.insert(std::string(k.name));
    check_unknown(allowed);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const toml::node* n = t_.get(keys[i].name);
      bool first = true;  // a subtable several descriptions share is checked once
      for (std::size_t j = 0; j < i; ++j) first = first && !(keys[j].table && keys[j].name == keys[i].name);
      if (!keys[i].table || !first || !n || !n->is_table()) continue;
      std::vector<std::string> sub = path;
      sub.emplace_back(keys[i].name);
      Table(*n->as_table(), name_.empty() ? sub.back() : name_ + "." + sub.back(), file_).check_described<S...>(sub);
    }
  }
  // A described field's failure at n: a nested key "sub.key" (and the sentence naming it so)
  // written in its own table, "[table.sub] key ...".
  [[noreturn]] void fail_described(const toml::node* n, const std::string& key, const std::string& what) const {
    std::string table = name_, k = key, w = what;
    if (const std::size_t dot = key.rfind('.'); dot != std::string::npos) {
      const std::string sub = key.substr(0, dot);
      table = name_.empty() ? sub : name_ + "." + sub;
      k = key.substr(dot + 1);
      if (w.rfind(sub + ".", 0) == 0) w = w.substr(sub.size() + 1);
    }
    throw FormatError({.file = file_, .line = line(n ? n : &t_), .table = table, .key = k, .kind = KeyKind::toml_table}, w);
  }

  static const char* type_name(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a number";
      case toml::node_type::boolean: return "a boolean";
      case toml::node_type::array: return "an array";
      case toml::node_type::table: return "a table";
      default: return "a date or time";
    }
  }
  const toml::table& t_;
  std::string name_;
  std::string file_;
  std::set<std::string> used_;
};

// Model (1)'s coefficient i within its physical range (case_file.cpp), else FormatError at its key.
void check_coefficient(const Table& t, int i, double x);
// A vibration amplitude `a` of `key` within what a shaker can do (case_file.cpp), else FormatError.
void check_amplitude(const Table& t, std::string_view key, double a);

// The tables with a reader in a file of their own; each fills its part of the Case.
void read_vibration(Table t, Case& c);      // [vibration]  (case_file_vibration.cpp)
void read_shaker(Table t, Case& c);         // [shaker]     (case_file_vibration.cpp)
void read_coefficients(Table t, Case& c);   // [coefficients] (case_file_plant.cpp)
void read_plant(Table t, Case& c);          // [plant]      (case_file_plant.cpp)
void read_readout(Table t, Case& c);        // [readout]    (case_file_plant.cpp)
void read_shake(Table t, Case& c);          // [shake]      (case_file_plant.cpp)

}  // namespace vrelab::io::internal
