#pragma once
// Test support: the shipped hand-written campaign (cases/lab-example) copied with a table
// appended to its manifest, and the reader's message for such a folder.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "io/formats/error.hpp"
#include "io/formats/lab_data.hpp"
#include "support/files.hpp"

namespace vrelab::test {

// cases/lab-example copied to t/lab with `table` appended to its manifest (after a blank
// line); *first_line: the manifest's line number of the table's first line.
inline std::filesystem::path lab_with(const TempDir& t, const std::string& table, int* first_line = nullptr) {
  namespace fs = std::filesystem;
  const fs::path dir = t.path / "lab";
  fs::copy(fs::path(VRELAB_CASES_DIR) / "lab-example", dir, fs::copy_options::recursive);
  std::ifstream in(dir / "manifest.toml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  // The text, a newline if it lacks one, a blank line, then the table.
  int lines = 0;
  for (char ch : text) lines += ch == '\n';
  const bool ends = !text.empty() && text.back() == '\n';
  std::ofstream(dir / "manifest.toml", std::ios::app) << (ends ? "" : "\n") << "\n" << table;
  if (first_line) *first_line = lines + (ends ? 0 : 1) + 2;
  return dir;
}

// What reading the campaign folder `dir` throws ("" when it reads).
inline std::string error_of(const std::filesystem::path& dir) {
  try {
    io::read_campaign(dir.string());
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace vrelab::test
