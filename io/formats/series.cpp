#include "io/formats/series.hpp"

#include "io/formats/raw_hdf5.hpp"

namespace vrelab::io {

std::string read_series(const std::string& path, const std::string& column,
                        const std::function<void(double t_s, double value)>& sample, const ReferenceSink& reference) {
  if (is_hdf5_path(path)) return read_series_hdf5(path, column, sample, reference);
  return read_series_csv(path, column, sample, reference);
}

}  // namespace vrelab::io
