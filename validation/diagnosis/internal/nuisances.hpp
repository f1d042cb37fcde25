#pragma once
// validation/diagnosis/internal/nuisances.hpp -- the lab nuisances (docs/diagnose.md, "Lab
// nuisances"): the stated sigma's shortfall and the statistics it is judged by. The bias
// drift is diagnose.hpp's remove_drift.
//
// Takes: a campaign (its runs' frequency in Hz, amplitude in g, direction, static orientation,
//        measured error and stated sigma in g), each run's gap in its sigma (z), the levels
//        the stated sigma is judged by (SigmaScaleOptions) and a diagnosis of the campaign.
// Gives: the repeats' pooled chi^2 about their weighted means and its degrees of freedom; the
//        correlation of neighbouring runs' z (one frequency or amplitude step apart, the rest
//        alike) and the number of pairs; and the sigma_scale nuisance: the factor the stated
//        sigma falls short by (from repeats, else from the gaps), whether it is beyond chance
//        and, when it is scatter, the diagnosis judged again with the sigma scaled.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::validation::internal {

// The level every nuisance is tested at: the one-sided tail of a normal deviate beyond 3,
// 1 - Phi(3) = 1.35e-3 (a clean campaign is flagged for drift with twice that, both signs,
// and for an understated sigma with it: 0.4 % in all, within the 2 % false alarms
// with room for the gap's own test). The thresholds are this tail's quantiles of each
// statistic's distribution under "no nuisance", not values tuned on campaigns.
constexpr double kNuisanceTail = 1.3498980316300946e-3;
// An understated sigma measured from the gaps alone (no repeated runs) is tested at 4 sigma,
// 1 - Phi(4) = 3.17e-5: there an excess is also what unmodelled physics leaves below the
// structure tests' power (few runs share a frequency or an amplitude on a mixed design), and
// "sigma understated" would swallow it (seed 11501 mixed, campaign 122: an out-of-library
// damping, sum z^2 84 for 45 runs, 3.6 sigma, no structure at 3 sigma). At 4 sigma 45 runs
// still flag a sigma 1.44 x understated (blind's draws: 1.8 - 3), 168 runs 1.22 x.
constexpr double kScatterFromGapsTail = 3.167124183311986e-5;

// Runs alike but for one step of frequency or of amplitude (same direction, orientation and
// the other): how alike their gaps z are, as the correlation of neighbours, and how many pairs.
std::pair<double, int> neighbour_correlation(const Campaign& c, const std::vector<double>& z);

// Repeated runs (the same frequency, amplitude, direction and orientation): the pooled
// scatter over the stated sigma (chi^2 about each group's weighted mean), and its degrees of freedom.
std::pair<double, int> repeat_scatter(const Campaign& c);

// Whether gaps w (one per run of c) look like scatter, w_i independent N(0, s^2) with one
// unknown s: grouped by frequency, by amplitude, by direction, by static orientation and by
// time order (quarters of the runs by time_h when every run has one, else in the file's
// order), each factor with at least two groups of at least two runs is tested twice, its
// groups' means (sum n_g mean_g^2 / s^2, chi^2 with G degrees of freedom) and spreads
// (Bartlett's statistic about the known mean 0, chi^2 with G - 1), s^2 the mean of w^2. The
// smallest p times the number of tests (Bonferroni: the family's level) as a normal deviate.
struct ScatterStructure {
  std::string factor;  // the factor of the strongest departure ("" when none was testable)
  std::string test;    // "means" or "spreads"
  double sigma = 0;    // the family's p as a normal deviate (0 when none was testable)
  int tests = 0;
};
ScatterStructure scatter_structure(const Campaign& c, const std::vector<double>& w);

struct SigmaScaleOptions {
  double structure_threshold_sigma = 3;    // gaps are scatter when neither their neighbours' correlation nor
                                           // scatter_structure reaches this (normal deviate)
  double threshold_sigma = 5;              // a library effect's evidence beyond its square, judged again: a physical gap
};

// The stated sigma's scale, estimated from d (the diagnosis with the stated sigma); when it is
// scatter beyond chance, `rediagnose` (the campaign with each run's sigma scaled) replaces d
// unless a physical gap remains (the nuisance's note says so). Returns the sigma_scale nuisance.
Nuisance sigma_scale(const Campaign& c, const SigmaScaleOptions& o, Diagnosis& d,
                     const std::function<Diagnosis(const Campaign&)>& rediagnose);

}  // namespace vrelab::validation::internal
