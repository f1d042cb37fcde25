#pragma once
// io/formats/output.hpp -- writing results: atomically, with the record of how they were made.
#include <string>

#include <nlohmann/json.hpp>

#include "io/formats/case_file.hpp"

namespace vrelab::io {

// Writes `text` to `path` through a temporary file in the same folder and a rename, so a
// reader never sees a partial file and a failed run leaves no file. Creates the folder.
// A path that cannot be written throws FormatError (io/formats/error.hpp; exit code 2).
void write_atomic(const std::string& path, const std::string& text);

// A result's JSON as written to file: indented by 2, ending in a newline. Text in a result
// that is not UTF-8 can only come from a path (data files are refused at read time when they
// are not UTF-8: io/formats/csv.hpp, and TOML is UTF-8 by its grammar): its bad bytes are written as
// U+FFFD, so a run in a folder named in Latin-1 still writes its result instead of failing
// after the computation (nlohmann's error_handler_t::replace).
std::string json_text(const nlohmann::json& j);

// The JSON path of the first number of `j` that is not finite ("/runs/3/z"), or "" when all
// are: a result's numbers are checked before it is printed or written.
std::string first_non_finite(const nlohmann::json& j);
// FormatError "<source>: the result <path> is not a finite number (nan): <why>" when `j` holds
// one (exit code 2: a value of the input drove the computation out of range).
void require_finite(const nlohmann::json& j, const std::string& source, const std::string& why);

// {"name", "version", "git"}: the program that made a result.
nlohmann::json program_record();
// {"file", "content"}: the case a result was made from.
nlohmann::json case_record(const Case& c);
// The head of every result from a case: {"program", "command", "case", "seed"}.
nlohmann::json result_record(const std::string& command, const Case& c);

// The JSON forms shared by the commands' results.
std::string unit_of(int coefficient, const Case& c);  // "mA/g", "1/g", ...
nlohmann::json coefficients_json(const plant::Coefficients& k, const validation::CoefFlags* available = nullptr);
nlohmann::json vec_json(const Vec3& v);
nlohmann::json plant_json(const plant::PlantConfig& p, bool physical);

// Runs tools/plots/<script> on `dir` with the first Python that has matplotlib (Debian's
// /usr/bin/python3 first). Returns "" when the figures were drawn, else why not (the data
// stay in `dir`).
std::string run_plot_script(const std::string& script, const std::string& dir);

}  // namespace vrelab::io
