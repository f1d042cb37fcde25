// app/diagnose.cpp -- `vrelab campaign`, `vrelab diagnose`, `vrelab blind`: each calls one
// library function, prints its report and writes its results (io/services/diagnosis.hpp,
// validation/diagnosis/blind.hpp, io/services/diagnosis_json.hpp).
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <algorithm>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "app/commands.hpp"
#include "core/dispatch.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "io/services/batch.hpp"
#include "io/services/blind_report.hpp"
#include "io/services/diagnosis.hpp"
#include "io/services/diagnosis_json.hpp"
#include "io/services/diagnosis_report.hpp"
#include "io/formats/output.hpp"
#include "validation/diagnosis/advice_check.hpp"
#include "validation/diagnosis/blind.hpp"
#include "vrelab_version.hpp"

namespace vrelab::app {
namespace {

// "vrelab <version> (<git>) ": the first words of every command's report.
std::string program() { return fmt::format("vrelab {} ({}) ", kProgramVersion, kGitDescribe); }

}  // namespace

void run_campaign(const CampaignOptions& o, std::ostream& out) {
  if (o.work_limit) check_campaign_work(io::read_case(o.case_path));
  const io::CampaignWritten w = io::write_virtual_campaign(
      {o.case_path, o.out_dir, o.key_path, o.seed, o.progress, o.raw_format == "hdf5" ? io::RawFormat::hdf5 : io::RawFormat::csv});
  out << program() << w.FullReport();
}

int run_diagnose(const DiagnoseOptions& o, std::ostream& out) {
  if (o.check && (!o.json_path.empty() || !o.report_dir.empty()))
    throw io::InputError("diagnose --check: reads and checks only; --json and --report need a diagnosis");
  if (o.threads < 0) throw io::InputError("diagnose --threads: must not be negative (0: all cores)");
  const io::FolderDiagnosis f = o.check ? io::read_folder(o.dir, o.settings) : io::diagnose_folder(o.dir, o.settings, o.threads, o.progress);
  out << program() << (o.check ? f.CheckReport() : f.FullReport());
  if (!o.json_path.empty()) io::write_atomic(o.json_path, io::json_text(io::to_json(f)));
  if (!o.report_dir.empty()) io::write_diagnosis_report(f, o.report_dir);
  // Bad runs are input errors: the others are diagnosed and written, and the exit code says
  // that the campaign was not read whole (docs/data-format.md, "Bad input").
  if (f.campaign.skipped.empty()) return 0;
  std::cerr << fmt::format("diagnose: {}: {} run(s) skipped for bad input (listed above); the others {}\n", o.dir,
                           f.campaign.skipped.size(), o.check ? "read" : "diagnosed");
  return 2;
}

int run_diagnose_many(const DiagnoseOptions& o, std::ostream& out) {
  if (!o.json_path.empty() || !o.report_dir.empty())
    throw io::InputError("diagnose --summary: --json and --report are for one campaign folder");
  if (o.threads < 0) throw io::InputError("diagnose --threads: must not be negative (0: all cores)");
  const io::BatchSummary s = io::diagnose_many({o.dirs, o.summary_path, o.settings, o.threads, o.progress, false}, out);
  out << s.BriefReport(o.summary_path);
  return static_cast<int>(s.failures.size());
}

namespace {

// blind --out DIR keeps DIR/campaigns.txt: a line per campaign diagnosed ("index<TAB>result
// <TAB>checksum", validation::campaign_result_text), appended as each finishes, under a header
// naming the seed, the diagnosis' settings and the program. A rerun with the same header
// reads them back instead of running them again (a killed run resumes; --n may grow); a
// line whose checksum fails (cut short, edited) is run again.
std::string blind_header(const validation::BlindSettings& s) {
  std::string text = fmt::format("# vrelab {} ({}) blind: campaigns diagnosed (index, result, checksum); seed {}{}",
                                 kProgramVersion, kGitDescribe, s.seed, s.mixed ? "; mixed designs" : "");
  core::for_each_field<validation::DiagnoseSettings>(
      [&](const auto& f) { text += fmt::format(" {} {}", f.name, core::format_value(s.diagnose.*f.member, 17)); });
  return text + "\n";
}

std::string line_checksum(const std::string& text) {
  std::uint32_t h = 2166136261u;
  for (unsigned char ch : text) h = (h ^ ch) * 16777619u;
  return fmt::format("{:08x}", h);
}

// stale: the file exists but under another header (its lines are not read back).
std::map<int, std::string> blind_done(const std::string& path, const std::string& header, bool* stale) {
  std::map<int, std::string> done;
  std::ifstream in(path);
  std::string line;
  *stale = false;
  if (!std::getline(in, line)) return done;
  if (line + "\n" != header) {  // another seed, settings or program
    *stale = true;
    return done;
  }
  while (std::getline(in, line)) {
    const std::size_t a = line.find('\t'), b = line.rfind('\t');
    if (a == std::string::npos || b == a) continue;
    const std::string body = line.substr(0, b);
    if (line_checksum(body) != line.substr(b + 1)) continue;
    try {
      done[std::stoi(line.substr(0, a))] = line.substr(a + 1, b - a - 1);
    } catch (const std::exception&) {
    }
  }
  return done;
}

// The advice checked (--check-advice) on the ambiguous and unexplained campaigns of r:
// DIR/advice.txt keeps a line per campaign checked under blind's header, appended as each
// finishes; a rerun reads them back.
void check_blind_advice(const BlindOptions& o, const validation::BlindResult& r, std::ostream& out) {
  const std::string path = o.out_dir + "/advice.txt", header = blind_header(o.settings);
  bool stale = false;
  std::map<int, std::string> done = blind_done(path, header, &stale);
  std::vector<const validation::BlindCampaign*> todo;
  std::vector<validation::AdviceCheck> checks;
  for (const auto& k : r.campaigns) {
    if (k.called != "ambiguous" && k.called != "unexplained") continue;
    if (const auto it = done.find(k.index); it != done.end()) try {
        checks.push_back(validation::read_advice_check(it->second));
        continue;
      } catch (const std::invalid_argument&) {  // checked again
      }
    todo.push_back(&k);
  }
  std::string kept = header;
  for (const auto& c : checks) {
    const std::string body = fmt::format("{}\t{}", c.index, validation::advice_check_text(c));
    kept += body + "\t" + line_checksum(body) + "\n";
  }
  io::write_atomic(path, kept);
  std::ofstream append(path, std::ios::app);
  std::vector<validation::AdviceCheck> fresh(todo.size());
  core::Progress bar(std::cerr, "advice", todo.size(), o.progress);
  core::parallel_for(
      todo.size(), core::thread_count(o.settings.threads),
      [&](std::size_t i) { fresh[i] = validation::check_advice(*todo[i], o.settings.diagnose); },
      [&](std::size_t i) {
        const std::string body = fmt::format("{}\t{}", fresh[i].index, validation::advice_check_text(fresh[i]));
        append << body << "\t" << line_checksum(body) << "\n" << std::flush;
        bar.tick();
      });
  bar.finish();
  checks.insert(checks.end(), fresh.begin(), fresh.end());
  std::sort(checks.begin(), checks.end(), [](const auto& a, const auto& b) { return a.index < b.index; });
  for (const auto& c : checks) {
    out << fmt::format("  advice, campaign {} [{}]: {} -> {} ({} -> {})\n", c.index, c.category, c.called_before, c.called_after,
                       c.outcome_before, c.outcome_after);
    for (const auto& x : c.runs)
      out << fmt::format("    {:g} Hz {:g} g [{:.2g} {:.2g} {:.2g}] at [{:.2g} {:.2g} {:.2g}] g, {} ({}): promised {:.1f}, obtained {:.1f}; {}\n",
                         x.advised.frequency_Hz, x.advised.amplitude_g, x.advised.direction[0], x.advised.direction[1],
                         x.advised.direction[2], x.advised.orientation_g[0], x.advised.orientation_g[1], x.advised.orientation_g[2],
                         x.advised.purpose, x.advised.between, x.promised_sigma, x.obtained_sigma, x.called);
    if (!c.error.empty()) out << "    error: " << c.error << "\n";
  }
  out << validation::advice_summary(checks);
}

}  // namespace

void run_blind(const BlindOptions& o, std::ostream& out) {
  std::string why;
  if (!o.settings.IsValid(&why)) throw io::InputError("blind: " + why);
  const bool writer = core::is_root_process();
  const std::string done_path = o.out_dir + "/campaigns.txt", header = blind_header(o.settings);
  std::map<int, std::string> done;
  if (writer) {
    bool stale = false;
    done = blind_done(done_path, header, &stale);
    if (stale)
      std::cerr << "blind: " << done_path
                << " was written by another seed, settings or program build; its campaigns are not read back "
                   "(all run again, the file replaced)\n";
    std::string kept = header;
    for (const auto& [i, t] : done) {
      const std::string body = fmt::format("{}\t{}", i, t);
      kept += body + "\t" + line_checksum(body) + "\n";
    }
    io::write_atomic(done_path, kept);
  }
  std::ofstream append;
  if (writer) append.open(done_path, std::ios::app);
  std::size_t resumed = 0;
  for (const auto& [i, t] : done) resumed += i < o.settings.n;  // (an outdated line among them is diagnosed again)
  core::Progress bar(std::cerr, "blind", static_cast<std::size_t>(o.settings.n) - resumed, o.progress && writer);
  const validation::BlindResult r = validation::run_blind(
      o.settings, [&bar](std::size_t, std::size_t) { bar.tick(); }, done,
      [&](int i, const std::string& text) {
        const std::string body = fmt::format("{}\t{}", i, text);
        append << body << "\t" << line_checksum(body) << "\n" << std::flush;  // an interruption loses at most this line
      });
  bar.finish();
  if (!writer) return;
  io::write_atomic(o.out_dir + "/scores.json", io::json_text(io::to_json(r)));
  io::write_atomic(o.out_dir + "/confusion.csv", io::confusion_csv(r));
  out << program() << r.FullReport();
  if (r.resumed > 0) out << fmt::format("  {} campaign(s) read back from {} (an earlier run)\n", r.resumed, done_path);
  // The figure before the report, which embeds it; an old figure goes first so that a failed
  // script leaves none for the report to show.
  for (const char* f : {"/confusion.png", "/confusion.svg"}) std::filesystem::remove(o.out_dir + f);
  const std::string plot = io::run_plot_script("confusion.py", o.out_dir);
  io::write_atomic(o.out_dir + "/report.html", io::blind_report(r, plot).html(o.out_dir));
  out << "Wrote " << o.out_dir << "/scores.json, report.html and confusion.csv"
      << (plot.empty() ? ", confusion.png/svg" : "; figure skipped: " + plot) << "\n";
  if (o.check_advice) check_blind_advice(o, r, out);
}

}  // namespace vrelab::app
