// app/diagnose.cpp -- `vrelab campaign`, `vrelab diagnose`, `vrelab blind`: each calls one
// library function, prints its report and writes its results (io/diagnosis.hpp,
// validation/diagnosis/blind.hpp, io/diagnosis_json.hpp).
#include <iostream>

#include <fmt/format.h>

#include "app/commands.hpp"
#include "core/dispatch.hpp"
#include "core/progress.hpp"
#include "io/batch.hpp"
#include "io/diagnosis.hpp"
#include "io/diagnosis_json.hpp"
#include "io/diagnosis_report.hpp"
#include "io/output.hpp"
#include "validation/diagnosis/blind.hpp"
#include "vrelab_version.hpp"

namespace vrelab::app {
namespace {

// "vrelab <version> (<git>) ": the first words of every command's report.
std::string program() { return fmt::format("vrelab {} ({}) ", kProgramVersion, kGitDescribe); }

}  // namespace

void run_campaign(const CampaignOptions& o, std::ostream& out) {
  if (o.work_limit) check_campaign_work(io::read_case(o.case_path));
  const io::CampaignWritten w = io::write_virtual_campaign({o.case_path, o.out_dir, o.key_path, o.seed, o.progress});
  out << program() << w.FullReport();
}

void run_diagnose(const DiagnoseOptions& o, std::ostream& out) {
  const io::FolderDiagnosis f = io::diagnose_folder(o.dir, o.settings);
  out << program() << f.FullReport();
  if (!o.json_path.empty()) io::write_atomic(o.json_path, io::json_text(io::to_json(f)));
  if (!o.report_dir.empty()) io::write_diagnosis_report(f, o.report_dir);
}

int run_diagnose_many(const DiagnoseOptions& o, std::ostream& out) {
  if (!o.json_path.empty() || !o.report_dir.empty())
    throw io::InputError("diagnose --summary: --json and --report are for one campaign folder");
  if (o.threads < 0) throw io::InputError("diagnose --threads: must not be negative (0: all cores)");
  const io::BatchSummary s = io::diagnose_many({o.dirs, o.summary_path, o.settings, o.threads, o.progress, false}, out);
  out << s.BriefReport(o.summary_path);
  return static_cast<int>(s.failures.size());
}

void run_blind(const BlindOptions& o, std::ostream& out) {
  std::string why;
  if (!o.settings.IsValid(&why)) throw io::InputError("blind: " + why);
  core::Progress bar(std::cerr, "blind", static_cast<std::size_t>(o.settings.n), o.progress);
  const validation::BlindResult r = validation::run_blind(o.settings, [&bar](std::size_t, std::size_t) { bar.tick(); });
  bar.finish();
  io::write_atomic(o.out_dir + "/scores.json", io::json_text(io::to_json(r)));
  io::write_atomic(o.out_dir + "/confusion.csv", io::confusion_csv(r));
  out << program() << r.FullReport();
  const std::string plot = io::run_plot_script("confusion.py", o.out_dir);
  out << "Wrote " << o.out_dir << "/scores.json and confusion.csv"
      << (plot.empty() ? ", confusion.png/svg" : "; figure skipped: " + plot) << "\n";
}

}  // namespace vrelab::app
