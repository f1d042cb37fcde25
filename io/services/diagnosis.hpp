#pragma once
// io/services/diagnosis.hpp -- the diagnosis stage on files: the library calls behind `vrelab campaign`
// and `vrelab diagnose` (docs/diagnose.md, docs/data-format.md).
//
// write_virtual_campaign takes a case file with [coefficients], [plant] and [campaign], simulates
//   the campaign (validation/diagnosis/campaign.hpp) and writes it in the lab data format with
//   its raw records when the case asks for them, and the answer key (JSON) apart.
// diagnose_folder takes a campaign folder and settings a caller sets on top of the manifest's
//   optional [diagnose] table, checks them, and diagnoses the campaign.
// Both throw InputError on bad input (naming the file, the key and why). Their results print
// themselves briefly or fully (without the program's name and version: the caller's).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "io/formats/lab_data.hpp"
#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::io {

struct CampaignRequest {
  std::string case_path, out_dir;
  std::string key_path;               // the answer key; "": <out_dir>.key.json
  std::optional<std::uint64_t> seed;  // default: the case's [run] seed
  bool progress = false;              // draw core::Progress on stderr
  RawFormat raw_format = RawFormat::csv;  // raw records (the case's [campaign] raw_sample_rate_Hz) as CSV or HDF5
};

struct CampaignWritten {
  CampaignRequest request;  // key_path and seed filled in
  std::size_t statics = 0, runs = 0;
  bool raw_records = false;  // runs written as raw records (records/<id>.csv or .h5)
  double wall_s = 0;         // simulation and writing
  std::string BriefReport() const;
  std::string FullReport() const;
  // "diagnose DIR", the counts, the skipped runs, then what was read (read_folder's result).
  std::string CheckReport() const;
};

CampaignWritten write_virtual_campaign(const CampaignRequest& request);

// DiagnoseSettings set on top of the manifest's [diagnose] (e.g. from a command line): each
// one set (o.set(&validation::DiagnoseSettings::field, value)) wins.
using DiagnoseOverrides = core::Overrides<validation::DiagnoseSettings>;

struct FolderDiagnosis {
  std::string dir;
  LabManifest manifest;
  validation::Campaign campaign;
  validation::DiagnoseSettings settings;  // used
  std::string settings_from;              // where they came from (defaults, the manifest, overrides)
  validation::Diagnosis diagnosis;
  double wall_s = 0;  // the diagnosis alone
  int threads = 1;    // the effects' fits ran on these (the results do not depend on it)
  bool diagnosed = false;  // false: read and checked only (read_folder)
  // "diagnose DIR", the counts, then the verdict (brief) or everything the diagnosis found (full).
  std::string BriefReport() const;
  std::string FullReport() const;
  // "diagnose DIR", the counts, the skipped runs, then what was read (read_folder's result).
  std::string CheckReport() const;
};

// The campaign read and checked, the settings resolved and validated; no diagnosis
// (`diagnose --check`). InputError as diagnose_folder's.
FolderDiagnosis read_folder(const std::string& dir, const DiagnoseOverrides& overrides = {});
// threads: the effects' fits on this many threads (0: all cores; validation::diagnose);
// progress: a bar of the effects' fits on stderr (core::Progress: redrawn on a terminal, sparse
// lines in a log, nothing for a diagnosis under a second).
FolderDiagnosis diagnose_folder(const std::string& dir, const DiagnoseOverrides& overrides = {}, int threads = 1,
                                bool progress = false);

}  // namespace vrelab::io
