// Identification from noise-free, error-free readings: the exact methods recover the
// coefficients to rounding; the printed formulas show the errata of paper-notes.md; the
// identifiability report names what no static test can separate.
//
// Tolerance 1e-9 relative: readings are U ~ K1 ~ 1 rounded to ~1e-16, and a coefficient is a
// combination of a few dozen readings divided by K1, so its absolute error is ~1e-15 at worst
// (observed ~2e-16 after the refinement in least squares); coefficients are drawn with
// |k| >= 1e-5, so the bound leaves a margin of ~10 over the worst case.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "plant/model1.hpp"
#include "support/random_coefficients.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/identification.hpp"

namespace test_identification {

using namespace vrelab;
using namespace vrelab::plant;
using namespace vrelab::validation;
constexpr double r2 = std::numbers::sqrt2;

namespace {

std::vector<Reading> exact_readings(const Coefficients& c, const std::vector<Position>& p) {
  std::mt19937_64 rng(0);
  return simulate_static_test(c, p, StaticTestErrors{}, rng);
}

void expect_recovered(const Coefficients& truth, const Estimate& e, const CoefFlags& which, const char* what) {
  for (int i = 0; i < kNumCoefficients; ++i) {
    if (!which[i]) continue;
    ASSERT_TRUE(e.available[i]);
    EXPECT_LE(std::abs(e.value[i] - truth[i]), 1e-9 * std::abs(truth[i]))
        << what << ": " << coefficient_name(i) << " estimate " << e.value[i] << " truth " << truth[i];
  }
}

CoefFlags all() {
  CoefFlags f;
  f.fill(true);
  return f;
}

}  // namespace

TEST(PositionTable, MatchesThePaperNotesConvention) {
  // Series 1, j = 2 (phi = 45 deg): (a_IA, a_PA) = (-cos 45, -sin 45); j = 5: a_IA = +1.
  const auto p = equally_spaced_positions(8);
  ASSERT_EQ(p.size(), 24u);
  EXPECT_NEAR(p[1].nominal_g[IA], -r2 / 2, 3e-16);
  EXPECT_NEAR(p[1].nominal_g[PA], -r2 / 2, 3e-16);
  EXPECT_NEAR(p[4].nominal_g[IA], 1, 1e-16);
  // Series 2, j = 3 (phi = 90): a_OA = -1; series 3, j = 1: a_PA = -1.
  EXPECT_NEAR(p[8 + 2].nominal_g[OA], -1, 1e-16);
  EXPECT_NEAR(p[16].nominal_g[PA], -1, 1e-16);
  EXPECT_EQ(p[16].nominal_g[IA], 0.0);
  for (const auto& q : p) EXPECT_NEAR(q.nominal_g.norm(), 1, 1e-15);
  EXPECT_TRUE(is_paper_set(p));
  EXPECT_FALSE(is_paper_set(equally_spaced_positions(24)));
}

TEST(LeastSquares, RecoversEveryCoefficientOnThe3x8SetWithK1AsymAndKppFixed) {
  std::mt19937_64 rng(31);
  const auto p = equally_spaced_positions(8);
  for (int n = 0; n < 120; ++n) {
    const Coefficients c = test::random_coefficients(rng);
    FixedSet fixed{};
    fixed[k1_asym] = c[k1_asym];
    fixed[k_PP] = c[k_PP];
    const auto r = least_squares(p, exact_readings(c, p), {}, fixed);
    ASSERT_TRUE(r.identifiability.full_rank());
    EXPECT_EQ(r.identifiability.rank, 11);
    expect_recovered(c, r.estimate, all(), "3x8");
  }
}

TEST(LeastSquares, RecoversEveryCoefficientOnThe3x24SetWithKppFixed) {
  std::mt19937_64 rng(32);
  const auto p = equally_spaced_positions(24);
  for (int n = 0; n < 120; ++n) {
    const Coefficients c = test::random_coefficients(rng);
    FixedSet fixed{};
    fixed[k_PP] = c[k_PP];
    const auto r = least_squares(p, exact_readings(c, p), {}, fixed);
    EXPECT_EQ(r.identifiability.rank, 12);
    expect_recovered(c, r.estimate, all(), "3x24");
  }
}

TEST(LeastSquares, AllFreeOn3x24RecoversTheIdentifiableAndNamesTheRest) {
  std::mt19937_64 rng(33);
  const auto p = equally_spaced_positions(24);
  const Coefficients c = test::random_coefficients(rng);
  const auto r = least_squares(p, exact_readings(c, p), {}, FixedSet{});
  const auto& id = r.identifiability;
  EXPECT_EQ(id.parameters, 13);
  EXPECT_EQ(id.rank, 12);
  CoefFlags expected{};
  for (int i : {K1, k1_asym, k3, k4, delta_OA, delta_PA, k_IP, k_IO, k_PO}) expected[i] = true;
  for (int i = 0; i < kNumCoefficients; ++i) EXPECT_EQ(id.identifiable[i], expected[i]) << coefficient_name(i);
  expect_recovered(c, r.estimate, expected, "3x24 all free");
  ASSERT_EQ(id.confounded.size(), 1u);
  EXPECT_NE(id.confounded[0].find("k0 and a common shift of k2, k_PP, k_OO"), std::string::npos) << id.confounded[0];
}

TEST(Identifiability, The3x8SetHasRank11Of13AndTheTwoKnownDirections) {
  const auto p = equally_spaced_positions(8);
  const Identifiability id = identifiability(p, FixedSet{});
  EXPECT_EQ(id.rank, 11);
  EXPECT_EQ(id.parameters, 13);
  ASSERT_EQ(id.null_directions.size(), 2u);
  // Independent check: moving the coefficients along each reported direction leaves every
  // reading of model (1) unchanged (to rounding).
  std::mt19937_64 rng(34);
  const Coefficients c = test::random_coefficients(rng);
  for (const auto& v : id.null_directions) {
    Coefficients moved = c;
    const double step = 1e-4;
    moved[K1] = c[K1] * (1 + step * v[K1]);
    for (int i = 1; i < kNumCoefficients; ++i) moved[i] = c[i] + step * v[i];
    for (const auto& q : p) EXPECT_NEAR(output(moved, q.nominal_g), output(c, q.nominal_g), 1e-14);
  }
  // The asymmetry direction derived by hand (docs/identification.md): with |a_IA| in
  // {0, 1/sqrt2, 1}, (k1', k2, k4) += c (1, 1/2 - sqrt2, sqrt2 - 1) changes no reading.
  const auto& asym = id.null_directions[1];
  EXPECT_NEAR(asym[k1_asym], 1, 1e-12);
  EXPECT_NEAR(asym[k2], 0.5 - r2, 1e-12);
  EXPECT_NEAR(asym[k4], r2 - 1, 1e-12);
  EXPECT_NE(id.confounded[0].find("k0 and a common shift of k2, k_PP, k_OO"), std::string::npos);
  EXPECT_NE(id.confounded[1].find("|a_IA| takes only 3 distinct values"), std::string::npos);
  // Fixing k1' and any one of k0, k2, k_PP, k_OO restores full rank.
  FixedSet f{};
  f[k1_asym] = 0.0;
  f[k_OO] = 0.0;
  EXPECT_TRUE(identifiability(p, f).full_rank());
}

TEST(PaperCorrected, RecoversEveryCoefficientWhenKppAndKooAreZero) {
  std::mt19937_64 rng(35);
  const auto p = equally_spaced_positions(8);
  for (int n = 0; n < 120; ++n) {
    Coefficients c = test::random_coefficients(rng);
    c[k_PP] = c[k_OO] = 0;
    const auto e = paper_corrected(*paper_table(p, exact_readings(c, p)), c[k1_asym]);
    CoefFlags which = all();
    which[k_PP] = which[k_OO] = false;  // zero truth: compared exactly below
    expect_recovered(c, e, which, "paper_corrected");
    EXPECT_EQ(e.value[k_PP], 0.0);
    EXPECT_EQ(e.value[k_OO], 0.0);
  }
}

TEST(PaperCorrected, UsesKnownKppAndKooAndShowsTheBiasOfAWrongAssumption) {
  std::mt19937_64 rng(37);
  const auto p = equally_spaced_positions(8);
  for (int n = 0; n < 60; ++n) {
    const Coefficients c = test::random_coefficients(rng);
    const PaperTable t = *paper_table(p, exact_readings(c, p));
    expect_recovered(c, paper_corrected(t, c[k1_asym], c[k_PP], c[k_OO]), all(), "paper_corrected, known k_PP/k_OO");
    // Assuming both zero (the paper): the biases derived by hand in docs/identification.md.
    const Estimate e = paper_corrected(t, c[k1_asym]);
    EXPECT_NEAR(e.value[k0] - c[k0], (c[k_PP] + c[k_OO]) / 2, 1e-13);
    EXPECT_NEAR(e.value[k2] - c[k2], (c[k_PP] - 3 * c[k_OO]) / 2, 1e-13);
    EXPECT_NEAR(e.value[k4] - c[k4], -c[k_PP] + c[k_OO], 1e-13);
  }
}

TEST(PaperPrinted, ReproducesTheErrataOfThePaperNotes) {
  std::mt19937_64 rng(36);
  const auto p = equally_spaced_positions(8);
  for (int n = 0; n < 50; ++n) {
    Coefficients c = test::random_coefficients(rng);
    c[k_PP] = c[k_OO] = 0;
    const auto e = paper_printed(*paper_table(p, exact_readings(c, p)), c[k1_asym]);
    // Erratum 4: K~1 = K1 (1 + 2 k3 / 3), and the printed k3 then returns
    // 2 (1 + k3/2) / (1 + 2 k3/3) - 2 = -(k3/3) / (1 + 2 k3/3), i.e. about -k3/3.
    EXPECT_NEAR(e.value[K1], c[K1] * (1 + 2 * c[k3] / 3), 1e-14);
    EXPECT_NEAR(e.value[k3], -(c[k3] / 3) / (1 + 2 * c[k3] / 3), 1e-9 * std::abs(c[k3]));
    EXPECT_NEAR(e.value[k3] / c[k3], -1.0 / 3.0, 0.01);
    // Errata 5 and 6, derived by hand from model (1) with rho = K1 / K~1 (k_PP = k_OO = 0):
    // the printed k2 sum over j = 2..8 also takes U13 + U15 + U17, so
    //   k2_printed = rho (1 + 3 k0 + sqrt2 k1' + 2 k2 + k3 + k4) + (1/2 - sqrt2) k1';
    // the factor (2 sqrt2 - 1) instead of (sqrt2 - 1) gives
    //   k4_printed = rho ((1 - sqrt2) k1' + k4) + (2 sqrt2 - 1) k1'   (= k4 + sqrt2 k1' at rho = 1).
    const double rho = c[K1] / e.value[K1];
    EXPECT_NEAR(e.value[k2], rho * (1 + 3 * c[k0] + r2 * c[k1_asym] + 2 * c[k2] + c[k3] + c[k4]) + (0.5 - r2) * c[k1_asym],
                1e-13);
    EXPECT_NEAR(e.value[k4], rho * ((1 - r2) * c[k1_asym] + c[k4]) + (2 * r2 - 1) * c[k1_asym], 1e-13);
    // The cross-coupling formulas are right; only K~1 instead of K1 scales them.
    EXPECT_NEAR(e.value[k_IP], c[k_IP] * c[K1] / e.value[K1], 1e-12);
    EXPECT_FALSE(e.available[delta_OA]);
  }
}

TEST(PaperTable, AveragesRepeatsAndRejectsOtherSets) {
  const auto p = equally_spaced_positions(8);
  std::vector<Reading> r;
  for (int i = 0; i < 24; ++i) r.push_back({i, 1.0 * i}), r.push_back({i, 1.0 * i + 2});
  const auto t = paper_table(p, r);
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ((*t)[1][2], 8 + 2 + 1.0);
  EXPECT_FALSE(paper_table(equally_spaced_positions(12), r).has_value());
}

// Issue 13, item 1: a 4-position tumble per series (0, 90, 180, 270 deg) sees no product of
// two axes, so with k1_asym, k3, k4 and k_PP held the 9 free coefficients have rank 6 (k_IP,
// k_IO and k_PO affect no reading). cos 90 deg computed in radians is 6e-17, and column
// scaling would make those rounding columns full size (rank 9 reported, k_IP from
// rounding). Angles in degrees are exact at multiples of 90 deg, and the rank is decided
// on the unscaled design.
TEST(Identifiability, AFourPositionTumbleHasRank6NotRoundingColumns) {
  for (double deg : {0.0, 90.0, 180.0, 270.0, -90.0, 450.0, 720.0}) {
    const auto [c, s] = cos_sin_deg(deg);
    EXPECT_EQ(c, std::cos(deg * std::numbers::pi / 180) > 0.5 ? 1.0 : std::cos(deg * std::numbers::pi / 180) < -0.5 ? -1.0 : 0.0) << deg;
    EXPECT_EQ(std::abs(s), std::abs(c) == 1 ? 0.0 : 1.0) << deg;
  }
  EXPECT_EQ(series_orientation_deg(1, 90)[IA], 0.0);
  EXPECT_EQ(series_orientation_deg(1, 90)[PA], -1.0);
  EXPECT_NEAR(cos_sin_deg(30).second, 0.5, 1e-16);
  EXPECT_NEAR(cos_sin_deg(-135).first, -r2 / 2, 1e-16);
  std::vector<Position> p;
  for (int s : {1, 2, 3})
    for (double deg : {0.0, 90.0, 180.0, 270.0}) p.push_back(series_position_deg(s, deg));
  FixedSet f{};
  f[k1_asym] = 2e-5, f[k3] = 1e-6, f[k4] = 2e-7, f[k_PP] = 0.0;
  const Identifiability id = identifiability(p, f);
  EXPECT_EQ(id.parameters, 9);
  EXPECT_EQ(id.rank, 6);
  EXPECT_FALSE(id.identifiable[k_IP]);
  // The same set with the rounding of radians put back (a user's 6e-17): still rank 6.
  std::vector<Position> rounded;
  for (int s : {1, 2, 3})
    for (double deg : {0.0, 90.0, 180.0, 270.0}) rounded.push_back(vector_position(series_orientation(s, deg * std::numbers::pi / 180)));
  EXPECT_EQ(identifiability(rounded, f).rank, 6);
  // equally_spaced_positions(4) is the same tumble.
  EXPECT_EQ(identifiability(equally_spaced_positions(4), f).rank, 6);
}

// An accepted identification must reproduce its readings and give physical coefficients.
TEST(FitCheck, RefusesAbsurdCoefficientsAndResidualsBeyondSigma) {
  std::mt19937_64 rng(7);
  const Coefficients c = test::random_coefficients(rng);
  const auto p = equally_spaced_positions(8);
  const auto r = exact_readings(c, p);
  Estimate e;
  e.value = c;
  const std::vector<double> var(r.size(), std::pow(c[K1] * 1e-6, 2));
  EXPECT_EQ(check_fit(p, r, e, var, 11).problem, "");
  Estimate absurd = e;
  absurd.value[k_IP] = 1e10;
  EXPECT_NE(check_fit(p, r, absurd, var, 11).problem.find("k_IP = 1e+10 lies beyond"), std::string::npos);
  Estimate off = e;
  off.value[k0] += 1e-3;  // 1 mg off against 1 ug noise: 1000 sigma
  const FitCheck f = check_fit(p, r, off, var, 11);
  EXPECT_NE(f.problem.find("does not reproduce its readings"), std::string::npos) << f.problem;
}

}  // namespace test_identification
