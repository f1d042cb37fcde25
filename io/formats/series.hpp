#pragma once
// io/formats/series.hpp -- a recorded series from a file, whatever its format: the one entry point
// of `vrelab measure` and of diagnose's raw records (io/formats/lab_data.cpp).
#include <functional>
#include <string>

#include "io/formats/csv.hpp"

namespace vrelab::io {

// By the file's extension: .h5 or .hdf5 (any case) is HDF5 (read_series_hdf5,
// io/formats/raw_hdf5.hpp), anything else CSV (read_series_csv, io/formats/csv.hpp). Both stream
// sample(t_s, output) in time order, then reference(...) for the same sample when the record
// has reference channels; both check the same things (time strictly increasing, finite
// samples, the output column/dataset present, every channel of one length) and throw
// FormatError naming the file and the line or dataset. Returns the output column's name.
std::string read_series(const std::string& path, const std::string& column,
                        const std::function<void(double t_s, double value)>& sample, const ReferenceSink& reference = {});

}  // namespace vrelab::io
