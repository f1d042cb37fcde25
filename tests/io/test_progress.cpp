// core::Progress away from a terminal (a log, CI, a pipe): a stage shorter than quiet_s says
// nothing, a longer one its tenths no closer than every_s apart and its last line; on a
// terminal every tick redraws the one line in place.
#include <gtest/gtest.h>

#include <cstddef>
#include <sstream>
#include <string>

#include "core/progress.hpp"

namespace test_progress {

namespace {

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// 72 ticks, as reproduce's amplitude study, in microseconds.
std::string ticks(bool terminal, double quiet_s, double every_s) {
  std::ostringstream out;
  {
    vrelab::core::Progress p(out, "stage", 72, true, terminal, quiet_s, every_s);
    for (std::size_t k = 0; k < 72; ++k) p.tick();
  }
  return out.str();
}

}  // namespace

TEST(Progress, AShortStageInALogSaysNothing) { EXPECT_EQ(ticks(false, 1.0, 10.0), ""); }

TEST(Progress, ALongStageInALogPrintsItsTenthsAndItsEnd) {
  // quiet_s = every_s = 0 stands for a stage long enough for every tenth: the first tick, each
  // tenth after it and the end, 11 lines (as before: 1/72, 8/72, ..., 72/72).
  const std::string s = ticks(false, 0.0, 0.0);
  EXPECT_EQ(count_lines(s), 11) << s;
  EXPECT_NE(s.find("72/72"), std::string::npos) << s;
  EXPECT_EQ(s.find('\r'), std::string::npos);
}

TEST(Progress, OnATerminalEveryTickRedrawsOneLine) {
  const std::string s = ticks(true, 1.0, 10.0);
  EXPECT_EQ(count_lines(s), 1) << s;  // the final newline
  std::size_t redraws = 0;
  for (char c : s) redraws += c == '\r';
  EXPECT_EQ(redraws, 72u);
}

}  // namespace test_progress
