// The case file's settings structs described once (core/settings_description.hpp): ShakeSettings
// with its Readout, FrequencyStudySettings with the FrequencyGrid it is read through, and
// SolverSettings, StaticTestSettings with its MonteCarloCheckpoint (no table: recorded and
// validated only; the coefficients held fixed through JsonValue), and ReproduceSettings with
// StaticTestErrors and ConfirmationSettings, read through ReproduceLists (lists of vectors and
// of names; the nested [reproduce.confirmation] shared by both). A range is enforced from the
// case file with the file, the line, the table and the key in the message; a scaled key
// ([readout] noise_sigma_ug) arrives in g and is recorded as written; each struct's JSON record
// reads back to the same struct; and each description lists every member of its struct
// (counted from the aggregate itself), so a member added but not described fails here.
// Readers only: fast.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/formats/case_file.hpp"
#include "io/formats/error.hpp"
#include "io/formats/settings_json.hpp"
#include "io/formats/validation_json.hpp"
#include "plant/ode_solver.hpp"
#include "rectification/prediction/frequency_study.hpp"
#include "rectification/simulation/shake.hpp"
#include "support/files.hpp"
#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/settings.hpp"
#include "validation/identification/dividing_head.hpp"
#include "validation/identification/static_test.hpp"
#include "validation/reproduce/reproduce.hpp"

using namespace vrelab;
namespace fs = std::filesystem;
using vrelab::test::read_file;
using vrelab::test::TempDir;

namespace {

// The number of members of the aggregate S: the most initialisers S{...} accepts, each an
// AnyMember (convertible to any type). A nested aggregate takes one (the conversion
// initialises it whole, no brace elision).
struct AnyMember {
  template <class T>
  operator T() const;  // declared only: used in unevaluated braces
};
template <class S, class... A>
constexpr int member_count() {
  if constexpr (requires { S{A{}..., AnyMember{}}; }) return member_count<S, A..., AnyMember>();
  else return static_cast<int>(sizeof...(A));
}

// A value of f other than its default d, inside its range (a number 1.25 d + 0.25 or the
// midpoint to the lower bound; a count +-1; a flag negated; a list or vector element-wise;
// a string with a suffix). Exact as text (shortest round trip) before scaling.
template <class F, class T>
T other_value(const F& f, const T& d) {
  if constexpr (std::is_same_v<T, bool>) {
    return !d;
  } else if constexpr (std::is_integral_v<T>) {
    return core::admissible_value(f, static_cast<T>(d + 1)) ? static_cast<T>(d + 1) : static_cast<T>(d - 1);
  } else if constexpr (std::is_floating_point_v<T>) {
    const T w = core::written(f, d);
    T up = w * 1.25 + 0.25;
    if (!core::admissible_value(f, up)) up = (w + (f.range.has_min ? f.range.min : w - 1)) / 2;
    return core::held(f, up);
  } else if constexpr (std::is_same_v<T, std::string>) {
    return d + "-other";
  } else if constexpr (core::is_number_list<T>) {
    return T{0.5, 2.0, 7.25};  // every list here is of positive numbers
  } else if constexpr (core::is_vector_list<T>) {
    using V = typename T::value_type;
    return T{V(0, 0.6, 0.8), V(1, 0, 0)};  // unit vectors: each list here is of directions or orientations
  } else if constexpr (core::is_string_list<T>) {
    return T{"first", "second"};  // as long as the vector lists
  } else if constexpr (core::FixedVector<T>) {
    T v = d;
    for (int i = 0; i < T::SizeAtCompileTime; ++i) v[i] = d[i] + 0.5 * (i + 1);
    return v;
  } else if constexpr (core::is_optional_numbers<T>) {
    T v = d;  // the first slot set or changed, the last unset or cleared
    v.front() = v.front() ? *v.front() + 0.5 : 0.75;
    v.back() = v.back() ? std::nullopt : std::optional<double>(-1.5);
    return v;
  } else {
    return d;
  }
}

// S with every field at other_value (nested described structs likewise).
template <class S>
S all_other() {
  const S d{};
  S s{};
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    if constexpr (core::Described<T>) s.*f.member = all_other<T>();
    else s.*f.member = other_value(f, d.*f.member);
  });
  return s;
}

// Every field of a equals b's (nested described structs field by field).
template <class S>
void expect_same(const S& a, const S& b, const std::string& where) {
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    if constexpr (core::Described<T>) expect_same(a.*f.member, b.*f.member, where + std::string(f.name) + ".");
    else if constexpr (io::HasJsonValue<T>)  // a type of its own, compared through its (lossless) JSON
      EXPECT_EQ(io::JsonValue<T>::to(a.*f.member), io::JsonValue<T>::to(b.*f.member)) << where << f.name;
    else EXPECT_TRUE(a.*f.member == b.*f.member) << where << f.name;
  });
}

// The JSON record's keys, in order.
std::vector<std::string> keys_of(const nlohmann::json& j) {
  std::vector<std::string> k;
  for (const auto& [key, v] : j.items()) k.push_back(key);
  std::sort(k.begin(), k.end());
  return k;
}

// A shipped case with `text` put after the line `after` (a table's header), written to t.
fs::path case_with(const TempDir& t, const std::string& name, const std::string& after, const std::string& text) {
  std::string s = read_file(fs::path(VRELAB_CASES_DIR) / name);
  const std::size_t at = s.find(after + "\n");
  if (at == std::string::npos) s += "\n" + after + "\n" + text + "\n";
  else s.insert(at + after.size() + 1, text + "\n");
  const fs::path p = t.path / name;
  std::ofstream(p) << s;
  return p;
}

// A shipped case with its text `from` replaced by `to`, written to t.
fs::path case_replacing(const TempDir& t, const std::string& name, const std::string& from, const std::string& to) {
  std::string s = read_file(fs::path(VRELAB_CASES_DIR) / name);
  s.replace(s.find(from), from.size(), to);
  const fs::path p = t.path / ("replaced-" + name);
  std::ofstream(p) << s;
  return p;
}

// The line number (1-based) of the first line of file p that starts with `start`.
int line_of(const fs::path& p, const std::string& start) {
  std::ifstream in(p);
  std::string l;
  for (int n = 1; std::getline(in, l); ++n)
    if (l.rfind(start, 0) == 0) return n;
  return 0;
}

std::string error_of(const fs::path& p) {
  try {
    io::read_case(p.string());
  } catch (const io::FormatError& e) {
    return e.what();
  }
  return "";
}

// The error reading p names p, the line that starts with `start`, then `what`.
void expect_error_at(const fs::path& p, const std::string& start, const std::string& what) {
  const std::string e = error_of(p);
  EXPECT_NE(e.find(p.string() + ":" + std::to_string(line_of(p, start)) + ": " + what), std::string::npos) << e;
}

}  // namespace

TEST(CaseSettings, EachDescriptionListsEveryMemberOfItsStruct) {
  // The aggregate's own member count against the description's: a member added to the struct
  // and not described fails here.
  EXPECT_EQ(member_count<rectification::Readout>(), core::field_count<rectification::Readout>());
  EXPECT_EQ(member_count<rectification::ShakeSettings>(), core::field_count<rectification::ShakeSettings>());
  EXPECT_EQ(member_count<rectification::FrequencyStudySettings>(),
            core::field_count<rectification::FrequencyStudySettings>());
  EXPECT_EQ(member_count<rectification::FrequencyGrid>(), core::field_count<rectification::FrequencyGrid>());
  EXPECT_EQ(member_count<plant::SolverSettings>(), core::field_count<plant::SolverSettings>());
  // The structs described before these (validation/diagnosis), by the same count.
  EXPECT_EQ(member_count<validation::DiagnoseSettings>(), core::field_count<validation::DiagnoseSettings>());
  EXPECT_EQ(member_count<validation::BlindSettings>(), core::field_count<validation::BlindSettings>());
  // The static test's (no table of its own: every field set from elsewhere).
  EXPECT_EQ(member_count<validation::StaticTestSettings>(), core::field_count<validation::StaticTestSettings>());
  EXPECT_EQ(member_count<validation::MonteCarloCheckpoint>(), core::field_count<validation::MonteCarloCheckpoint>());
  EXPECT_TRUE(core::table_keys<validation::StaticTestSettings>().empty());
  // The experiment's, the table's lists as written, and their nested structs.
  EXPECT_EQ(member_count<validation::ReproduceSettings>(), core::field_count<validation::ReproduceSettings>());
  EXPECT_EQ(member_count<validation::ConfirmationSettings>(), core::field_count<validation::ConfirmationSettings>());
  EXPECT_EQ(member_count<validation::StaticTestErrors>(), core::field_count<validation::StaticTestErrors>());
  EXPECT_EQ(member_count<validation::ReproduceLists>(), core::field_count<validation::ReproduceLists>());
  EXPECT_EQ(member_count<validation::ConfirmationIndices>(), core::field_count<validation::ConfirmationIndices>());
  // [reproduce]'s keys: the settings' own and the lists as written (the rest set_by).
  using K = std::vector<std::string_view>;
  EXPECT_EQ(core::table_keys<validation::ReproduceSettings>(),
            (K{"frequency_Hz", "amplitudes_g", "confirmation", "departure_frequencies_Hz", "invisible_shift_per_g", "threads"}));
  EXPECT_EQ(core::table_keys<validation::ReproduceLists>(),
            (K{"directions", "direction_names", "orientations_g", "orientation_names", "confirmation"}));
  EXPECT_EQ(core::table_keys<validation::ConfirmationSettings>(), (K{"amplitude_g", "record_s"}));
  // And the JSON record holds them by the names written here by hand (the documented keys).
  using V = std::vector<std::string>;
  EXPECT_EQ(keys_of(io::settings_json(rectification::Readout{})),
            (V{"noise_sigma_ug", "quantisation_lsb_ug", "sample_rate_Hz", "seed"}));
  EXPECT_EQ(keys_of(io::settings_json(rectification::ShakeSettings{})),
            (V{"analytic_jacobian", "blocks", "exponential_integrator", "min_measure_s", "periodic_steady_state",
               "readout", "relative_tolerance", "settle_decay"}));
  EXPECT_EQ(keys_of(io::settings_json(rectification::FrequencyStudySettings{})),
            (V{"amplitude_g", "direction", "frequencies_Hz", "ode_frequencies_Hz", "pickoff_p2_per_rad"}));
  EXPECT_EQ(keys_of(io::settings_json(rectification::FrequencyGrid{})), (V{"from_Hz", "ode_points", "points", "to_Hz"}));
  EXPECT_EQ(keys_of(io::settings_json(plant::SolverSettings{})),
            (V{"absolute_tolerance", "analytic_jacobian", "max_step_s", "max_steps", "relative_tolerance"}));
  EXPECT_EQ(keys_of(io::settings_json(validation::StaticTestSettings{})),
            (V{"fixed", "monte_carlo_checkpoint", "monte_carlo_trials", "seed"}));
  EXPECT_EQ(keys_of(io::settings_json(validation::MonteCarloCheckpoint{})), (V{"fingerprint", "path"}));
  EXPECT_EQ(keys_of(io::settings_json(validation::ReproduceSettings{})),
            (V{"amplitudes_g", "confirmation", "departure_frequencies_Hz", "directions", "errors", "fixed", "frequency_Hz",
               "invisible_shift_per_g", "orientations", "positions", "seed", "shake", "threads"}));
  EXPECT_EQ(keys_of(io::settings_json(validation::ConfirmationSettings{})),
            (V{"amplitude_g", "direction", "orientation", "record_s"}));
  EXPECT_EQ(keys_of(io::settings_json(validation::StaticTestErrors{})),
            (V{"angle_sigma_rad", "initial_error_rad", "noise_sigma_g", "repeats"}));
}

// adjust: for a struct whose IsValid asks more than the ranges (StaticTestSettings: not 1 trial).
template <class S>
void expect_round_trip(const std::string& name, void (*adjust)(S&) = nullptr) {
  SCOPED_TRACE(name);
  S s = all_other<S>();
  if (adjust) adjust(s);
  std::string why;
  EXPECT_TRUE(s.IsValid(&why)) << why;
  const nlohmann::json j = io::settings_json(s);
  S back{};
  io::settings_from_json(j, back);
  expect_same(back, s, name + ".");
  EXPECT_EQ(io::settings_json(back), j);
}

TEST(CaseSettings, EachJsonRecordReadsBackToTheSameSettings) {
  // Every field away from its default, so a field the record drops would come back changed.
  expect_round_trip<rectification::Readout>("Readout");
  expect_round_trip<rectification::ShakeSettings>("ShakeSettings");
  expect_round_trip<rectification::FrequencyStudySettings>("FrequencyStudySettings");
  expect_round_trip<rectification::FrequencyGrid>("FrequencyGrid");
  expect_round_trip<plant::SolverSettings>("SolverSettings");
  expect_round_trip<validation::MonteCarloCheckpoint>("MonteCarloCheckpoint");
  expect_round_trip<validation::StaticTestSettings>("StaticTestSettings",
                                                    [](validation::StaticTestSettings& s) { s.monte_carlo_trials = 16; });
  expect_round_trip<validation::ReproduceLists>("ReproduceLists");
  // The fields of types of their own set (other_value leaves them), so the set is a run.
  expect_round_trip<validation::ReproduceSettings>("ReproduceSettings", [](validation::ReproduceSettings& s) {
    s.positions = validation::equally_spaced_positions(8);
    s.positions.push_back(validation::vector_position(Vec3(0, 0.6, 0.8)));
    s.fixed = {};
    s.fixed[plant::k1_asym] = 2e-5, s.fixed[plant::k_PP] = 0.0, s.fixed[plant::k_OO] = 0.0;
    s.directions = {{"IA", Vec3(1, 0, 0)}, {"oblique", Vec3(1, 1, 1).normalized()}};
    s.orientations = {{"IA up", Vec3(1, 0, 0)}, {"tilted", Vec3(0, 0.6, 0.8)}};
    s.confirmation.orientation = s.orientations[1], s.confirmation.direction = s.directions[1];
  });
  // The coefficients held fixed by name; a name that is not a coefficient is refused, by name.
  validation::StaticTestSettings st;
  io::settings_from_json(nlohmann::json{{"fixed", {{"k1_asym", 2e-5}, {"k_PP", 0}}}}, st);
  EXPECT_EQ(st.fixed[plant::k1_asym], 2e-5);
  EXPECT_EQ(st.fixed[plant::k_PP], 0.0);
  EXPECT_FALSE(st.fixed[plant::k0]);
  try {
    io::settings_from_json(nlohmann::json{{"fixed", {{"k_XX", 1}}}}, st);
    ADD_FAILURE() << "an unknown coefficient read";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fixed: 'k_XX' is not a coefficient"), std::string::npos) << e.what();
  }
  // A key the description does not hold is refused, by name.
  rectification::ShakeSettings s;
  EXPECT_THROW(io::settings_from_json(nlohmann::json{{"blockz", 3}}, s), std::invalid_argument);
  EXPECT_THROW(io::settings_from_json(nlohmann::json{{"readout", {{"noise_sigma_g", 1}}}}, s), std::invalid_argument);
}

TEST(CaseSettings, ReproduceReadsFromTheCaseAndItsRecordReadsBack) {
  // cases/paper.toml: TOML -> ReproduceSettings -> JSON text -> ReproduceSettings, the same.
  const io::Case c = io::read_case(std::string(VRELAB_CASES_DIR) + "/paper.toml");
  ASSERT_TRUE(c.reproduce.has_value());
  const validation::ReproduceSettings& s = *c.reproduce;
  std::string why;
  EXPECT_TRUE(s.IsValid(&why)) << why;
  // The lists as written, named and indexed from 1; the directions normalised.
  ASSERT_EQ(s.directions.size(), 4u);
  EXPECT_EQ(s.directions[3].name, "oblique [1,1,1]");
  EXPECT_NEAR(s.directions[3].v[1], 1 / std::sqrt(3.0), 1e-15);
  EXPECT_EQ(s.confirmation.orientation.name, "IA at 45 deg");  // orientation = 2
  EXPECT_EQ(s.confirmation.direction.name, "IA");              // direction = 1
  EXPECT_EQ(s.confirmation.amplitude_g, 2.0);
  // The fields set by the other tables.
  EXPECT_EQ(s.positions.size(), 24u);
  EXPECT_EQ(s.errors.noise_sigma_g, c.dividing_head->errors.noise_sigma_g);
  EXPECT_EQ(s.errors.repeats, 4);
  EXPECT_EQ(s.fixed[plant::k1_asym], 2e-5);
  EXPECT_EQ(s.shake.blocks, 16);
  const nlohmann::json j = nlohmann::json::parse(io::settings_json(s).dump());
  EXPECT_EQ(j["confirmation"]["orientation"]["name"], "IA at 45 deg");
  EXPECT_EQ(j["directions"][0]["vector"].get<std::vector<double>>(), (std::vector<double>{1, 0, 0}));
  EXPECT_EQ(j["positions"].size(), 24u);
  EXPECT_EQ(j["errors"]["repeats"], 4);
  EXPECT_EQ(j["shake"]["readout"]["noise_sigma_ug"], 20.0);
  validation::ReproduceSettings back;
  io::settings_from_json(j, back);
  expect_same(back, s, "ReproduceSettings.");
  EXPECT_EQ(io::settings_json(back), j);
  // A named vector without its name, or a position without its series, is refused by key.
  try {
    io::settings_from_json(nlohmann::json::parse(R"({"directions": [{"vector": [1, 0, 0]}]})"), back);
    ADD_FAILURE() << "a direction without its name read";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("directions: [0]: expected an object with 'name'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::settings_from_json(nlohmann::json::parse(R"({"positions": [{"angle_rad": 0}]})"), back),
               std::invalid_argument);
}

TEST(CaseSettings, ABadReproduceValueIsNamedAtItsLineAndKey) {
  TempDir t;
  // A range of the settings' own, on the list's entry; in the nested [reproduce.confirmation].
  fs::path p = case_replacing(t, "paper.toml", "amplitudes_g = [0.5, 1.0, 1.5", "amplitudes_g = [0.5, 1.0, 1500.0");
  expect_error_at(p, "amplitudes_g = [0.5, 1.0, 1500.0", "[reproduce] amplitudes_g[2] = 1500: must be in (0, 1000] g");
  p = case_replacing(t, "paper.toml", "record_s = 2.0", "record_s = 0.0");
  expect_error_at(p, "record_s = 0.0", "[reproduce.confirmation] record_s = 0: must be in (0, 1000000] s");
  // The lists as written: an index past its list, an orientation that is not gravity, an
  // entry of the wrong type.
  p = case_replacing(t, "paper.toml", "direction = 1 ", "direction = 5 ");
  expect_error_at(p, "direction = 5", "[reproduce.confirmation] direction = 5: must be at most 4, the entries of directions");
  // (the list over two lines: the message at the entry's)
  p = case_replacing(t, "paper.toml", "[0.0, 0.7071067811865476, 0.7071067811865476]]", "\n  [0.0, 0.7071, 0.8]]");
  expect_error_at(p, "  [0.0, 0.7071, 0.8]]",
                  "[reproduce] orientations_g[2] = [0, 0.7071, 0.8]: a static orientation is gravity in sensor axes "
                  "[IA, PA, OA], |a| = 1 g (within 0.001); got |a| = 1.0677 g");
  p = case_replacing(t, "paper.toml", "direction_names = [\"IA\"", "direction_names = [1");
  expect_error_at(p, "direction_names = [1", "[reproduce] direction_names[0]: expected a string");
  p = case_replacing(t, "paper.toml", "directions = [[1.0, 0.0, 0.0]", "directions = [[1.0, 0.0]");
  expect_error_at(p, "directions = [[1.0, 0.0]", "[reproduce] directions[0]: expected an array of 3 numbers [IA, PA, OA]");
  // Unknown keys, in either table, with the closest; a key set by another table is none here.
  p = case_with(t, "paper.toml", "[reproduce.confirmation]", "orientaton = 2");
  expect_error_at(p, "orientaton = 2", "[reproduce.confirmation] orientaton: unknown key (did you mean 'orientation'?)");
  p = case_with(t, "paper.toml", "[reproduce]", "seed = 3");
  expect_error_at(p, "seed = 3", "[reproduce] seed: unknown key");
  // A required key missing.
  p = case_replacing(t, "paper.toml", "record_s = 2.0", "");
  EXPECT_NE(error_of(p).find("[reproduce.confirmation] record_s: missing (required)"), std::string::npos) << error_of(p);
}

TEST(CaseSettings, ARangeIsEnforcedFromTheCaseFileAtItsLineAndKey) {
  TempDir t;
  // [shake] blocks below its range [2, 1000].
  fs::path p = case_with(t, "shake-sine-lab.toml", "[shake]", "blocks = 1");
  expect_error_at(p, "blocks = 1", "[shake] blocks = 1: must be in [2, 1000]");
  // A [readout] value below zero, in the unit written (ug).
  p = case_replacing(t, "shake-sine-lab.toml", "quantisation_lsb_ug = 1.0", "quantisation_lsb_ug = -2.0");
  expect_error_at(p, "quantisation_lsb_ug = -2.0", "[readout] quantisation_lsb_ug = -2: must be a non-negative number of ug");
  // [frequency_study]: points out of range; to_Hz not above from_Hz, at to_Hz's line.
  p = case_replacing(t, "frequency.toml", "ode_points = 10", "ode_points = 2000");
  expect_error_at(p, "ode_points = 2000", "[frequency_study] ode_points = 2000: must be in [0, 1000]");
  p = case_replacing(t, "frequency.toml", "to_Hz = 5000.0", "to_Hz = 0.5");
  expect_error_at(p, "to_Hz = 0.5", "[frequency_study] to_Hz = 0.5: must be above from_Hz = 1");
  // An unknown key names the closest described one.
  p = case_with(t, "shake-sine-lab.toml", "[shake]", "blokcs = 3");
  EXPECT_NE(error_of(p).find("[shake] blokcs: unknown key (did you mean 'blocks'?)"), std::string::npos) << error_of(p);
  // A key set from elsewhere is no key of the table: [readout] seed comes from [run] seed.
  p = case_with(t, "shake-sine-lab.toml", "[readout]", "seed = 3");
  EXPECT_NE(error_of(p).find("[readout] seed: unknown key"), std::string::npos) << error_of(p);
}

TEST(CaseSettings, AScaledKeyArrivesInTheHeldUnitAndIsRecordedAsWritten) {
  // shake-sine-lab.toml: [readout] noise_sigma_ug = 20, quantisation_lsb_ug = 1; [run] seed.
  const io::Case c = io::read_case(std::string(VRELAB_CASES_DIR) + "/shake-sine-lab.toml");
  EXPECT_EQ(c.shake.readout.noise_sigma_g, 20 * 1e-6);  // as the reader always computed it
  EXPECT_EQ(c.shake.readout.quantisation_lsb_g, 1 * 1e-6);
  EXPECT_EQ(c.shake.readout.seed, c.seed);
  const nlohmann::json j = io::settings_json(c.shake);
  EXPECT_EQ(j["readout"]["noise_sigma_ug"], 20.0);
  EXPECT_EQ(j["readout"]["quantisation_lsb_ug"], 1.0);
  rectification::ShakeSettings back;
  io::settings_from_json(j, back);
  EXPECT_EQ(back.readout.noise_sigma_g, c.shake.readout.noise_sigma_g);
  // The frequency grid from its three keys, as the study's defaults give it.
  const io::Case f = io::read_case(std::string(VRELAB_CASES_DIR) + "/frequency.toml");
  rectification::FrequencyStudySettings d;
  rectification::FrequencyGrid{}.apply(d);
  EXPECT_EQ(f.frequency_study->frequencies_Hz, d.frequencies_Hz);
  EXPECT_EQ(f.frequency_study->ode_frequencies_Hz, d.ode_frequencies_Hz);
  EXPECT_EQ(f.frequency_study->frequencies_Hz.size(), 80u);
}

TEST(CaseSettings, IsValidFollowsTheDescribedRanges) {
  std::string why;
  EXPECT_TRUE(rectification::ShakeSettings{}.IsValid(&why)) << why;
  rectification::ShakeSettings s;
  s.min_measure_s = 2e6;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_EQ(why, "min_measure_s = 2000000: must be in [0, 1000000] s");
  s = {};
  s.readout.noise_sigma_g = -1e-6;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_EQ(why, "readout.noise_sigma_ug = -1: must be a non-negative number of ug");
  plant::SolverSettings v;
  v.absolute_tolerance = {1e-9, 0.0};
  EXPECT_FALSE(v.IsValid(&why));
  EXPECT_EQ(why, "absolute_tolerance[1] = 0: must be a positive number of state units");
  validation::StaticTestSettings st;
  EXPECT_TRUE(st.IsValid(&why)) << why;
  st.monte_carlo_trials = 1;
  EXPECT_FALSE(st.IsValid(&why));
  EXPECT_EQ(why, "monte_carlo_trials: needs at least 2 trials (or 0 for none)");
  st = {};
  st.monte_carlo_checkpoint.fingerprint = "two\nlines";
  EXPECT_FALSE(st.IsValid(&why));
  EXPECT_EQ(why, "monte_carlo_checkpoint.fingerprint: must be one line");
  // ReproduceSettings: the ranges (nested ones by their path), then what no range says.
  const io::Case c = io::read_case(std::string(VRELAB_CASES_DIR) + "/paper.toml");
  const validation::ReproduceSettings good = *c.reproduce;
  validation::ReproduceSettings r = good;
  r.invisible_shift_per_g = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(r.IsValid(&why));
  EXPECT_EQ(why, "invisible_shift_per_g = inf: must be a finite number of 1/g");
  r = good;
  r.errors.repeats = 0;
  EXPECT_FALSE(r.IsValid(&why));
  EXPECT_EQ(why, "errors.repeats = 0: must be in [1, 100000] visits");
  r = good;
  r.confirmation.direction.v = Vec3::Zero();
  EXPECT_FALSE(r.IsValid(&why));
  EXPECT_EQ(why, "confirmation.direction: not set (a zero vector)");
  r = good;
  r.orientations[0].v = Vec3(0, 0, 10);
  EXPECT_FALSE(r.IsValid(&why));
  EXPECT_NE(why.find("orientations: 'IA vertical': a static orientation is gravity"), std::string::npos) << why;
  r = good;
  r.positions.resize(4);  // 4 positions cannot identify the 10 coefficients not held fixed
  EXPECT_FALSE(r.IsValid(&why));
  EXPECT_EQ(why.rfind("positions: rank ", 0), 0u) << why;
}
