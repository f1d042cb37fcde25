#include "rectification/measurement/series.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace vrelab::rectification {

bool SeriesWindows::IsValid(std::string* why) const {
  try {
    validate();
  } catch (const std::invalid_argument& e) {
    if (why) *why = e.what();
    return false;
  }
  return true;
}

void SeriesWindows::validate() const {
  auto finite = [](double x) { return std::isfinite(x); };
  if (!finite(baseline_from_s) || !finite(baseline_to_s) || !(baseline_to_s > baseline_from_s))
    throw std::invalid_argument("baseline interval: need from < to");
  if (!finite(on_from_s) || !finite(on_to_s) || !(on_to_s > on_from_s))
    throw std::invalid_argument("vibration interval: need from < to");
  if (!(frequency_Hz >= 0) || !finite(frequency_Hz)) throw std::invalid_argument("frequency_Hz must not be negative");
  if (frequency_Hz > 0 && (on_to_s - on_from_s) * frequency_Hz < 1)
    throw std::invalid_argument("vibration interval: shorter than one period of frequency_Hz");
  if (!(K1 > 0) || !finite(K1)) throw std::invalid_argument("K1 must be positive");
  if (blocks < 2) throw std::invalid_argument("blocks must be at least 2");
  if (!(input_rms_g >= 0) || !finite(input_rms_g)) throw std::invalid_argument("input_rms_g must not be negative (0: not given)");
  if (on_from_s < baseline_to_s && baseline_from_s < on_to_s)
    throw std::invalid_argument("the vibration interval overlaps the baseline interval");
}

bool record_covers_window_end(double to_s, double last_t_s, double dt_s) {
  return last_t_s + dt_s * (1 + 1e-6) >= to_s;
}

double used_on_to_s(const SeriesWindows& w) {
  return w.frequency_Hz > 0 ? w.on_from_s + std::floor((w.on_to_s - w.on_from_s) * w.frequency_Hz + 1e-9) / w.frequency_Hz
                            : w.on_to_s;
}

SeriesMeasurer::SeriesMeasurer(const SeriesWindows& w) : w_(w) {
  w_.validate();
  base_.from = w.baseline_from_s;
  base_.to = w.baseline_to_s;
  on_.from = w.on_from_s;
  on_.to = used_on_to_s(w);
  for (Window* x : {&base_, &on_}) {
    x->sum.assign(static_cast<std::size_t>(w.blocks), 0.0);
    x->count.assign(static_cast<std::size_t>(w.blocks), 0);
  }
}

void SeriesMeasurer::accumulate(Window& w, double t, double x) {
  // Half-open [from, to): with synchronous sampling a whole number of periods holds a whole
  // number of samples.
  if (t < w.from || t >= w.to) return;
  auto b = static_cast<std::size_t>((t - w.from) / (w.to - w.from) * static_cast<double>(w.sum.size()));
  if (b >= w.sum.size()) b = w.sum.size() - 1;
  w.sum[b] += x;
  w.count[b] += 1;
}

void SeriesMeasurer::add(double t, double output) {
  if (!std::isfinite(t) || !std::isfinite(output)) throw std::invalid_argument("sample is not a finite number");
  if (t <= last_t_) throw std::invalid_argument("time does not increase");
  if (n_ == 1) first_dt_ = t - last_t_;
  const double x = output / w_.K1;
  accumulate(base_, t, x);
  if (t >= on_.from && t < on_.to) {
    const double dt = n_fit_ == 0 ? 0.0 : t - prev_on_t_;
    integral_ += x * dt;
    const double tm = t - on_.from;
    st_ += tm, stt_ += tm * tm, si_ += integral_, sti_ += tm * integral_;
    ++n_fit_;
    prev_on_t_ = t;
  }
  accumulate(on_, t, x);
  last_t_ = t;
  ++n_;
}

SeriesResult SeriesMeasurer::finish() const {
  SeriesResult r;
  auto stats = [](const Window& w, const char* what, long& n_total) {
    double mean = 0;
    std::vector<double> means;
    n_total = 0;
    for (std::size_t b = 0; b < w.sum.size(); ++b) {
      if (w.count[b] < 2)
        throw std::invalid_argument(std::string(what) + " interval holds too few samples (block " + std::to_string(b + 1) +
                                    " of " + std::to_string(w.sum.size()) + " has " + std::to_string(w.count[b]) +
                                    "); is the record shorter than the interval?");
      means.push_back(w.sum[b] / static_cast<double>(w.count[b]));
      n_total += w.count[b];
    }
    for (std::size_t b = 0; b < means.size(); ++b) mean += w.sum[b];
    mean /= static_cast<double>(n_total);
    double ss = 0;
    for (double m : means) ss += (m - mean) * (m - mean);
    const double k = static_cast<double>(means.size());
    return std::pair<double, double>(mean, std::sqrt(ss / (k - 1) / k));
  };
  const auto [base_mean, base_sigma] = stats(base_, "baseline", r.samples_baseline);
  const auto [on_mean, on_sigma] = stats(on_, "vibration", r.samples_on);
  for (const auto& [w, what] : {std::pair<const Window*, const char*>{&base_, "baseline"}, {&on_, "vibration"}})
    if (!record_covers_window_end(w->to, last_t_, first_dt_)) {
      char msg[200];
      std::snprintf(msg, sizeof msg, "the record ends at %g s, before the %s interval [%g, %g) s does (its last sample is due at %g s)",
                    last_t_, what, w->from, w->to, w->to - first_dt_);
      throw std::invalid_argument(msg);
    }
  r.baseline_g = base_mean;
  r.measured_g = on_mean - base_mean;
  r.sigma_g = std::sqrt(base_sigma * base_sigma + on_sigma * on_sigma);
  const double n = static_cast<double>(n_fit_);
  r.integral_slope_g = (n * sti_ - st_ * si_) / (n * stt_ - st_ * st_) - base_mean;
  r.sample_rate_Hz = first_dt_ > 0 ? 1 / first_dt_ : 0;
  r.on_to_used_s = on_.to;
  return r;
}

}  // namespace vrelab::rectification
