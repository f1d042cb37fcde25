#pragma once
// fuzz/readers.hpp -- the readers as fuzz targets: one function per reader that takes bytes,
// feeds them to the library's reader the way a user's file would come, and returns normally
// when the reader either accepts them or refuses them as bad input.
//
// A refusal is what the CLI answers with exit code 2: io::InputError, plant::SolverError or
// std::invalid_argument. Anything else escapes (another exception, which the CLI reports as an
// internal error with exit 1) or aborts (a crash, an ASan/UBSan report): that is a finding.
// The same functions are called by libFuzzer (fuzz_<target>, VRELAB_FUZZ=ON, clang) and by
// the replay program of the normal build (vrelab_fuzz_replay), which runs the inputs kept in
// fuzz/regressions/<target>/ and fuzz/corpus/<target>/ as a fast test.
#include <cstddef>
#include <cstdint>
#include <string>

namespace vrelab::fuzz {

// A case file (io::read_case), written to a temporary file.
void case_file(const std::uint8_t* data, std::size_t size);
// A lab data campaign (io::read_campaign): the input is split at lines "%%" into
// manifest.toml, static.csv, runs.csv and rec.csv (a raw record a runs.csv may name),
// written into a temporary folder.
void lab_data(const std::uint8_t* data, std::size_t size);
// `measure`'s series (io::read_series_csv, in memory) into the measurement
// (rectification::SeriesMeasurer) with windows [0, 1) at rest and [1, 2) under vibration.
void series(const std::uint8_t* data, std::size_t size);

// The target of a name ("case_file", "lab_data", "series"), or nullptr.
using Target = void (*)(const std::uint8_t*, std::size_t);
Target target(const std::string& name);

}  // namespace vrelab::fuzz
