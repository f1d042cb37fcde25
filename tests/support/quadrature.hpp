#pragma once
// Independent numerical averages used as references by the tests: Gauss-Legendre on
// sub-intervals split where the integrand has a kink (found by bisection, not by any
// formula of the code under test), and Gauss-Hermite nodes from the Golub-Welsch method.
#include <cmath>
#include <functional>
#include <numbers>
#include <utility>
#include <vector>

#include <Eigen/Dense>

namespace vrelab::test {

// n-point Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
inline std::vector<std::pair<double, double>> gauss_legendre(int n) {
  std::vector<std::pair<double, double>> out;
  for (int i = 1; i <= n; ++i) {
    double x = std::cos(std::numbers::pi * (i - 0.25) / (n + 0.5));
    double dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    out.emplace_back(x, 2 / ((1 - x * x) * dp * dp));
  }
  return out;
}

// Integral of f over [a, b], smooth inside: `pieces` sub-intervals of 20-point Gauss-Legendre.
inline double integrate_smooth(const std::function<double(double)>& f, double a, double b, int pieces = 16) {
  static const auto gl = gauss_legendre(20);
  double sum = 0;
  const double h = (b - a) / pieces;
  for (int p = 0; p < pieces; ++p) {
    const double lo = a + p * h, mid = lo + h / 2;
    for (const auto& [x, w] : gl) sum += w * h / 2 * f(mid + x * h / 2);
  }
  return sum;
}

// Integral of f over [a, b], where f is smooth except where one of the `kinks` functions
// changes sign. Sign changes are located on a fine grid and refined by bisection.
inline double integrate_piecewise(const std::function<double(double)>& f, double a, double b,
                                  const std::vector<std::function<double(double)>>& kinks) {
  std::vector<double> cuts{a, b};
  const int grid = 4000;
  for (const auto& g : kinks) {
    for (int i = 0; i < grid; ++i) {
      double lo = a + (b - a) * i / grid, hi = a + (b - a) * (i + 1) / grid;
      double glo = g(lo), ghi = g(hi);
      if (glo == 0) {
        cuts.push_back(lo);
        continue;
      }
      if ((glo < 0) == (ghi < 0) || ghi == 0) continue;
      for (int it = 0; it < 200 && hi - lo > 1e-16 * (1 + std::abs(lo)); ++it) {
        const double m = 0.5 * (lo + hi);
        if ((g(m) < 0) == (glo < 0)) lo = m; else hi = m;
      }
      cuts.push_back(0.5 * (lo + hi));
    }
  }
  std::sort(cuts.begin(), cuts.end());
  double sum = 0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
    if (cuts[i + 1] > cuts[i]) sum += integrate_smooth(f, cuts[i], cuts[i + 1]);
  return sum;
}

// Probabilists' Gauss-Hermite rule: E[f(Z)], Z ~ N(0, 1), exact for polynomials of degree < 2n.
inline std::vector<std::pair<double, double>> gauss_hermite(int n) {
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) j(k, k - 1) = j(k - 1, k) = std::sqrt(static_cast<double>(k));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(j);
  std::vector<std::pair<double, double>> out;
  for (int k = 0; k < n; ++k) out.emplace_back(es.eigenvalues()[k], std::pow(es.eigenvectors()(0, k), 2));
  return out;
}

}  // namespace vrelab::test
