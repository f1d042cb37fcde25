#pragma once
// io/formats/ranges.hpp -- the physical ranges of the numbers in lab data (docs/data-format.md,
// "Ranges and limits"), one table for every reader: PSD tables, runs.csv, static.csv and raw
// records (CSV and HDF5).
//
// A number outside its range is refused where it is read (file, line or sample, column or
// dataset), before any computation: beyond them a value is a slip (Hz for kHz, a sample in
// the wrong unit, a DAQ's overflow code such as 1e308), and the computations would overflow
// (a PSD of 1e300 g^2/Hz: chi^2 nan) or take hours (a breakpoint at 1e300 Hz: the PSD
// integral's quadrature grows with ln(f_max / f_min)). The bounds lie far outside every
// shaker test and far inside double's range.
//
// The size limits bound the work that grows with a file's rows (the identification with
// the static readings, the diagnosis' runs x runs covariance with the runs); a file over them
// is refused at its first row past the limit, with the number.
#include <cstddef>
#include <string>

namespace vrelab::io {

struct PhysicalRange {
  const char* quantity;  // "a frequency", for messages
  double min, max;       // closed unless min_open
  bool min_open;         // (min, max]
  bool magnitude;        // the bounds are on |x| (a signed quantity)
  const char* unit;      // "Hz"
};

inline constexpr PhysicalRange kFrequencyRange{"a frequency", 0.01, 1e5, false, false, "Hz"};
inline constexpr PhysicalRange kPsdLevelRange{"a PSD level", 1e-20, 1e4, false, false, "g^2/Hz"};
inline constexpr double kPsdMaxRms_g = 1000;  // a table's rms, as the case files' amplitude limit
inline constexpr PhysicalRange kAmplitudeRange{"an amplitude", 0, 1000, true, false, "g"};
inline constexpr PhysicalRange kErrorRange{"a vibration error", 0, 1e9, false, true, "ug"};
inline constexpr PhysicalRange kSigmaUgRange{"a sigma", 0, 1e9, true, false, "ug"};
inline constexpr PhysicalRange kOutputRange{"an output", 0, 1e12, false, true, "output units"};
inline constexpr PhysicalRange kOutputSigmaRange{"an output's sigma", 0, 1e12, true, false, "output units"};
inline constexpr PhysicalRange kTimeRange{"a time", 0, 1e9, false, true, "s"};
inline constexpr PhysicalRange kReferenceRange{"a reference acceleration", 0, 1e5, false, true, "g"};

inline constexpr std::size_t kMaxStaticReadings = 1000000;  // rows of static.csv
inline constexpr std::size_t kMaxRuns = 2000;               // rows of runs.csv
inline constexpr std::size_t kMaxPsdRows = 10000000;        // rows of a PSD file

// "" when x lies in r, else the reason: "1e+300 Hz is outside a frequency's range [0.01,
// 1e+05] Hz (docs/data-format.md, Ranges and limits)".
std::string range_problem(const PhysicalRange& r, double x);

// The reason a file holds more rows than `limit` ("more than 1000000 rows of static readings
// ...; docs/data-format.md, Ranges and limits").
std::string rows_problem(std::size_t limit, const std::string& what, const std::string& why);

}  // namespace vrelab::io
