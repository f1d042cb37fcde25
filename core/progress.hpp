#pragma once
// core/progress.hpp -- the one progress display: "label [####....] done/total, elapsed, ETA",
// redrawn in place on a terminal. Elsewhere (a log) sparse lines: at a new tenth when
// every_s has passed since the last line, and the last line when the whole took quiet_s or
// more; a stage shorter than quiet_s prints nothing. Not thread-safe by itself: call tick()
// under the pool's lock (core::parallel_for's after_each).
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <ostream>
#include <string>
#include <utility>

#include <unistd.h>

namespace vrelab::core {

class Progress {
 public:
  // `out` is where it draws (std::cerr in the CLI); enabled = false draws nothing.
  Progress(std::ostream& out, std::string label, std::size_t total, bool enabled = true, bool terminal = isatty(2) != 0,
           double quiet_s = 1.0, double every_s = 10.0)
      : out_(out), label_(std::move(label)), total_(total), enabled_(enabled && total > 0), tty_(terminal),
        quiet_s_(quiet_s), every_s_(every_s), start_(std::chrono::steady_clock::now()) {}
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  double elapsed_s() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  std::size_t done() const { return done_; }

  // `items` more finished.
  void tick(std::size_t items = 1) {
    done_ += items;
    if (!enabled_) return;
    const std::size_t decile = total_ ? 10 * done_ / total_ : 10;
    const double t = elapsed_s();
    if (!tty_) {
      const bool last = done_ >= total_;
      if (last ? t < quiet_s_ : decile == last_decile_ || t - last_line_s_ < every_s_ || t < quiet_s_) return;
      last_line_s_ = t;
    }
    last_decile_ = decile;
    const double eta = done_ > 0 && done_ < total_ ? t / static_cast<double>(done_) * static_cast<double>(total_ - done_) : 0.0;
    constexpr int kWidth = 24;
    const int fill = total_ && done_ < total_ ? static_cast<int>(kWidth * done_ / total_) : kWidth;
    char line[160];
    std::snprintf(line, sizeof line, "%s [%s%s] %zu/%zu, %.1f s, ETA %.0f s", label_.c_str(), std::string(fill, '#').c_str(),
                  std::string(kWidth - fill, '.').c_str(), done_, total_, t, eta);
    out_ << (tty_ ? "\r" : "") << line << (tty_ ? " " : "\n") << std::flush;
    drawn_ = true;
  }
  void finish() {
    if (enabled_ && tty_ && drawn_) out_ << "\n" << std::flush;
    drawn_ = false;
  }

 private:
  std::ostream& out_;
  std::string label_;
  std::size_t total_, done_ = 0, last_decile_ = 11;
  bool enabled_, tty_, drawn_ = false;
  double quiet_s_, every_s_, last_line_s_ = 0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace vrelab::core
