#pragma once
// app/settings_cli.hpp -- a described settings struct's fields (core/settings_description.hpp)
// as CLI11 flags: `--threshold-sigma S` for a field threshold_sigma, the help text, the range
// and the default from the description. A bool field gives `--name` (true) and `--no-name`
// (false), its alias (e.g. --no-pairs) naming the flag that sets the non-default. A field
// whose type is described (a nested table), a list, a vector or a field set from elsewhere
// (set_by) gets no flag; a scaled field's flag takes the value as written.
//
// add_override_flags sets a core::Overrides (the value given wins over a manifest's);
// add_settings_flags sets the struct itself. Ranges are not checked here: the struct's
// IsValid names the field, the value and the rule.
#include <string>
#include <type_traits>

#include <CLI/CLI.hpp>

#include "core/settings_description.hpp"

namespace vrelab::app {

template <class F>
std::string cli_flag(const F& f, bool negated = false) {
  std::string s(f.name);
  for (char& ch : s)
    if (ch == '_') ch = '-';
  return (negated ? "--no-" : "--") + s;
}

template <class F, class S>
std::string cli_help(const F& f, const S& defaults) {
  using T = typename F::Type;
  std::string h(f.help);
  if constexpr (!std::is_same_v<T, bool>) {
    const core::Range& r = f.range;
    if (r.has_min || r.has_max) h += "; " + core::range_text(r, f.unit);
  }
  return h + " (default " + core::format_value(core::written(f, defaults.*f.member)) + ")";
}

// set(field, value) for each flag given.
template <class S, class Set>
void add_described_flags(CLI::App* cmd, const Set& set) {
  const S defaults{};
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    if constexpr (core::Described<T> || core::is_number_list<T> || core::FixedVector<T>) {
      return;
    } else if (!f.in_table()) {
      return;
    } else if constexpr (std::is_same_v<T, bool>) {
      const bool d = defaults.*f.member;
      std::string off = cli_flag(f, true), on = cli_flag(f);
      std::string& other = d ? off : on;  // the flag setting the non-default
      if (!f.alias.empty()) other = "--" + std::string(f.alias) + "," + other;
      cmd->add_flag_callback(on, [set, f] { set(f, true); }, std::string(f.help) + (d ? " (default)" : ""));
      cmd->add_flag_callback(off, [set, f] { set(f, false); }, "Opposite of " + cli_flag(f) + (d ? "" : " (default)"));
    } else {
      cmd->add_option_function<T>(cli_flag(f), [set, f](const T& x) { set(f, core::held(f, x)); }, cli_help(f, defaults));
    }
  });
}

template <class S>
void add_override_flags(CLI::App* cmd, core::Overrides<S>& o) {
  add_described_flags<S>(cmd, [&o](const auto& f, const auto& x) { o.set(f.member, x); });
}

template <class S>
void add_settings_flags(CLI::App* cmd, S& s) {
  add_described_flags<S>(cmd, [&s](const auto& f, const auto& x) { s.*f.member = x; });
}

}  // namespace vrelab::app
