// FormatError's place as data (io/formats/error.hpp): for a case file, a lab campaign's
// static.csv and runs.csv and its manifest, each broken at one place, the error's file, line,
// column, table and key are that place. The expected place is found here in the text the test
// wrote (the line of the broken text counted from its newlines, the column from the header's
// cells or the bad byte's offset), not taken from the reader.
#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "io/formats/case_file.hpp"
#include "io/formats/error.hpp"
#include "io/formats/lab_data.hpp"
#include "support/files.hpp"

namespace test_format_error {

using namespace vrelab;
namespace fs = std::filesystem;
using vrelab::test::read_file;
using vrelab::test::TempDir;

namespace {

// The 1-based line of the first occurrence of `needle` in `text`.
long line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  long line = 1;
  for (std::size_t i = 0; i < at && i < text.size(); ++i) line += text[i] == '\n';
  return line;
}

// The text of line `line` (1-based) of `text`.
std::string line_text(const std::string& text, long line) {
  std::istringstream in(text);
  std::string s;
  for (long k = 0; k < line && std::getline(in, s); ++k) {
  }
  return s;
}

// The 1-based index of `name` among the comma-separated cells of `header`; 0 if absent.
long column_of(const std::string& header, const std::string& name) {
  std::istringstream in(header);
  long k = 0;
  for (std::string cell; std::getline(in, cell, ',');) {
    ++k;
    if (cell == name) return k;
  }
  return 0;
}

// The error read_case / read_campaign throws (a failure when none).
template <class F>
io::FormatError error_of(F&& read) {
  try {
    read();
  } catch (const io::FormatError& e) {
    return e;
  }
  ADD_FAILURE() << "no FormatError";
  return io::FormatError("none");
}

fs::path lab_copy(const TempDir& t) {
  const fs::path dir = t.path / "lab";
  fs::copy(fs::path(VRELAB_CASES_DIR) / "lab-example", dir, fs::copy_options::recursive);
  return dir;
}

}  // namespace

TEST(FormatError, AnUnknownKeyInACaseTableIsPlacedAtItsLineTableAndKey) {
  TempDir t;
  const std::string text = "# a case with one wrong key\ng_m_per_s2 = 9.81\n\n[range]\nlimit_g = 5.0\nbogus_key = 1.0\n";
  const std::string path = (t.path / "bad.toml").string();
  std::ofstream(path) << text;
  const io::FormatError e = error_of([&] { io::read_case(path); });
  const long line = line_of(text, "bogus_key");
  EXPECT_EQ(line, 6);  // the hand count of the text above
  EXPECT_EQ(e.where().file, path);
  EXPECT_EQ(e.where().line, line);
  EXPECT_EQ(e.where().column, 0);
  EXPECT_EQ(e.where().table, "range");
  EXPECT_EQ(e.where().key, "bogus_key");
  EXPECT_EQ(e.where().kind, io::KeyKind::toml_key);
  EXPECT_EQ(e.reason(), "unknown key");
  EXPECT_EQ(std::string(e.what()), path + ":" + std::to_string(line) + ": [range] bogus_key: unknown key");
}

TEST(FormatError, ANonFiniteTopLevelNumberAndASyntaxErrorAreOnTheirLines) {
  TempDir t;
  const std::string path = (t.path / "bad.toml").string();
  {
    const std::string text = "# gravity\n\ng_m_per_s2 = nan\n";
    std::ofstream(path) << text;
    const io::FormatError e = error_of([&] { io::read_case(path); });
    EXPECT_EQ(e.where().line, line_of(text, "g_m_per_s2"));
    EXPECT_EQ(e.where().table, "");  // the top level: the key alone
    EXPECT_EQ(e.where().key, "g_m_per_s2");
    EXPECT_EQ(std::string(e.what()).rfind(path + ":3: g_m_per_s2: must be a finite number", 0), 0u) << e.what();
  }
  {
    const std::string text = "[range]\nlimit_g = 5.0\n\n[orientation]\na_g = = [1.0, 0.0, 0.0]\n";
    std::ofstream(path) << text;
    const io::FormatError e = error_of([&] { io::read_case(path); });
    EXPECT_EQ(e.where().file, path);
    EXPECT_EQ(e.where().line, line_of(text, "a_g = ="));
    EXPECT_EQ(e.where().key, "");  // the parser names no key
  }
}

TEST(FormatError, ABadStaticCellIsPlacedAtItsLineColumnAndName) {
  TempDir t;
  const fs::path dir = lab_copy(t);
  const std::string file = (dir / "static.csv").string();
  std::string text = read_file(file);
  const std::string row = "\n1,60,";  // the first series' 60 degree position
  const std::size_t at = text.find(row);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, row.size(), "\n1,6x0,");
  std::ofstream(file) << text;
  const io::FormatError e = error_of([&] { io::read_campaign(dir.string()); });
  const long line = line_of(text, "\n1,6x0,") + 1;  // the row after the newline found
  const long column = column_of(line_text(text, line_of(text, "series,angle_deg")), "angle_deg");
  EXPECT_EQ(column, 2);  // series,angle_deg,...: the second cell
  EXPECT_EQ(line, 7);    // the hand count of cases/lab-example/static.csv
  EXPECT_EQ(e.where().file, file);
  EXPECT_EQ(e.where().line, line);
  EXPECT_EQ(e.where().column, column);
  EXPECT_EQ(e.where().key, "angle_deg");
  EXPECT_EQ(e.where().kind, io::KeyKind::csv_column);
  EXPECT_EQ(std::string(e.what()).rfind(file + ":" + std::to_string(line) + ":2: column angle_deg: '6x0' is not a number", 0), 0u)
      << e.what();
}

TEST(FormatError, ABadRunsCellIsPlacedAtItsLineAndColumn) {
  TempDir t;
  const fs::path dir = lab_copy(t);
  const std::string file = (dir / "runs.csv").string();
  const std::string original = read_file(file);
  {
    // A Latin-1 degree sign in the id of the run ia-100Hz-2g: the column is the bad byte's.
    std::string text = original;
    const std::string id = "\nia-100Hz-2g,";
    const std::size_t at = text.find(id);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, id.size(), "\nia-100Hz-2g\xB0,");
    std::ofstream(file) << text;
    const io::FormatError e = error_of([&] { io::read_campaign(dir.string()); });
    const long line = line_of(text, "\nia-100Hz-2g\xB0") + 1;
    const long column = static_cast<long>(line_text(text, line).find('\xB0')) + 1;
    EXPECT_EQ(column, 12);  // after the 11 characters of "ia-100Hz-2g"
    EXPECT_EQ(line, 5);     // the hand count of cases/lab-example/runs.csv
    EXPECT_EQ(e.where().file, file);
    EXPECT_EQ(e.where().line, line);
    EXPECT_EQ(e.where().column, column);
  }
  {
    // One cell more than the header on the run ia-10Hz-2g: the column is the one past the header's.
    std::string text = original;
    const std::string row = "\nia-10Hz-2g,";
    const std::size_t at = text.find(row);
    ASSERT_NE(at, std::string::npos);
    const std::size_t end = text.find('\n', at + 1);
    text.insert(end, ",7");
    std::ofstream(file) << text;
    const io::FormatError e = error_of([&] { io::read_campaign(dir.string()); });
    const std::string header = line_text(text, line_of(text, "id,frequency_Hz"));
    const long header_cells = column_of(header, "sigma_ug");  // the header's last cell
    EXPECT_EQ(header_cells, 11);
    EXPECT_EQ(e.where().file, file);
    EXPECT_EQ(line_of(text, "\nia-10Hz-2g,") + 1, 4);  // the hand count of cases/lab-example/runs.csv
    EXPECT_EQ(e.where().line, line_of(text, "\nia-10Hz-2g,") + 1);
    EXPECT_EQ(e.where().column, header_cells + 1);
  }
}

TEST(FormatError, ABadManifestKeyIsPlacedAtItsLineTableAndKey) {
  TempDir t;
  const fs::path dir = lab_copy(t);
  const std::string file = (dir / "manifest.toml").string();
  const std::string original = read_file(file);
  {
    const std::string text = original + "\n[diagnose]\nsignificance = 4.0\n";
    std::ofstream(file) << text;
    const io::FormatError e = error_of([&] { io::read_campaign(dir.string()); });
    const long line = line_of(text, "significance = 4.0");
    EXPECT_EQ(e.where().file, file);
    EXPECT_EQ(e.where().line, line);
    EXPECT_EQ(e.where().table, "diagnose");
    EXPECT_EQ(e.where().key, "significance");
    EXPECT_EQ(e.where().kind, io::KeyKind::toml_table);  // the reason names the key (the settings reader's sentence); the key is data too
    EXPECT_EQ(std::string(e.what()), file + ":" + std::to_string(line) + ": [diagnose] significance: unknown key");
  }
  {
    const std::string text = "colour = \"red\"\n" + original;  // a top-level key, line 1
    std::ofstream(file) << text;
    const io::FormatError e = error_of([&] { io::read_campaign(dir.string()); });
    EXPECT_EQ(e.where().line, 1);
    EXPECT_EQ(e.where().table, "");
    EXPECT_EQ(e.where().key, "colour");
    EXPECT_EQ(std::string(e.what()), file + ":1: colour: unknown key");
  }
}

// The message alone, for refusals without a place: what() is the message, the place empty.
TEST(FormatError, AMessageWithoutAPlaceIsTheMessage) {
  const io::InputError e("--checkpoint needs --monte-carlo N");
  EXPECT_EQ(std::string(e.what()), "--checkpoint needs --monte-carlo N");
  EXPECT_EQ(e.where().file, "");
  EXPECT_EQ(e.where().line, 0);
  EXPECT_EQ(e.where().kind, io::KeyKind::none);
}

}  // namespace test_format_error
