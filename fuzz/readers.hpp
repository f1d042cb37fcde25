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

// A random run's PSD table (io::read_psd_file), written to a temporary file. An accepted
// table must be within the physical ranges (io/formats/ranges.hpp) with a finite rms.
void psd_table(const std::uint8_t* data, std::size_t size);
// A raw CSV record with reference channels through `vrelab measure` (io::measure: the
// series reader, the reference analysis and the report's checks), written to a temporary
// file and measured twice over rest [0, 1) s and vibration [1, 2) s: as a sine run of 10 Hz
// (the tones) and as a random run (Welch).
void raw_csv(const std::uint8_t* data, std::size_t size);
// An HDF5 raw record (io::read_series_hdf5) through `vrelab measure` as raw_csv. The bytes
// describe the file (write_hdf5_record): the HDF5 library's own parser of corrupt files is
// not this project's code (nor instrumented), what the reader decides about the datasets is.
void raw_hdf5(const std::uint8_t* data, std::size_t size);

// The files a target gives its reader, for the CLI (tests/cli/cli_corpus.sh): a lab_data
// input as a campaign folder `dir`, a raw_hdf5 input as an HDF5 file `path`.
void write_lab_data(const std::uint8_t* data, std::size_t size, const std::string& dir);
// The bytes as an HDF5 record: byte 0 the number of datasets (1 + b % 6); then per dataset a
// name (time_s, output_mA, output_V, ref_IA_g, ref_PA_g, ref_OA_g, input_PA_g, or a group
// named output_mA), a type (float64, float32, int32, uint8, a string, a 2-D float64), a
// `units` attribute (none, the name's, "V", "s"), a length (2 bytes little-endian, modulo
// 8193), a storage (contiguous, chunked, deflated), a fill and its parameter byte b: a time
// ramp (t = -0.5 + i dt, dt = (b + 1) / 2000 s), a 10 Hz sine of amplitude b / 16 about 0.5
// on that time base, a constant (the next 8 bytes as a double), or the following bytes as
// doubles. Missing bytes read as zero.
void write_hdf5_record(const std::uint8_t* data, std::size_t size, const std::string& path);

// The target of a name ("case_file", "lab_data", "series", "psd_table", "raw_csv",
// "raw_hdf5"), or nullptr.
using Target = void (*)(const std::uint8_t*, std::size_t);
Target target(const std::string& name);

}  // namespace vrelab::fuzz
