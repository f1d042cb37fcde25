#pragma once
// io/formats/error.hpp -- the one error of the file readers and writers: what is wrong in a
// file, and where, as data.
//
// Takes: the place (file, line, column, the TOML table and key, the CSV column or the HDF5
//        dataset and element, each optional) and the reason in words.
// Gives: FormatError, a std::runtime_error whose what() is composed from the place and the
//        reason, as users read it on the command line:
//          <file>[:<line>[:<column>]]: [<place>: ]<reason>
//        <place> by KeyKind: toml_key "[table] key" ("[table]" without a key, "key" at the
//        top level); toml_table writes "[table] <reason>" (a sentence about the table);
//        csv_column "column <name>"; hdf5_dataset "dataset <name>[<element>]"; none writes
//        no place (a key, if given, is data only and the reason names it). Code that needs
//        the place (which table to blame, the line to point at) reads where(), never the
//        text. A FormatError made from a message alone has no place: the CLI's and the
//        services' own refusals of bad input (a flag, a missing table) are made so.
// InputError is the same type under the name the CLI, the services and Python catch: bad
// input of any kind, exit code 2.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace vrelab::io {

// What the key of a FormatLocation names, and so how the message writes it. toml_table: the
// reason is a sentence about the table, written "[table] reason" (no key).
enum class KeyKind { none, toml_key, toml_table, csv_column, hdf5_dataset };

struct FormatLocation {
  std::string file{};      // empty: none
  long line = 0;           // 1-based; 0: none
  long column = 0;         // 1-based, after the line: a CSV cell's index or a byte of the line; 0: none
  std::string table{};     // the TOML table of `key` ("vibration", "plant.effects"); empty: the top level
  std::string key{};       // the TOML key, CSV column or HDF5 dataset the reason is about; empty: none
  KeyKind kind = KeyKind::none;
  long long element = -1;  // an HDF5 dataset's element (0-based); -1: none
};

class FormatError : public std::runtime_error {
 public:
  FormatError(FormatLocation where, std::string reason)
      : std::runtime_error(compose(where, reason)), where_(std::move(where)), reason_(std::move(reason)) {}
  // A refusal without a place: the message is the reason.
  explicit FormatError(const std::string& message) : std::runtime_error(message), reason_(message) {}
  explicit FormatError(const char* message) : FormatError(std::string(message)) {}

  const FormatLocation& where() const { return where_; }
  const std::string& reason() const { return reason_; }

  // "[table] key", "column name", "dataset name[element]", or "" (KeyKind::none, toml_table).
  static std::string place(const FormatLocation& w) {
    std::string p;
    switch (w.kind) {
      case KeyKind::csv_column:
        p.append("column ").append(w.key);
        break;
      case KeyKind::hdf5_dataset:
        p.append("dataset ").append(w.key);
        if (w.element >= 0) p.append("[").append(std::to_string(w.element)).append("]");
        break;
      case KeyKind::toml_key:
        if (!w.table.empty()) p.append("[").append(w.table).append(w.key.empty() ? "]" : "] ");
        p.append(w.key);
        break;
      case KeyKind::toml_table:
      case KeyKind::none: break;
    }
    return p;
  }

  static std::string compose(const FormatLocation& w, const std::string& reason) {
    std::string s = w.file;
    if (w.line > 0) {
      s.append(":").append(std::to_string(w.line));
      if (w.column > 0) s.append(":").append(std::to_string(w.column));
    }
    std::string said;
    if (w.kind == KeyKind::toml_table) said.append("[").append(w.table).append("] ");
    said.append(reason);
    for (const std::string& part : {place(w), said}) {
      if (part.empty()) continue;
      if (!s.empty()) s.append(": ");
      s.append(part);
    }
    return s;
  }

 private:
  FormatLocation where_;
  std::string reason_;
};

using InputError = FormatError;

}  // namespace vrelab::io
