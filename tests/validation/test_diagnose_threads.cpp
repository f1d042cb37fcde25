// The diagnosis with the effects' fits on several threads (validation::diagnose's `threads`)
// against one thread: the same numbers, every digit. Whatever is shared between the effects
// (the response cache: loop responses by key and frequency, a random run's covariances
// through the loop, the tables; the nominal's held-out likelihoods) must not depend on which
// effect asked first, and the effects must come out in the library's order before ranking.
// Campaigns: cases/lab-example (10 sine runs, a hidden pickoff nonlinearity) and
// cases/lab-random's random and sine-on-random runs with three of its sine runs (random
// runs: their covariances through the loop shared by every effect that leaves the dynamics
// alone), each on 1 and 3 threads (more threads than the machine's 2
// cores: the effects interleave). Compared: io::to_json of the diagnosis as text. A few
// seconds each in Release, a minute under the sanitizers: label "campaign". The three-thread
// diagnosis also reports its progress (diagnose's EffectsProgress), checked here.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "io/formats/lab_data.hpp"
#include "io/services/diagnosis_json.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"

namespace test_diagnose_threads {

using namespace vrelab;
using namespace vrelab::validation;

namespace {

// keep_sine: the sine runs kept (the first ones; -1: all).
void expect_same_on_threads(const std::string& folder, int keep_sine = -1) {
  Campaign c = io::read_campaign(std::string(VRELAB_CASES_DIR) + "/" + folder);
  if (keep_sine >= 0) {
    std::vector<RunRecord> kept;
    int sines = 0;
    for (const RunRecord& r : c.runs)
      if (r.random || sines++ < keep_sine) kept.push_back(r);
    c.runs = kept;
  }
  ASSERT_FALSE(c.runs.empty()) << folder;
  // The progress told on three threads: 1, 2, ..., total, one call at a time (the calls are
  // under the pool's lock), total the effects scored, once per pass over them.
  std::vector<std::pair<std::size_t, std::size_t>> told;
  const Diagnosis one = diagnose(c, {}, 1),
                  three = diagnose(c, {}, 3, [&told](std::size_t done, std::size_t total) { told.emplace_back(done, total); });
  std::printf("  %s: %s\n", folder.c_str(), verdict_text(one).c_str());
  EXPECT_FALSE(one.effects.empty()) << folder;
  EXPECT_EQ(io::to_json(one, c).dump(), io::to_json(three, c).dump()) << folder;
  ASSERT_FALSE(told.empty()) << folder;
  const std::size_t total = told.front().second;
  EXPECT_EQ(total, three.effects.size()) << folder;
  EXPECT_EQ(told.size() % total, 0u) << folder;
  for (std::size_t k = 0; k < told.size(); ++k) {
    EXPECT_EQ(told[k].first, k % total + 1) << folder;
    EXPECT_EQ(told[k].second, total) << folder;
  }
}

}  // namespace

TEST(DiagnoseThreadsCampaign, SineCampaignIsTheSameNumbersOnOneAndThreeThreads) { expect_same_on_threads("lab-example"); }

TEST(DiagnoseThreadsCampaign, RandomCampaignIsTheSameNumbersOnOneAndThreeThreads) { expect_same_on_threads("lab-random", 3); }

}  // namespace test_diagnose_threads
