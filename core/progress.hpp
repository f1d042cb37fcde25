#pragma once
// core/progress.hpp -- the one progress display: "label [####....] done/total, elapsed, ETA",
// redrawn in place on a terminal, a line every 10 % elsewhere (logs stay short). Not
// thread-safe by itself: call tick() under the pool's lock (core::parallel_for's after_each).
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
  Progress(std::ostream& out, std::string label, std::size_t total, bool enabled = true, bool terminal = isatty(2) != 0)
      : out_(out), label_(std::move(label)), total_(total), enabled_(enabled && total > 0), tty_(terminal),
        start_(std::chrono::steady_clock::now()) {}
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
    if (!tty_ && decile == last_decile_ && done_ < total_) return;
    last_decile_ = decile;
    const double t = elapsed_s();
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
  std::chrono::steady_clock::time_point start_;
};

}  // namespace vrelab::core
