#include "validation/identification/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/dispatch.hpp"

namespace vrelab::validation {

Propagation propagate_first_order(const Estimator& estimator, const std::vector<Reading>& readings,
                                  const ReadingBudget& budget) {
  if (budget.variance.size() != readings.size() || budget.bias.size() != readings.size())
    throw std::invalid_argument("propagate_first_order: one budget entry per reading is needed");
  // Step: small against the readings (the estimators are linear or nearly so in U, so the
  // truncation error is negligible) and large against their rounding.
  double scale = 0;
  for (const Reading& r : readings) scale = std::max(scale, std::abs(r.output));
  const double h = 1e-6 * (scale > 0 ? scale : 1.0);
  CoefArray bias{};
  std::array<CoefArray, plant::kNumCoefficients> cov{};
  CoefArray j{};
  std::vector<Reading> work = readings;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    work[i].output = readings[i].output + h;
    const Estimate up = estimator(work);
    work[i].output = readings[i].output - h;
    const Estimate down = estimator(work);
    work[i].output = readings[i].output;
    for (int k = 0; k < plant::kNumCoefficients; ++k) {
      j[k] = (up.value[k] - down.value[k]) / (2 * h);
      bias[k] += j[k] * budget.bias[i];
    }
    for (int k = 0; k < plant::kNumCoefficients; ++k)
      for (int l = 0; l < plant::kNumCoefficients; ++l) cov[k][l] += j[k] * j[l] * budget.variance[i];
  }
  Propagation p;
  for (int k = 0; k < plant::kNumCoefficients; ++k) {
    p.sigma[k] = std::sqrt(cov[k][k]);
    p.bias[k] = bias[k];
  }
  p.covariance = cov;
  return p;
}

namespace {

// Trials per item: the unit a worker takes (a rank's share of a million trials costs seconds,
// a block a few milliseconds: small next to the work, large next to a message).
constexpr int kTrialsPerBlock = 256;

// Block b's own random stream, from the seed and b alone (std::seed_seq is specified to the
// bit): the trials are the same whatever ranks and threads ran them.
std::mt19937_64 block_rng(std::uint64_t seed, std::uint64_t b) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(b >> 32)};
  return std::mt19937_64(seq);
}

std::uint64_t fnv1a64(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (const unsigned char ch : text) h = (h ^ ch) * 1099511628211ull;
  return h;
}

// Reads a block's numbers ("%a %a ..."): false unless there are `count` of them.
bool read_block(const std::string& text, std::size_t count, std::vector<double>* v) {
  v->clear();
  const char* p = text.c_str();
  for (char* end = nullptr;; p = end) {
    const double x = std::strtod(p, &end);
    if (end == p) break;
    v->push_back(x);
  }
  return v->size() == count;
}

// The checkpoint's line of block b: "b <index> <numbers> <checksum of what precedes it>".
std::string checkpoint_line(std::size_t b, const std::string& numbers) {
  std::string line = "b " + std::to_string(b) + " " + numbers;
  char sum[24];
  std::snprintf(sum, sizeof sum, "%016llx", static_cast<unsigned long long>(fnv1a64(line)));
  return line.append(sum).append("\n");
}

// The blocks a checkpoint file holds (a cut, altered or repeated line is dropped: the block
// runs again), after checking its header; rewrites the file with them alone (atomically), so
// that the lines appended after start on a line of their own.
std::size_t read_checkpoint(const std::string& path, const std::string& header, std::size_t blocks,
                            std::size_t count, std::vector<std::vector<double>>* partial) {
  namespace fs = std::filesystem;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument("--checkpoint " + path + ": cannot be read");
  std::string line, kept = header, numbers;
  std::getline(in, line);
  if (line + "\n" != header)
    throw std::invalid_argument("--checkpoint " + path +
                                ": holds another run (case, program, seed or trials); remove it or name another file");
  std::size_t found = 0;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // the last line without its newline: cut by a kill
    const std::size_t sp = line.rfind(' ');
    if (line.rfind("b ", 0) != 0 || sp == std::string::npos) continue;
    char* end = nullptr;
    const unsigned long long b = std::strtoull(line.c_str() + 2, &end, 10);
    if (end == line.c_str() + 2 || *end != ' ' || b >= blocks || !(*partial)[b].empty()) continue;
    numbers = line.substr(static_cast<std::size_t>(end - line.c_str()) + 1, sp - static_cast<std::size_t>(end - line.c_str()));
    if (checkpoint_line(b, numbers) != line + "\n") continue;
    if (!read_block(numbers, count, &(*partial)[b])) {
      (*partial)[b].clear();
      continue;
    }
    kept += line + "\n";
    ++found;
  }
  in.close();
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << kept;
    if (!(out.flush())) throw std::runtime_error("--checkpoint " + path + ": cannot be written");
  }
  fs::rename(tmp, path);
  return found;
}

}  // namespace

std::vector<MonteCarloStats> monte_carlo(const std::vector<Estimator>& estimators,
                                         const plant::Coefficients& truth, const OutputSource& source,
                                         const std::vector<Position>& positions,
                                         const StaticTestErrors& errors, int n, std::uint64_t seed, int threads,
                                         const MonteCarloCheckpoint& checkpoint) {
  if (n < 2) throw std::invalid_argument("Monte Carlo needs at least 2 trials");
  const std::size_t ne = estimators.size(), nk = plant::kNumCoefficients;
  const std::size_t blocks = (static_cast<std::size_t>(n) + kTrialsPerBlock - 1) / kTrialsPerBlock;
  // Per block: for each estimator and coefficient its mean error and sum of squared
  // deviations (Welford within the block), as hexadecimal floats (exact).
  std::vector<std::vector<double>> partial(blocks);
  // The checkpoint (rank 0's: it alone decides the items and writes): the blocks already
  // there are not run again.
  std::ofstream save;
  if (!checkpoint.path.empty() && core::is_root_process()) {
    char head[160];
    std::snprintf(head, sizeof head, " trials %d seed %llu block %d estimators %zu\n", n,
                  static_cast<unsigned long long>(seed), kTrialsPerBlock, ne);
    const std::string header = "# vrelab identify --monte-carlo checkpoint " + checkpoint.fingerprint + head;
    if (std::filesystem::exists(checkpoint.path)) {
      const std::size_t found = read_checkpoint(checkpoint.path, header, blocks, 2 * ne * nk, &partial);
      std::fprintf(stderr, "vrelab: --checkpoint %s: %zu of %zu blocks already in\n", checkpoint.path.c_str(), found,
                   blocks);
    } else {
      std::ofstream(checkpoint.path, std::ios::binary) << header;
    }
    save.open(checkpoint.path, std::ios::binary | std::ios::app);
    if (!save) throw std::invalid_argument("--checkpoint " + checkpoint.path + ": cannot be written");
  }
  std::vector<std::size_t> items;
  for (std::size_t b = 0; b < blocks; ++b)
    if (partial[b].empty()) items.push_back(b);
  core::dispatch(
      items, threads,
      [&](std::size_t b) {
        std::mt19937_64 rng = block_rng(seed, b);
        const int trials = static_cast<int>(std::min<std::size_t>(kTrialsPerBlock, static_cast<std::size_t>(n) - b * kTrialsPerBlock));
        std::vector<double> mean(ne * nk, 0.0), m2(ne * nk, 0.0);
        for (int t = 1; t <= trials; ++t) {
          const std::vector<Reading> readings = simulate_static_test(source, truth[plant::K1], positions, errors, rng);
          for (std::size_t e = 0; e < ne; ++e) {
            const Estimate est = estimators[e](readings);
            for (std::size_t k = 0; k < nk; ++k) {
              const double x = est.value[k] - truth[k];
              const double d = x - mean[e * nk + k];
              mean[e * nk + k] += d / t;
              m2[e * nk + k] += d * (x - mean[e * nk + k]);
            }
          }
        }
        std::string text;
        char cell[64];
        for (std::size_t i = 0; i < ne * nk; ++i) {
          std::snprintf(cell, sizeof cell, "%a %a ", mean[i], m2[i]);
          text += cell;
        }
        return text;
      },
      [&](std::size_t b, const std::string& text) {
        if (!read_block(text, 2 * ne * nk, &partial[b]))
          throw std::runtime_error("monte_carlo: a block's result could not be read back");
        if (save.is_open()) {  // one line and a flush: a kill leaves at most the last one cut
          save << checkpoint_line(b, text);
          save.flush();
          if (!save) throw std::runtime_error("--checkpoint " + checkpoint.path + ": cannot be written");
        }
      });
  // The blocks merged in their order (Chan et al.'s pairwise update): one sum, whatever order
  // they finished in. (Under MPI only rank 0 has them; the others return zeros.)
  std::vector<MonteCarloStats> stats(ne);
  std::vector<double> mean(ne * nk, 0.0), m2(ne * nk, 0.0);
  double count = 0;
  for (std::size_t b = 0; b < blocks && !partial[b].empty(); ++b) {
    const double nb = static_cast<double>(std::min<std::size_t>(kTrialsPerBlock, static_cast<std::size_t>(n) - b * kTrialsPerBlock));
    const double total = count + nb;
    for (std::size_t i = 0; i < ne * nk; ++i) {
      const double d = partial[b][2 * i] - mean[i];
      mean[i] += d * nb / total;
      m2[i] += partial[b][2 * i + 1] + d * d * count * nb / total;
    }
    count = total;
  }
  for (std::size_t e = 0; e < ne; ++e) {
    stats[e].n = n;
    for (std::size_t k = 0; k < nk; ++k) {
      stats[e].mean_error[k] = mean[e * nk + k];
      stats[e].std[k] = std::sqrt(m2[e * nk + k] / (n - 1));
    }
  }
  return stats;
}

}  // namespace vrelab::validation
