#pragma once
// Blind's result lines (the resume log) in tests: a bad line is refused (std::invalid_argument),
// neither read nor taken for an older program's line (OutdatedCampaignResult, diagnosed again).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "validation/diagnosis/blind.hpp"

namespace vrelab::test {

// The line with the last field before its gap part cut, the gap part kept (a line cut at its
// very end would be refused by the gap's check alone, or read as outdated).
inline std::string cut_before_gap(const std::string& text) {
  const std::size_t gap = text.rfind("\tgap\t");
  if (gap == std::string::npos || gap == 0) return text;  // (then read: the check below fails)
  return text.substr(0, text.rfind('\t', gap - 1)) + text.substr(gap);
}

inline void expect_refused_not_outdated(const std::string& line, const std::string& what) {
  validation::BlindCampaign back;
  try {
    validation::read_campaign_result(line, back);
    ADD_FAILURE() << what << " was read";
  } catch (const validation::OutdatedCampaignResult&) {
    ADD_FAILURE() << what << " was called outdated";
  } catch (const std::invalid_argument&) {
  }
}

}  // namespace vrelab::test
