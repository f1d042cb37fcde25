// Settings described once (core/settings_description.hpp): every field of DiagnoseSettings'
// description, set to a value other than its default, arrives through each surface that
// iterates the description -- the manifest's [diagnose] table, the command line's flags, the
// caller's overrides -- and the JSON record of the settings used holds every field. IsValid
// follows the ranges; a bad key or value names the file, the line and the key. The Python
// keywords are checked in tests/python/test_settings_keywords.py. Fast (no diagnosis).
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/settings_cli.hpp"
#include "io/formats/case_file.hpp"
#include "io/formats/lab_data.hpp"
#include "io/services/diagnosis.hpp"
#include "io/services/diagnosis_json.hpp"
#include "support/files.hpp"
#include "support/lab_manifest.hpp"
#include "validation/diagnosis/blind.hpp"
#include "validation/diagnosis/settings.hpp"

using namespace vrelab;
namespace fs = std::filesystem;
using vrelab::test::TempDir;
using vrelab::test::error_of;
using vrelab::test::lab_with;
using Settings = validation::DiagnoseSettings;

namespace {

// A value of f other than its default, inside its range: not the default's negation for a
// flag, the default + 1 (or - 1) for a count, 1.25 x default + 0.25 (or the midpoint to the
// lower bound) for a number. Each is exact as text (shortest round trip).
template <class F>
typename F::Type other_value(const F& f, const typename F::Type& d) {
  using T = typename F::Type;
  if constexpr (std::is_same_v<T, bool>) {
    return !d;
  } else if constexpr (std::is_integral_v<T>) {
    return core::admissible(f, static_cast<T>(d + 1)) ? static_cast<T>(d + 1) : static_cast<T>(d - 1);
  } else {
    const T up = d * 1.25 + 0.25;
    if (core::admissible(f, up)) return up;
    return (d + (f.range.has_min ? f.range.min : d - 1)) / 2;
  }
}

// Settings with every field at other_value, and how many fields there are.
Settings all_other(int* fields) {
  const Settings d;
  Settings s;
  int n = 0;
  core::for_each_field<Settings>([&](const auto& f) {
    s.*f.member = other_value(f, d.*f.member);
    ++n;
  });
  *fields = n;
  return s;
}

// Each field of `got` equals `want`'s, and differs from the default (the value was set);
// returns the fields checked.
int expect_all_equal(const Settings& got, const Settings& want, const std::string& surface) {
  const Settings d;
  int n = 0;
  core::for_each_field<Settings>([&](const auto& f) {
    EXPECT_EQ(got.*f.member, want.*f.member) << surface << ": " << f.name;
    EXPECT_NE(got.*f.member, d.*f.member) << surface << ": " << f.name << " kept its default";
    ++n;
  });
  return n;
}

}  // namespace

TEST(SettingsDescription, DiagnoseSettingsHasEightFieldsAndItsDefaultsAreValid) {
  // The struct's eight members (settings.hpp), each described once.
  EXPECT_EQ(core::field_count<Settings>(), 8);
  std::string why;
  EXPECT_TRUE(Settings{}.IsValid(&why)) << why;
  int n = 0;
  const Settings s = all_other(&n);
  EXPECT_TRUE(s.IsValid(&why)) << why;
}

TEST(SettingsDescription, EveryFieldArrivesThroughTheManifestsDiagnoseTable) {
  int fields = 0;
  const Settings want = all_other(&fields);
  std::string table = "[diagnose]\n";
  core::for_each_field<Settings>(
      [&](const auto& f) { table += std::string(f.name) + " = " + core::format_value(want.*f.member) + "\n"; });
  TempDir t;
  io::LabManifest m;
  io::read_campaign(lab_with(t, table).string(), &m);
  EXPECT_TRUE(m.diagnose_given);
  EXPECT_EQ(expect_all_equal(m.diagnose, want, "[diagnose]"), fields);
}

TEST(SettingsDescription, EveryFieldArrivesThroughTheCommandLine) {
  int fields = 0;
  const Settings want = all_other(&fields);
  std::vector<std::string> args;  // CLI11 parses a reversed vector
  core::for_each_field<Settings>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    std::string flag(f.name);
    for (char& ch : flag)
      if (ch == '_') ch = '-';
    if constexpr (std::is_same_v<T, bool>) {
      args.push_back((want.*f.member ? "--" : "--no-") + flag);
    } else {
      args.push_back("--" + flag);
      args.push_back(core::format_value(want.*f.member));
    }
  });
  CLI::App app("test");
  io::DiagnoseOverrides o;
  app::add_override_flags(&app, o);
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  app.parse(reversed);
  Settings s;
  o.apply(s);
  EXPECT_EQ(expect_all_equal(s, want, "argv"), fields);
}

TEST(SettingsDescription, TheDocumentedFlagNamesStillParse) {
  // README's and docs/data-format.md's flags, by hand.
  CLI::App app("test");
  io::DiagnoseOverrides o;
  app::add_override_flags(&app, o);
  std::vector<std::string> args{"--significance-sigma", "4", "--model-accuracy", "0.01", "--explained-shrinkage",
                                "0.8", "--resimulate-runs", "0", "--no-pairs"};
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  app.parse(reversed);
  Settings s;
  o.apply(s);
  EXPECT_EQ(s.significance_sigma, 4.0);
  EXPECT_EQ(s.model_accuracy, 0.01);
  EXPECT_EQ(s.explained_shrinkage, 0.8);
  EXPECT_EQ(s.resimulate_runs, 0);
  EXPECT_FALSE(s.try_pairs);
  EXPECT_TRUE(s.advise_next_runs);  // not given: the default
}

TEST(SettingsDescription, OverridesWinOverTheManifestAndTheJsonRecordHasEveryField) {
  int fields = 0;
  const Settings want = all_other(&fields);
  io::DiagnoseOverrides o;
  core::for_each_field<Settings>([&](const auto& f) { o.set(f.member, want.*f.member); });
  TempDir t;
  // The manifest sets two fields to yet other values: the overrides win.
  const io::FolderDiagnosis f =
      io::read_folder(lab_with(t, "[diagnose]\nsignificance_sigma = 4.5\ntry_pairs = true\n").string(), o);
  EXPECT_EQ(expect_all_equal(f.settings, want, "overrides"), fields);
  EXPECT_NE(f.settings_from.find("set over by the caller"), std::string::npos) << f.settings_from;
  // The record diagnose's JSON writes as "settings" (to_json(FolderDiagnosis) adds "from").
  const nlohmann::json j = io::to_json(f.settings);
  int found = 0;
  core::for_each_field<Settings>([&](const auto& x) {
    ASSERT_TRUE(j.contains(std::string(x.name))) << x.name;
    EXPECT_EQ(j[std::string(x.name)].get<std::decay_t<decltype(want.*x.member)>>(), want.*x.member) << x.name;
    ++found;
  });
  EXPECT_EQ(found, fields);
  EXPECT_EQ(static_cast<int>(j.size()), fields);
}

TEST(SettingsDescription, IsValidFollowsTheRangesNamingFieldValueAndRule) {
  // Hand-written messages for values just outside each bound kind.
  const std::vector<std::string> expected{"model_accuracy = 1: must be in [0, 1)",
                                          "significance_sigma = -1: must be a positive number of sigma",
                                          "explained_shrinkage = 0: must be in (0, 1]",
                                          "resimulate_runs = -1: must be in [0, 1000000] runs",
                                          "ambiguity_evidence = -0.5: must be a non-negative number"};
  std::vector<std::string> got;
  std::string why;
  Settings s;
  s.model_accuracy = 1;
  EXPECT_FALSE(s.IsValid(&why));
  got.push_back(why);
  s = {}, s.significance_sigma = -1;
  EXPECT_FALSE(s.IsValid(&why));
  got.push_back(why);
  s = {}, s.explained_shrinkage = 0;
  EXPECT_FALSE(s.IsValid(&why));
  got.push_back(why);
  s = {}, s.resimulate_runs = -1;
  EXPECT_FALSE(s.IsValid(&why));
  got.push_back(why);
  s = {}, s.ambiguity_evidence = -0.5;
  EXPECT_FALSE(s.IsValid(&why));
  got.push_back(why);
  EXPECT_EQ(got, expected);
  // A non-finite number is out of any range; the first bad field is the one named.
  s = {}, s.structure_sigma = INFINITY, s.significance_sigma = 0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_EQ(why.rfind("significance_sigma = 0", 0), 0u) << why;
  s.significance_sigma = 5;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_EQ(why.rfind("structure_sigma = inf", 0), 0u) << why;
}

TEST(SettingsDescription, ABadKeyTypeOrRangeInTheManifestNamesFileLineAndKey) {
  struct Case {
    std::string table_tail, expected;
  };
  // Each bad line is the table's second line.
  const std::vector<Case> cases{{"significanc_sigma = 4\n", "[diagnose] significanc_sigma: unknown key"},
                                {"model_accuracy = \"small\"\n", "[diagnose] model_accuracy: expected a number"},
                                {"resimulate_runs = 2.5\n", "[diagnose] resimulate_runs: expected a whole number of runs"},
                                {"try_pairs = 1\n", "[diagnose] try_pairs: expected true or false"},
                                {"explained_shrinkage = 1.5\n", "[diagnose] explained_shrinkage = 1.5: must be in (0, 1]"},
                                {"advise_next_runs = \"no\"\n", "[diagnose] advise_next_runs: expected true or false"}};
  int checked = 0;
  for (const Case& c : cases) {
    TempDir t;
    int first = 0;
    const fs::path dir = lab_with(t, "[diagnose]\n" + c.table_tail, &first);
    const std::string expected = (dir / "manifest.toml").string() + ":" + std::to_string(first + 1) + ": " + c.expected;
    EXPECT_EQ(error_of(dir), expected);
    ++checked;
  }
  EXPECT_EQ(checked, 6);
}

TEST(SettingsDescription, BlindSettingsDescribeTheirFieldsAndNestTheDiagnosis) {
  validation::BlindSettings b;
  b.n = 3, b.seed = 11, b.threads = 2, b.mixed = true, b.diagnose.structure_sigma = 2.5;
  const nlohmann::json j = io::to_json(b);
  EXPECT_EQ(j.size(), 5u);
  EXPECT_EQ(j["mixed"], true);
  EXPECT_EQ(j["n"], 3);
  EXPECT_EQ(j["seed"], 11);
  EXPECT_EQ(j["threads"], 2);
  EXPECT_EQ(j["diagnose"].size(), 8u);
  EXPECT_EQ(j["diagnose"]["structure_sigma"], 2.5);
  std::string why;
  b.threads = -1;
  EXPECT_FALSE(b.IsValid(&why));
  EXPECT_EQ(why, "threads = -1: must be a non-negative number of threads");
  b.threads = 0, b.diagnose.explained_shrinkage = 2;
  EXPECT_FALSE(b.IsValid(&why));
  EXPECT_EQ(why, "diagnose.explained_shrinkage = 2: must be in (0, 1]");
  // Blind's CLI: --n, --seed, --threads from the description.
  CLI::App app("test");
  validation::BlindSettings c;
  app::add_settings_flags(&app, c);
  std::vector<std::string> args{"--n", "4", "--seed", "9", "--threads", "5"};
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  app.parse(reversed);
  EXPECT_EQ(c.n, 4);
  EXPECT_EQ(c.seed, 9u);
  EXPECT_EQ(c.threads, 5);
}
