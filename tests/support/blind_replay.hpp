#pragma once
// Campaign `index` of blind's draw `seed`, simulated on the ODE plant through the effects'
// truth hooks and diagnosed exactly as `blind` makes it (run_blind), the campaigns before it
// read back from a result line as clean (not simulated): a miss of a scored seed replayed.
// mixed: blind --mixed's draw (sine, random and sine-on-random runs).
#include <cstdint>
#include <map>
#include <string>

#include "validation/diagnosis/blind.hpp"

namespace vrelab::test {

inline validation::BlindResult replay_blind_campaign(std::uint64_t seed, int index, bool mixed = false) {
  validation::BlindSettings s;
  s.n = index + 1, s.seed = seed, s.threads = 1, s.mixed = mixed;
  std::map<int, std::string> done;
  for (int i = 0; i < index; ++i) {
    validation::BlindCampaign k = validation::blind_key(i, seed, mixed);
    k.called = "clean";
    validation::EffectFit e;
    e.name = "pickoff_nonlinearity";
    k.diagnosis.effects = {e};
    k.top = e.name;
    done[i] = validation::campaign_result_text(k);
  }
  return validation::run_blind(s, {}, done, {});
}

}  // namespace vrelab::test
