#include "io/services/batch.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "core/dispatch.hpp"
#include "core/progress.hpp"
#include "io/formats/output.hpp"
#include "io/formats/paths.hpp"
#include "io/services/internal.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"
#include "vrelab_version.hpp"

namespace vrelab::io {
namespace {

namespace fs = std::filesystem;

// verdict etc. are free text: quoted when they hold a comma or a quote.
std::string field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch == '\n' ? ' ' : ch);
  return q + "\"";
}

// The first field of a CSV line (unquoted) and where the rest starts.
std::string first_field(const std::string& line, std::size_t* end) {
  std::string f;
  std::size_t i = 0;
  if (!line.empty() && line[0] == '"') {
    for (i = 1; i < line.size(); ++i) {
      if (line[i] == '"') {
        if (i + 1 < line.size() && line[i + 1] == '"') f += '"', ++i;
        else break;
      } else {
        f += line[i];
      }
    }
    ++i;
  } else {
    i = line.find(',');
    if (i == std::string::npos) i = line.size();
    f = line.substr(0, i);
  }
  *end = i;
  return f;
}

// FNV-1a, 32 bits, of a row's text before its checksum (as the sweep's rows).
std::string checksum(const std::string& text) {
  std::uint32_t h = 2166136261u;
  for (unsigned char ch : text) h = (h ^ ch) * 16777619u;
  return fmt::format("{:08x}", h);
}

constexpr const char* kColumns =
    "campaign,verdict,chosen,parameter,value,unit,sigma,shrinkage,shrinkage_in_sigma,rms_before_g,rms_after_g,"
    "significant_runs,runs,settings_from,checksum,wall_s";

// The program and each DiagnoseSettings field as name=value (set here) or name=- (the manifest's).
std::string fingerprint(const DiagnoseOverrides& o) {
  std::string text = fmt::format("{} {}", kProgramVersion, kGitDescribe);
  int i = 0;
  core::for_each_field<validation::DiagnoseSettings>([&](const auto& f) {
    text += fmt::format(" {}={}", f.name, o.given(i++) ? core::format_value(o.values().*f.member) : std::string("-"));
  });
  return text;
}

// One campaign's row body (without checksum and wall time), or throws.
std::string diagnose_row(const std::string& dir, const DiagnoseOverrides& o) {
  const FolderDiagnosis f = diagnose_folder(dir, o);
  const validation::Diagnosis& d = f.diagnosis;
  const validation::EffectFit* e = nullptr;
  for (const auto& x : d.effects)
    if (d.chosen.names.size() == 1 && x.name == d.chosen.names.front()) e = &x;  // (a pair: no one parameter)
  const double shrink = d.rms_before_g > 0 ? 1 - d.rms_after_g / d.rms_before_g : 0.0;
  const double shrink_s = d.rms_before_sigma > 0 ? 1 - d.rms_after_sigma / d.rms_before_sigma : 0.0;
  return fmt::format("{},{},{},{},{},{},{},{:.6g},{:.6g},{:.6e},{:.6e},{},{},{}", field(dir), field(validation::verdict_text(d)),
                     field(validation::to_string(d.chosen)), field(e ? e->parameter : ""), e ? fmt::format("{:.6e}", e->value) : "",
                     field(e ? e->unit : ""), e && !e->at_bound ? fmt::format("{:.3e}", e->sigma) : "", shrink, shrink_s,
                     d.rms_before_g, d.rms_after_g, d.significant_runs, d.runs.size(), field(f.settings_from));
}

}  // namespace

std::vector<std::string> campaign_folders(const std::vector<std::string>& dirs) {
  std::vector<std::string> out;
  for (const std::string& d : dirs) {
    std::error_code ec;
    if (fs::is_directory(d, ec) && !fs::exists(fs::path(d) / "manifest.toml", ec)) {
      std::vector<std::string> sub;
      for (const auto& e : fs::directory_iterator(d, ec))
        if (e.is_directory() && fs::exists(e.path() / "manifest.toml")) sub.push_back(e.path().string());
      std::sort(sub.begin(), sub.end());
      if (!sub.empty()) {
        out.insert(out.end(), sub.begin(), sub.end());
        continue;
      }
    }
    out.push_back(d);  // a campaign, or a bad folder: its diagnosis fails, named, and the others go on
  }
  return out;
}

BatchSummary diagnose_many(const BatchRequest& r, std::ostream& out) {
  BatchSummary s;
  s.campaigns = campaign_folders(r.dirs);
  s.ranks = core::process_count();
  s.threads = core::threads_per_process(r.threads);
  const bool writer = core::is_root_process();
  const std::string fp = fingerprint(r.overrides);
  const std::string header = fmt::format(
      "# vrelab {} ({}) diagnose --summary: one row per campaign\n# fingerprint {}\n"
      "# run: {} MPI rank(s) x {} thread(s) (the last run of this file; rows do not depend on it)\n"
      "# shrinkage: 1 - held-out gap rms after/before the chosen effect (g; in_sigma: in each run's sigma); "
      "sigma empty: the fit ended on its range's edge\n{}\n",
      kProgramVersion, kGitDescribe, fp, s.ranks, s.threads, kColumns);
  // campaign -> its line; kept from an earlier run of the same program and settings.
  std::map<std::string, std::string> rows;
  if (writer) require_writable_file(r.summary_path, "the summary (--summary)");
  if (writer && fs::exists(r.summary_path) && !r.restart) {
    std::ifstream in(r.summary_path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.find("# fingerprint " + fp + "\n") == std::string::npos)
      throw InputError(r.summary_path + ": exists with rows of another program version or other settings; remove it");
    if (!text.empty() && text.back() != '\n') text.erase(text.rfind('\n') + 1);  // a partial last line
    std::istringstream lines(text);
    std::string line;
    long no = 0;
    while (std::getline(lines, line)) {
      ++no;
      if (line.empty() || line[0] == '#' || line.rfind("campaign,", 0) == 0) continue;
      std::size_t end = 0;
      const std::string id = first_field(line, &end);
      const std::size_t wall = line.rfind(','), sum = wall == std::string::npos ? wall : line.rfind(',', wall - 1);
      if (sum == std::string::npos || checksum(line.substr(0, sum)) != line.substr(sum + 1, wall - sum - 1)) {
        s.recomputed.push_back(fmt::format("{}:{}: campaign {}: the row does not match its checksum; run again",
                                           r.summary_path, no, id));
        rows.erase(id);
        continue;
      }
      rows[id] = line + "\n";
    }
  }
  auto text_of = [&] {
    std::string t = header;
    for (const std::string& c : s.campaigns)
      if (auto it = rows.find(c); it != rows.end()) t += it->second;
    return t;
  };
  const fs::path path(r.summary_path);
  if (writer && path.has_parent_path()) fs::create_directories(path.parent_path());
  if (writer) write_atomic(r.summary_path, text_of());
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < s.campaigns.size(); ++i)
    if (!rows.count(s.campaigns[i])) todo.push_back(i);
  s.kept = s.campaigns.size() - todo.size();
  s.ran = todo.size();
  out << fmt::format("vrelab {} ({}) diagnose --summary {}: {} campaign(s), {} already there; {} thread(s){}\n",
                     kProgramVersion, kGitDescribe, r.summary_path, s.campaigns.size(), s.kept, s.threads,
                     s.ranks > 1 ? fmt::format(" on each of {} MPI ranks", s.ranks) : "");
  for (const auto& x : s.recomputed) out << "  " << x << "\n";
  out.flush();
  std::ofstream append;
  if (writer) append.open(r.summary_path, std::ios::app);
  core::Progress bar(std::cerr, "diagnose", todo.size(), r.progress && writer);
  const auto start = std::chrono::steady_clock::now();
  // A campaign's result: "+" and its row, or "!" and why it failed.
  core::dispatch(
      todo, s.threads,
      [&](std::size_t i) {
        const auto t0 = std::chrono::steady_clock::now();
        try {
          const std::string body = diagnose_row(s.campaigns[i], r.overrides);
          return fmt::format("+{},{},{:.4g}\n", body, checksum(body), internal::seconds_since(t0));
        } catch (const std::exception& e) {
          return std::string("!") + e.what();
        }
      },
      [&](std::size_t i, const std::string& result) {
        bar.tick();
        if (result.empty() || result[0] != '+') {
          s.failures.push_back(s.campaigns[i] + ": " + (result.empty() ? std::string() : result.substr(1)));
          return;
        }
        const std::string line = result.substr(1);
        append << line << std::flush;  // one row per write: an interruption loses at most this row
        rows[s.campaigns[i]] = line;
      });
  bar.finish();
  append.close();
  s.wall_s = internal::seconds_since(start);
  if (writer) write_atomic(r.summary_path, text_of());  // every row, in the campaigns' order
  s.written = rows.size();
  std::sort(s.failures.begin(), s.failures.end());
  return s;
}

std::string BatchSummary::BriefReport(const std::string& summary_path) const {
  std::string t = fmt::format("Done: {} campaign(s) diagnosed in {:.3g} s wall on {} rank(s) x {} thread(s) ({} kept, "
                              "{} failed) -> {}\n",
                              ran, wall_s, ranks, threads, kept, failures.size(), summary_path);
  for (const auto& f : failures) t += "  failed: " + f + "\n";
  return t;
}

}  // namespace vrelab::io
