#pragma once
// io/services/batch.hpp -- `vrelab diagnose DIR... --summary FILE`: many campaign folders diagnosed,
// one row each in a summary CSV, on threads or on the ranks of mpirun (core/dispatch.hpp;
// docs/mpi.md).
//
// Takes: folders, each a campaign (it has manifest.toml) or a folder of campaign folders (its
//        subfolders with a manifest, sorted by name); the settings over each manifest's
//        [diagnose]; the threads per process.
// Gives: the summary CSV (written atomically; a row appended as each campaign finishes, so a
//        killed run resumes where it stopped: rows already there, with this program and these
//        settings, are kept and not run again; a row edited by hand fails its checksum and is
//        run again), and the campaigns that failed (a bad folder: its id and why), whose rows
//        are not written. A campaign's row is a function of its folder and the settings alone.
#include <ostream>
#include <string>
#include <vector>

#include "io/services/diagnosis.hpp"

namespace vrelab::io {

struct BatchRequest {
  std::vector<std::string> dirs;
  std::string summary_path;
  DiagnoseOverrides overrides;
  int threads = 0;        // per process; 0: all cores (one per rank under mpirun)
  bool progress = false;  // core::Progress on stderr (rank 0)
  bool restart = false;   // discard an existing summary
};

struct BatchSummary {
  std::vector<std::string> campaigns;  // the folders found, in order
  std::size_t kept = 0, ran = 0, written = 0;
  std::vector<std::string> failures;  // "<folder>: why"
  std::vector<std::string> recomputed;
  int ranks = 1, threads = 1;
  double wall_s = 0;
  std::string BriefReport(const std::string& summary_path) const;
};

// The campaign folders among `dirs` (each a campaign or a folder of them); InputError for a
// path that is neither, naming it.
std::vector<std::string> campaign_folders(const std::vector<std::string>& dirs);

// Announces the batch on `out` before running. Under mpirun only rank 0 reads and writes.
BatchSummary diagnose_many(const BatchRequest& request, std::ostream& out);

}  // namespace vrelab::io
