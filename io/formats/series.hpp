#pragma once
// io/formats/series.hpp -- a recorded series from a file, whatever its format: the one entry point
// of `vrelab measure` and of diagnose's raw records (io/formats/lab_data.cpp).
#include <functional>
#include <optional>
#include <string>

#include "io/formats/csv.hpp"

namespace vrelab::io {

// By the file's extension: .h5 or .hdf5 (any case) is HDF5 (read_series_hdf5,
// io/formats/raw_hdf5.hpp), anything else CSV (read_series_csv, io/formats/csv.hpp). Both stream
// sample(t_s, output) in time order, then reference(...) for the same sample when the record
// has reference channels; both check the same things (time strictly increasing, finite
// samples, the output column/dataset present, every channel of one length) and throw
// FormatError naming the file and the line or dataset. Returns the output column's name.
// `names`: the lab's own names of the columns or datasets (ChannelNames, io/formats/csv.hpp).
std::string read_series(const std::string& path, const std::string& column,
                        const std::function<void(double t_s, double value)>& sample, const ReferenceSink& reference = {},
                        const ChannelNames& names = {});

// The scale factor a CSV series states in a comment line before its header, `K1 = <value>
// <unit>/g` (as `vrelab shake --series` writes it: "# output in mA; K1 = 1.25 mA/g; ..."), or
// nullopt: none stated, or an HDF5 record (no such attribute yet). A stated K1 that is not a
// positive finite number is FormatError at the file and the line.
struct StatedScaleFactor {
  double K1 = 0;     // output units per g
  std::string unit;  // the output unit, as stated ("mA")
  long line = 0;
};
std::optional<StatedScaleFactor> stated_scale_factor(const std::string& path);

// The unit an output column's name carries (output_<unit>: "mA" for output_mA), "" for none.
std::string output_unit_of(const std::string& column);

}  // namespace vrelab::io
