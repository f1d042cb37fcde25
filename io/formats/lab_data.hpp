#pragma once
// io/formats/lab_data.hpp -- the lab data format (docs/data-format.md): a campaign directory.
//
//   DIR/manifest.toml  instrument, units, gravity, nominal dynamics, identification's held
//                      coefficients, the names of the two files below, diagnose's
//                      settings ([diagnose], optional)
//   DIR/static.csv     the static readings: orientation (a_IA_g, a_PA_g, a_OA_g) or
//                      (series, angle_deg); output_<unit>; sigma_<unit> (one reading's);
//                      count (readings averaged; optional, 1)
//   DIR/runs.csv       the shaker runs: id, frequency_Hz, amplitude_g, d_IA, d_PA, d_OA,
//                      a_IA_g, a_PA_g, a_OA_g, and either measured_ug and sigma_ug (a
//                      summary) or series (a CSV of time_s and output_<unit>, read
//                      streaming) with rest_from_s, rest_to_s, on_from_s, on_to_s
//
// read_campaign: bad input throws FormatError (io/formats/error.hpp) with the file, the line
// and the column or key; a run that cannot be used (a NaN, a series shorter than its
// intervals, a missing series file) is skipped and listed in Campaign::skipped with why; the
// others are diagnosed.
// write_campaign: the same format, written atomically file by file.
#include <string>

#include <nlohmann/json.hpp>

#include "io/formats/csv.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "vibration/random.hpp"

namespace vrelab::io {

struct LabManifest {
  std::string name = "campaign";
  std::string output_unit = "mA";
  double g_m_per_s2 = 9.80665;
  bool dynamics_given = false;  // the manifest has a [dynamics] table
  // The optional [diagnose] table: DiagnoseSettings' fields by name (its Describe); defaults elsewhere.
  validation::DiagnoseSettings diagnose;
  bool diagnose_given = false;
  // The optional [names] table: the lab's own names of the columns and datasets of the files
  // the runs reference (PSD files, raw records; vrelab's name -> the lab's).
  ChannelNames names;
};

validation::Campaign read_campaign(const std::string& dir, LabManifest* manifest = nullptr);

// A random run's PSD file as read_campaign reads the file a run's `psd` cell names
// (docs/data-format.md, "Random runs"); `coupling`: "common" or "independent". Bad content
// (a frequency or level outside its range among it) throws FormatError at the file, line and column.
// `names`: the lab's own column names (frequency_Hz, psd_<axis>_g2_per_Hz -> a controller
// export's "Frequency (Hz)", ...; LabManifest::names).
vibration::RandomProfile read_psd_file(const std::string& path, const std::string& coupling = "common",
                                       const ChannelNames& names = {});

// Writes manifest.toml, static.csv and runs.csv (summaries). `raw_series`, when non-empty,
// gives per run a recorded series already written under DIR (file name, rest and on
// windows) to reference instead of the summary; else, when the campaign holds raw records
// (Campaign::raw), they are written as DIR/records/<run id>.csv (RawFormat::csv) or
// DIR/records/<run id>.h5 (RawFormat::hdf5, docs/data-format.md "Raw records in HDF5"),
// each atomically, and referenced.
enum class RawFormat { csv, hdf5 };
struct RawSeriesRef {
  std::string file;
  double rest_from_s = 0, rest_to_s = 0, on_from_s = 0, on_to_s = 0;
};
void write_campaign(const std::string& dir, const validation::Campaign& c, const LabManifest& m,
                    const std::vector<RawSeriesRef>& raw_series = {}, RawFormat raw_format = RawFormat::csv);

}  // namespace vrelab::io
