#pragma once
// rectification/measurement/series.hpp -- the vibration error from a recorded output series.
//
// Takes: samples (time s, output in output units) in time order, streamed one at a time;
//        the baseline interval (instrument at rest) and the vibration interval (s); K1
//        (output units per g; 1 if the output is already in g); optionally the vibration
//        frequency (Hz) to measure over whole periods; the number of blocks for batch means.
// Gives: e = mean(U/K1 over the vibration interval) - mean(U/K1 over the baseline), g; its
//        standard uncertainty from batch means of both intervals; the paper's slope of the
//        running integral of (U/K1 - baseline); counts and the detected sample rate.
// Memory does not grow with the record: sums only, so records of any length stream through.
#include <string>
#include <vector>

namespace vrelab::rectification {

struct SeriesWindows {
  double baseline_from_s = 0, baseline_to_s = 0;
  double on_from_s = 0, on_to_s = 0;
  double frequency_Hz = 0;  // > 0: the vibration interval is cut to whole periods from on_from_s
  double K1 = 1.0;
  int blocks = 4;
  double input_rms_g = 0;  // > 0: the input's rms (g), for the VRC in the report; 0: unknown
  // Throws std::invalid_argument naming the field.
  void validate() const;
  // False (with validate()'s reason in *why) for windows no measurement can use.
  bool IsValid(std::string* why) const;
};

struct SeriesResult {
  double measured_g = 0, sigma_g = 0, integral_slope_g = 0, baseline_g = 0;
  long samples_on = 0, samples_baseline = 0;
  double sample_rate_Hz = 0;
  double on_to_used_s = 0;  // end of the vibration interval used (whole periods)
};

// Windows are half-open, [from, to): a record sampled every dt_s covers a window's end when
// its last sample is at or after to - dt (the next sample would fall at or beyond `to`), to
// 1e-6 dt for the rounding of written times. `measure` (SeriesMeasurer::finish) and the lab
// data's raw records (diagnose) both decide with this.
bool record_covers_window_end(double to_s, double last_t_s, double dt_s);
// The vibration window's end as the measurement uses it: on_to_s, or with frequency_Hz > 0
// on_from_s plus the whole periods it holds (to 1e-9 of a period).
double used_on_to_s(const SeriesWindows& w);

class SeriesMeasurer {
 public:
  explicit SeriesMeasurer(const SeriesWindows& w);
  // Samples must come in increasing time; throws std::invalid_argument otherwise.
  void add(double t_s, double output);
  // Throws std::invalid_argument if a window holds fewer than two samples per block, or the
  // record ends before a window does (record_covers_window_end).
  SeriesResult finish() const;

 private:
  struct Window {
    double from = 0, to = 0;
    std::vector<double> sum;
    std::vector<long> count;
  };
  void accumulate(Window& w, double t, double x);
  SeriesWindows w_;
  Window base_, on_;
  double last_t_ = -1e300, first_dt_ = 0;
  long n_ = 0;
  // Least squares of the running integral of U/K1 against time over the vibration interval.
  double integral_ = 0, st_ = 0, stt_ = 0, si_ = 0, sti_ = 0, prev_on_t_ = 0;
  long n_fit_ = 0;
};

}  // namespace vrelab::rectification
