#include "validation/diagnosis/internal/evidence.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "core/parallel.hpp"
#include "validation/diagnosis/internal/tabulate.hpp"

namespace vrelab::validation::internal {

std::vector<int> Folds::train(double k) const {
  std::vector<int> t;
  for (std::size_t j = 0; j < key.size(); ++j)
    if (key[j] != k) t.push_back(static_cast<int>(j));
  if (t.empty())
    for (std::size_t j = 0; j < key.size(); ++j) t.push_back(static_cast<int>(j));
  return t;
}

Folds folds_of(const std::vector<RunRecord>& runs) {
  std::set<double> amplitudes, frequencies;
  for (const auto& run : runs) amplitudes.insert(run.amplitude_g), frequencies.insert(run.frequency_Hz);
  const bool by_amplitude = amplitudes.size() >= 2, by_frequency = !by_amplitude && frequencies.size() >= 2;
  Folds f;
  f.description = by_amplitude ? "leave one amplitude out" : by_frequency ? "leave one frequency out" : "none (in-sample: one amplitude, one frequency)";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    f.key.push_back(by_amplitude ? runs[k].amplitude_g : by_frequency ? runs[k].frequency_Hz : 0.0);
    f.test[f.key.back()].push_back(static_cast<int>(k));
  }
  return f;
}

void note_measured_motion(const Campaign& c, Diagnosis& d) {
{
  int sine_runs = 0, measured_sine_runs = 0;
  for (const RunRecord& r : c.runs) {
    if (motion_used(r)) ++d.runs_with_measured_motion;
    if (!r.random) ++sine_runs, measured_sine_runs += motion_used(r) ? 1 : 0;
  }
  if (sine_runs > 0 && measured_sine_runs == sine_runs)
    for (const Effect& e : effect_library())
      if (e.acts_on == ActsOn::table_motion) d.measured_effects.push_back(e.name);
}
}

Likelihood Scorer::conditional_on(const Data& dd, const Eigen::VectorXd& pred, const Eigen::MatrixXd& G,
                                  const std::vector<int>& train) const {
  const Likelihood l_all = likelihood(dd, pred, G, m_.all), l_train = likelihood(dd, pred, G, train);
  return Likelihood{l_all.m2logl - l_train.m2logl, l_all.chi2 - l_train.chi2};
}

void Scorer::score(const std::function<Fitted(const std::vector<int>&)>& fit_on, Scored& sc) const {
  score_forms([&](const std::vector<int>& train) { return std::vector<Form>{Form{fit_on(train), 0.0}}; }, sc);
}

void Scorer::score_forms(const std::function<std::vector<Form>(const std::vector<int>&)>& fit_on, Scored& sc) const {
  const Data& data = m_.data;
  const Table& nominal = m_.nominal;
  const std::vector<int>& all = m_.all;
  const int n = m_.n;
  sc.heldout = Eigen::VectorXd::Zero(n);
  for (const auto& [key, test] : folds_.test) {
    const std::vector<int> train = folds_.train(key);
    const std::vector<Form> forms = fit_on(train);
    std::vector<Likelihood> with(forms.size());
    std::vector<Eigen::VectorXd> a(forms.size());
    for (std::size_t c = 0; c < forms.size(); ++c) {
      const Fitted& f = forms[c].f;
      if (train.size() == all.size()) {
        with[c] = likelihood(data, f.t.pred, f.t.G, all);
      } else {
        const Eigen::Index k = f.cov.rows(), m = plant::kNumCoefficients;
        Data da = data;
        da.Sigma = Eigen::MatrixXd::Zero(m + k, m + k);
        da.Sigma.topLeftCorner(m, m) = data.Sigma;
        da.Sigma.bottomRightCorner(k, k) = f.cov;
        Eigen::MatrixXd Ga(n, m + k);
        Ga << f.t.G, f.slopes;
        with[c] = conditional_on(da, f.t.pred, Ga, train);
      }
      a[c] = adjusted_residual(data, f.t.pred, f.t.G, train, test);
    }
    // The forms' mixture: prior weights pi_c from the training runs, -2 ln p(test) =
    // -2 ln sum pi_c p_c(test); the posterior weights rho_c (pi_c p_c, normalised) weigh the
    // forms' held-out residuals, and chi^2 is theirs plus 2 KL(rho || pi): what the held-out
    // runs had to overturn of the training runs' choice (0 with one form).
    const auto log_sum_exp = [](const std::vector<double>& x) {
      const double top = *std::max_element(x.begin(), x.end());
      double s = 0;
      for (double v : x) s += std::exp(v - top);
      return top + std::log(s);
    };
    std::vector<double> lp(forms.size()), lj(forms.size());
    for (std::size_t c = 0; c < forms.size(); ++c) lp[c] = -0.5 * forms[c].m2logl, lj[c] = lp[c] - 0.5 * with[c].m2logl;
    const double zp = log_sum_exp(lp), zj = log_sum_exp(lj);
    Likelihood mix{-2 * (zj - zp), 0.0};
    Eigen::VectorXd residual = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(test.size()));
    double mean_m2logl = 0;
    for (std::size_t c = 0; c < forms.size(); ++c) {
      const double rho = std::exp(lj[c] - zj);
      if (!(rho > 0)) continue;
      mix.chi2 += rho * with[c].chi2, mean_m2logl += rho * with[c].m2logl;
      residual += rho * a[c];
    }
    mix.chi2 += mix.m2logl - mean_m2logl;
    const Likelihood without = find_or_make(nominal_heldout_lock_, nominal_heldout_, key, [&] {
      return train.size() == all.size() ? likelihood(data, nominal.pred, nominal.G, all)
                                        : conditional_on(data, nominal.pred, nominal.G, train);
    });
    sc.fit.evidence += without.m2logl - mix.m2logl;
    sc.fit.heldout_chi2 += mix.chi2;
    for (std::size_t i = 0; i < test.size(); ++i) sc.heldout(test[i]) = residual(static_cast<Eigen::Index>(i));
  }
}

std::vector<Scorer::Form> Scorer::unseen_forms(const EffectFitter& fitter, const EffectFitter::Multi& mf, const Data& dd,
                                               const std::vector<int>& train) const {
  // A fold's fit is scored by its slope over +-sigma: the training posterior taken as a
  // Gaussian about the fit. Where the training runs do not see the effect (-2 ln L falls by
  // less than kSeen from no effect), a nonlinear effect's fit is a noise minimum and that
  // Gaussian is not its posterior: a squeeze film's fold that leaves 4 g out, fitted on the 1
  // and 2 g runs at 1424 +- 183 /rad where -2 ln L moves by 6 over 0-1600, predicts +222 ug at
  // 4 g where the film makes -17 ug. The posterior is then the training likelihood over the
  // grid (a uniform prior on its points), and the held-out runs are scored by that mixture:
  // -2 ln sum_g w_g p(test | train, p_g). A linear effect's prediction is linear in its
  // parameter, so its Gaussian is exact; a natural form's further parameters fitted, or a
  // form chosen, keep the fit (their grid tables would each be a new simulation).
  const Effect& e = fitter.effect();
  const std::vector<double>& grid = fitter.grid();
  if (e.fitted().linear || grid.size() < 2 || train.size() == m_.all.size() || mf.cov.size() > 0) return {};
  for (std::size_t j = 1; j < mf.values.size(); ++j)
    if (mf.values[j] != e.parameters[j].nominal) return {};
  const double l_none = likelihood(dd, m_.nominal.pred, m_.nominal.G, train).m2logl;
  const Table at_fit = fitter.at(mf.values);
  if (l_none - likelihood(dd, at_fit.pred, at_fit.G, train).m2logl >= EffectFitter::kSeen) return {};
  std::vector<Form> forms;
  const int n = m_.n;
  for (double p : grid) {
    Table t = fitter.at(p);
    const double l = likelihood(dd, t.pred, t.G, train).m2logl;
    if (std::isfinite(l)) forms.push_back(Form{Fitted{std::move(t), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(0, 0)}, l});
  }
  return forms;
}

Fitted Scorer::fitted_at(const EffectFitter& fitter, double p, double sp) const {
  const int n = m_.n;
  Fitted f{fitter.at(p), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(0, 0)};
  if (std::isfinite(sp) && sp > 0) {
    f.slopes = fitter.slope(p, sp);
    f.cov = Eigen::MatrixXd::Constant(1, 1, sp * sp);
  }
  return f;
}

Fitted Scorer::fitted_multi(const EffectFitter& fitter, const EffectFitter::Multi& mf) const {
  const int n = m_.n;
  if (mf.cov.size() == 0) {
    if (mf.values.size() > 1 && mf.status.size() > 1 &&
        std::any_of(mf.status.begin() + 1, mf.status.end(), [](ParameterStatus x) { return x != ParameterStatus::held; })) {
      // A discrete parameter chosen, the first fitted at it: its slope at that value.
      Fitted f{fitter.at(mf.values), Eigen::MatrixXd(n, 0), Eigen::MatrixXd(0, 0)};
      const double sp = mf.sigma.front();
      if (std::isfinite(sp) && sp > 0) {
        std::vector<double> up = mf.values, down = mf.values;
        up.front() += sp, down.front() -= sp;
        try {
          f.slopes = (fitter.at(up).pred - fitter.at(down).pred) / (2 * sp);
          f.cov = Eigen::MatrixXd::Constant(1, 1, sp * sp);
        } catch (const std::invalid_argument&) {
          f.slopes = Eigen::MatrixXd(n, 0);
        }
      }
      return f;
    }
    return fitted_at(fitter, mf.values.front(), mf.sigma.front());
  }
  return Fitted{fitter.at(mf.values), mf.slopes, mf.cov};
}

void heldout_nominal(const CampaignModel& m, Evidence& ev, Diagnosis& d) {
  ev.folds = folds_of(m.campaign.runs);
  d.folds = ev.folds.description;
  const int n = m.n;
  const Data& data = m.data;
  const Table& nominal = m.nominal;
  Eigen::VectorXd& heldout_nominal = ev.heldout_nominal;
  heldout_nominal = Eigen::VectorXd::Zero(n);
  ev.heldout_floor2 = Eigen::VectorXd::Zero(n);
  for (const auto& [key, test] : ev.folds.test) {
    const std::vector<int> train = ev.folds.train(key);
    const Eigen::VectorXd a = adjusted_residual(data, nominal.pred, nominal.G, train, test);
    // r_test - G_test dc* is r_test less its conditional mean given the training runs, so with
    // no gap its covariance is the conditional one: S_test + G_test P G_test^T.
    const Eigen::MatrixXd P = factored(data, nominal.G, train).conditional_covariance();
    for (std::size_t i = 0; i < test.size(); ++i) {
      const int k = test[i];
      heldout_nominal(k) = a(static_cast<Eigen::Index>(i));
      ev.heldout_floor2(k) = data.sigma2(k) + (nominal.G.row(k) * P * nominal.G.row(k).transpose())(0, 0);
    }
  }
}

void score_effects(const CampaignModel& m, const Scorer& scorer, Evidence& ev, Diagnosis& d, int threads,
                   const EffectsProgress& progress) {
  const Data& data = m.data;
  const std::vector<int>& all = m.all;
  std::vector<const Effect*> effects;
  for (const Effect& e : effect_library())
    if (std::find(d.measured_effects.begin(), d.measured_effects.end(), e.name) == d.measured_effects.end()) effects.push_back(&e);
  std::vector<std::unique_ptr<EffectFitter>> fitters(effects.size());
  std::vector<Scored> scored(effects.size());
  const auto fitted_forms = [&](const EffectFitter& fitter, const Data& dd, const std::vector<int>& runs) {
    std::vector<Scorer::Form> forms;
    const std::vector<EffectFitter::Form> fits = fitter.fit_forms(dd, runs);
    if (fits.size() == 1) {
      std::vector<Scorer::Form> grid = scorer.unseen_forms(fitter, fits.front().mf, dd, runs);
      if (!grid.empty()) return grid;
    }
    for (const EffectFitter::Form& form : fits) forms.push_back({scorer.fitted_multi(fitter, form.mf), form.m2logl});
    return forms;
  };
  // Handed out costliest first (those that change the loop's dynamics need their own loop
  // responses at every value; then by the parameters a natural form fits), so that the last
  // effect to finish is a cheap one. The results stay in the library's order.
  std::vector<std::size_t> order(effects.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Effect &x = *effects[a], &y = *effects[b];
    if (x.changes_dynamics != y.changes_dynamics) return x.changes_dynamics;
    return x.parameters.size() > y.parameters.size();
  });
  core::parallel_for(order.size(), threads, [&](std::size_t k) {
    const std::size_t i = order[k];
    const Effect& e = *effects[i];
    fitters[i] = std::make_unique<EffectFitter>(make_effect_fitter(e, m.nominal, m.plant, m.campaign.runs, m.cache, m.absorbed));
    const EffectFitter& fitter = *fitters[i];
    Scored& sc = scored[i];
    sc.fit.name = e.name, sc.fit.parameter = e.fitted().name, sc.fit.unit = e.fitted().unit;
    scorer.score_forms([&](const std::vector<int>& runs) { return fitted_forms(fitter, data, runs); }, sc);
    EffectFitter::Multi mf = fitter.fit_all(data, all);
    const Table at_fit = fitter.at(mf.values);
    sc.fit.insample_chi2 = likelihood(data, at_fit.pred, at_fit.G, all).chi2;
    sc.fit.insample_dof = m.n - static_cast<int>(mf.cov.size() > 0 ? mf.free.size() : 1);
    fitter.add_model_error(data, all, mf);
    const double p = mf.values.front(), sp = mf.sigma.front();
    sc.fit.value = p, sc.fit.sigma = sp;
    sc.fit.at_bound = !std::isfinite(sp);
    sc.fit.parameters = fitted_parameters(e, mf);
    sc.all = std::move(mf);
  }, [&, done = std::size_t{0}](std::size_t) mutable {
    if (progress) progress(++done, order.size());
  });
  for (std::size_t i = 0; i < effects.size(); ++i) {
    ev.fitters[effects[i]->name] = std::move(fitters[i]);
    ev.scored.push_back(std::move(scored[i]));
  }
  std::vector<Scored>& scored_all = ev.scored;
  // An effect whose held-out evidence or chi^2 is not a finite number (a fold's -2 ln L not
  // finite) is no candidate: listed after the ranked ones with why, never chosen.
  for (Scored& sc : scored_all)
    if (!std::isfinite(sc.fit.evidence) || !std::isfinite(sc.fit.heldout_chi2))
      sc.fit.not_ranked = "its held-out evidence or chi^2 is not a finite number";
  const auto ranked_end =
      std::stable_partition(scored_all.begin(), scored_all.end(), [](const Scored& a) { return a.fit.not_ranked.empty(); });
  std::sort(scored_all.begin(), ranked_end, [](const Scored& a, const Scored& b) { return a.fit.evidence > b.fit.evidence; });
  for (const auto& sc : scored_all) d.effects.push_back(sc.fit);
}

}  // namespace vrelab::validation::internal
