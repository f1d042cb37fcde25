// The vibration's kind and its name in files: the names are the ones the case files and the
// lab's runs table use (docs/data-format.md, cases/*.toml), and parsing is the inverse of
// writing; any other text is no kind (the readers then name the file's line).
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "rectification/simulation/vibration_kind.hpp"

namespace test_vibration_kind {

using vrelab::rectification::parse_vibration_kind;
using vrelab::rectification::VibrationKind;

TEST(VibrationKind, NamesAreTheFilesAndParseIsTheirInverse) {
  const std::vector<std::pair<VibrationKind, std::string>> names = {{VibrationKind::sine, "sine"},
                                                                    {VibrationKind::swept_sine, "swept_sine"},
                                                                    {VibrationKind::random, "random"},
                                                                    {VibrationKind::sine_on_random, "sine_on_random"}};
  for (const auto& [kind, name] : names) {
    EXPECT_EQ(to_string(kind), name);
    ASSERT_TRUE(parse_vibration_kind(name).has_value()) << name;
    EXPECT_EQ(*parse_vibration_kind(name), kind) << name;
  }
}

TEST(VibrationKind, OtherTextIsNoKind) {
  for (const char* text : {"", "Sine", "sine ", "sine-on-random", "swept", "gaussian"})
    EXPECT_FALSE(parse_vibration_kind(text).has_value()) << '"' << text << '"';
}

}  // namespace test_vibration_kind
