// Blind's family size and its shrinkage's drift line (validation/diagnosis/blind.cpp), declared
// in diagnose.hpp: the nominal model only, never an effect hypothesis.
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "validation/diagnosis/diagnose.hpp"
#include "validation/diagnosis/internal/evidence.hpp"
#include "validation/diagnosis/internal/identification.hpp"
#include "validation/diagnosis/internal/likelihood.hpp"
#include "validation/diagnosis/internal/stage_options.hpp"
#include "validation/diagnosis/internal/tabulate.hpp"

namespace vrelab::validation {
namespace {

using internal::Data;
using internal::Table;

// A campaign as diagnose sees it before any hypothesis: the nominal simulation's gap
// r = measured - predicted and the covariance V its runs are judged by.
struct NominalView {
  Eigen::VectorXd r;
  FactoredCovariance V;
};

// The nominal simulation of a campaign as diagnose sees it before any hypothesis: the drift line
// removed (each run's sigma scaled by sigma_scale), identified from its static readings,
// tabulated, V's model accuracy at the nominal prediction.
struct Nominal {
  Data data;
  Table t;
};

Nominal nominal_of(const Campaign& c0, const DiagnoseSettings& s, double sigma_scale) {
  Campaign c = c0;
  remove_drift(c);
  for (RunRecord& r : c.runs) r.sigma_g *= sigma_scale;
  internal::Identified id = internal::identify(c);
  internal::ResponseCache cache;
  Nominal nm{std::move(id.data), internal::tabulate(id.plant, c.runs, nullptr, 0, cache, internal::Absorbed{})};
  internal::add_simulation_accuracy(nm.data, nm.t, internal::stage_options(s).simulation_rel_accuracy);
  return nm;
}

// The gap r = measured - predicted and the covariance V its runs are judged by, the stated
// sigma taken as it is (no sigma_scale: a family's size is judged with the runs' stated sigma).
NominalView nominal_view(const Campaign& c, const DiagnoseSettings& s) {
  const Nominal nm = nominal_of(c, s, 1);
  std::vector<int> all(static_cast<std::size_t>(nm.t.pred.size()));
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  return {nm.data.measured - nm.t.pred, internal::factored(nm.data, nm.t.G, all)};
}

}  // namespace

// Why sqrt(g^T V^-1 g) >= 5 is the "a gap >= 5 sigma": with Gaussian errors of
// covariance V, the most powerful test of "no gap" against "the gap g" (known shape and size,
// Neyman-Pearson) is the statistic g^T V^-1 y / sqrt(g^T V^-1 g), distributed N(0, 1) without
// the gap and N(sqrt(g^T V^-1 g), 1) with it: sqrt(g^T V^-1 g) is the gap's separation from
// none in sigma of the best test there is, with the runs' correlations through the static
// test's coefficients counted (a gap the coefficients can take up is no gap to any test).
// The diagnosis' targeted test asks an effect's held-out evidence, the fall of -2 ln L it
// brings, for more than the significance level squared, 25; for a one-parameter effect of the true
// shape that fall is (g^T V^-1 y)^2 / g^T V^-1 g, expected g^T V^-1 g + 1: a gap at 5 is the
// one the diagnosis' own test finds about half the time, no yardstick asks for more. The
// largest |g_k| / sigma_k of any one run (the largest run's size) counts neither the take-up
// nor the runs' joint power: a squeeze film 55 sigma in one run whose shape trades with k2/k3
// is a few sigma here; an effect below 5 sigma in every run but present in all is more.
double nominal_gap_significance(const Campaign& with, const Campaign& without, const DiagnoseSettings& s) {
  if (with.runs.size() != without.runs.size())
    throw std::invalid_argument("nominal_gap_significance: the campaigns have different runs");
  for (std::size_t k = 0; k < with.runs.size(); ++k) {
    const RunRecord &a = with.runs[k], &b = without.runs[k];
    // (A random run's sigma is its own record's scatter, which the effect changes a little.)
    if (a.frequency_Hz != b.frequency_Hz || a.amplitude_g != b.amplitude_g || a.direction != b.direction ||
        a.orientation_g != b.orientation_g || a.random.has_value() != b.random.has_value() ||
        (!a.random && a.sigma_g != b.sigma_g))
      throw std::invalid_argument("nominal_gap_significance: run " + a.id + " differs between the campaigns");
  }
  const NominalView w = nominal_view(with, s), o = nominal_view(without, s);
  const Eigen::VectorXd g = w.r - o.r;
  const double q = w.V.chi2(g);
  // (A NaN would be size 0: the campaign out of its scored family without a word.)
  if (!w.V.ok() || !std::isfinite(q))
    throw std::invalid_argument("nominal_gap_significance: the gap's chi^2 is not a number (a run's variance not positive, a coefficient's variance negative, or a slope or prediction not finite)");
  return std::sqrt(std::max(0.0, q));
}

std::vector<double> heldout_nominal_gap_g(const Campaign& c, const DiagnoseSettings& s, double sigma_scale) {
  const Nominal nm = nominal_of(c, s, sigma_scale);
  const internal::Folds folds = internal::folds_of(c.runs);
  std::vector<double> h(c.runs.size());
  for (const auto& [key, test] : folds.test) {
    const Eigen::VectorXd a = internal::adjusted_residual(nm.data, nm.t.pred, nm.t.G, folds.train(key), test);
    for (std::size_t i = 0; i < test.size(); ++i) h[static_cast<std::size_t>(test[i])] = a(static_cast<Eigen::Index>(i));
  }
  return h;
}

std::vector<double> drift_line_removed_g(const Campaign& c0) {
  Campaign c = c0;
  remove_drift(c);
  std::vector<double> line(c.runs.size());
  for (std::size_t k = 0; k < c.runs.size(); ++k) line[k] = c0.runs[k].measured_g - c.runs[k].measured_g;
  return line;
}

}  // namespace vrelab::validation
