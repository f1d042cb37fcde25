#pragma once
// rectification/simulation/vibration_kind.hpp -- the kind of a commanded (or measured)
// vibration, and its name in files.
//
// Takes: a kind, or the text a case file, a lab's runs table or a JSON result names it by.
// Gives: VibrationKind (sine, swept_sine, random, sine_on_random); to_string(kind), the name
//        the files use ("sine", "swept_sine", "random", "sine_on_random"), and
//        parse_vibration_kind(text), its inverse (nullopt for any other text). The code
//        compares kinds, never their names: text only where files are read or written.
#include <optional>
#include <string>
#include <string_view>

namespace vrelab::rectification {

enum class VibrationKind { sine, swept_sine, random, sine_on_random };

inline std::string to_string(VibrationKind k) {
  switch (k) {
    case VibrationKind::sine: return "sine";
    case VibrationKind::swept_sine: return "swept_sine";
    case VibrationKind::random: return "random";
    case VibrationKind::sine_on_random: return "sine_on_random";
  }
  return "";
}

inline std::optional<VibrationKind> parse_vibration_kind(std::string_view text) {
  for (VibrationKind k :
       {VibrationKind::sine, VibrationKind::swept_sine, VibrationKind::random, VibrationKind::sine_on_random})
    if (to_string(k) == text) return k;
  return std::nullopt;
}

// A kind with a sine tone at one frequency (sine, sine_on_random).
constexpr bool has_sine_tone(VibrationKind k) { return k == VibrationKind::sine || k == VibrationKind::sine_on_random; }
// A kind with a Gaussian random part (random, sine_on_random).
constexpr bool has_random_part(VibrationKind k) {
  return k == VibrationKind::random || k == VibrationKind::sine_on_random;
}

}  // namespace vrelab::rectification
