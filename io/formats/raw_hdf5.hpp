#pragma once
// io/formats/raw_hdf5.hpp -- raw records in HDF5 (docs/data-format.md, "Raw records in HDF5"): one
// file per run, one 1-D dataset per channel, all of one length:
//   time_s              the sample times, s, strictly increasing
//   output_<unit>       the instrument's output in the manifest's unit
//   ref_IA_g, ref_PA_g, ref_OA_g   optional reference-accelerometer channels, g (input_*_g too)
// each with a string attribute `units` ("s", the unit, "g"). Read in bounded hyperslabs
// (kHdf5BlockSamples samples per channel at a time): memory does not grow with the record.
// The reader delivers the same callbacks, in the same order, with the same checks as
// read_series_csv (io/formats/csv.hpp); anything wrong is FormatError naming the file and the dataset.
#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "io/formats/csv.hpp"

namespace vrelab::io {

// Samples per channel read (and written) at a time: 64 Ki doubles, 512 KiB per channel.
inline constexpr std::size_t kHdf5BlockSamples = 65536;

// True for a path ending in .h5 or .hdf5 (any case): read_series reads it as HDF5.
bool is_hdf5_path(const std::string& path);

// `column`: the output dataset's name; empty: the one dataset whose name starts with
// "output_" (several: FormatError naming them). Returns the output dataset's name. `names`
// maps a dataset vrelab names (time_s, output_<unit>, ref_<axis>_g) to the lab's path in the
// file, in any group ("/daq/t"; ChannelNames).
std::string read_series_hdf5(const std::string& path, const std::string& column,
                             const std::function<void(double t_s, double value)>& sample,
                             const ReferenceSink& reference = {}, const ChannelNames& names = {});

// Writes a record streaming: chunked datasets (kHdf5BlockSamples samples per chunk) grown as
// samples come, to `path`.tmp.<pid>, renamed to `path` by commit(); a writer destroyed
// without commit() removes its temporary file. HDF5 errors are FormatError naming the file.
class Hdf5SeriesWriter {
 public:
  // `output_unit`: the dataset output_<unit>; `reference`: which ref_<axis>_g datasets to
  // write; `run_id`, `comment`: file attributes.
  Hdf5SeriesWriter(const std::string& path, const std::string& output_unit, const std::array<bool, 3>& reference = {},
                   const std::string& run_id = "", const std::string& comment = "");
  ~Hdf5SeriesWriter();
  Hdf5SeriesWriter(const Hdf5SeriesWriter&) = delete;
  Hdf5SeriesWriter& operator=(const Hdf5SeriesWriter&) = delete;
  void add(double t_s, double output, const std::array<double, 3>& ref_g = {});
  void commit();

 private:
  struct State;
  std::unique_ptr<State> s_;
  void flush();
  void create_datasets(const std::string& output_unit, const std::string& run_id, const std::string& comment);
};

}  // namespace vrelab::io
