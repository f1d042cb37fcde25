#include "io/services/diagnosis.hpp"

#include <iostream>

#include <chrono>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "io/formats/case_file.hpp"
#include "io/services/diagnosis_json.hpp"
#include "io/services/internal.hpp"
#include "io/formats/output.hpp"
#include "validation/diagnosis/campaign.hpp"
#include "core/parallel.hpp"
#include "core/progress.hpp"
#include "validation/diagnosis/diagnose.hpp"

namespace vrelab::io {

CampaignWritten write_virtual_campaign(const CampaignRequest& request) {
  Case c = read_case(request.case_path);
  require(c, c.coefficients.has_value(), "coefficients", "campaign");
  require(c, c.campaign.has_value(), "campaign", "campaign");
  if (c.physical) throw InputError(c.path + ": campaign takes a plant built from coefficients");
  if (request.seed) c.seed = *request.seed;
  const CampaignSpec& spec = *c.campaign;
  if (request.raw_format == RawFormat::hdf5 && !(spec.design.raw_sample_rate_Hz > 0))
    throw InputError(c.path + ": campaign --raw-format hdf5: the case writes summaries, not raw records (set [campaign] "
                              "raw_series = true)");
  CampaignWritten w;
  w.request = request;
  w.request.seed = c.seed;
  if (w.request.key_path.empty()) w.request.key_path = request.out_dir + ".key.json";
  const auto start = std::chrono::steady_clock::now();
  core::Progress progress(std::cerr, "campaign",
                          spec.design.frequencies_Hz.size() * spec.design.amplitudes_g.size() * spec.design.directions.size() *
                                  spec.design.orientations_g.size() +
                              spec.design.random_runs.size(),
                          request.progress);
  validation::Campaign camp =
      validation::simulate_campaign(c.plant, spec.hidden, spec.design, c.seed, 0, [&progress] { progress.tick(); });
  progress.finish();
  camp.name = spec.name;
  LabManifest m;
  m.name = spec.name, m.output_unit = c.output_unit, m.g_m_per_s2 = c.g_m_per_s2;
  write_campaign(request.out_dir, camp, m, {}, request.raw_format);  // with the raw records, when simulated
  nlohmann::json key = result_record("campaign", c);
  key["hidden"] = nlohmann::json::array();
  for (const auto& h : spec.hidden) key["hidden"].push_back({{"name", h.name}, {"parameter", h.parameter}});
  key["truth"] = coefficients_json(c.plant.coefficients);
  key["data"] = request.out_dir;
  write_atomic(w.request.key_path, json_text(key));
  w.statics = camp.statics.size(), w.runs = camp.runs.size(), w.raw_records = !camp.raw.empty();
  w.wall_s = internal::seconds_since(start);
  return w;
}

std::string CampaignWritten::BriefReport() const {
  return fmt::format("campaign {}  [seed {}]\n", request.case_path, request.seed.value_or(0));
}

std::string CampaignWritten::FullReport() const {
  return BriefReport() +
         fmt::format("Wrote {} static readings and {} shaker runs ({}) to {} (lab data format, docs/data-format.md); the "
                     "answer key to {} ({:.1f} s wall)\n",
                     statics, runs, raw_records ? (request.raw_format == RawFormat::hdf5 ? "raw records in records/ (HDF5)" : "raw records in records/") : "summaries", request.out_dir,
                     request.key_path, wall_s);
}

FolderDiagnosis read_folder(const std::string& dir, const DiagnoseOverrides& o) {
  FolderDiagnosis f;
  f.dir = dir;
  f.campaign = read_campaign(dir, &f.manifest);  // checks the manifest's [diagnose]
  const validation::Campaign& c = f.campaign;
  if (c.runs.empty()) throw InputError(dir + ": no usable shaker run" + (c.skipped.empty() ? "" : ": " + c.skipped.front()));
  validation::DiagnoseSettings& s = f.settings;
  s = f.manifest.diagnose;
  f.settings_from = f.manifest.diagnose_given ? "the manifest's [diagnose]" : "defaults";
  o.apply(s);
  if (o.any()) f.settings_from += ", set over by the caller";
  std::string why;
  if (!s.IsValid(&why)) throw InputError("diagnose settings: " + why);
  return f;
}

FolderDiagnosis diagnose_folder(const std::string& dir, const DiagnoseOverrides& o, int threads, bool progress) {
  if (threads < 0) throw InputError("diagnose: threads must not be negative (0: all cores)");
  FolderDiagnosis f = read_folder(dir, o);
  f.threads = core::thread_count(threads);
  const auto start = std::chrono::steady_clock::now();
  try {
    std::optional<core::Progress> bar;  // one per pass over the effects (a scaled sigma: two)
    const validation::EffectsProgress tick = [&bar](std::size_t done, std::size_t total) {
      if (done == 1) bar.emplace(std::cerr, "diagnose: the effects' fits", total);
      bar->tick();
    };
    f.diagnosis = validation::diagnose(f.campaign, f.settings, f.threads, progress ? tick : validation::EffectsProgress{});
  } catch (const std::invalid_argument& e) {
    throw InputError(dir + ": " + e.what());
  }
  f.wall_s = internal::seconds_since(start);
  f.diagnosed = true;
  // Every number the diagnosis prints or writes is finite, or the diagnosis fails naming it.
  require_finite(to_json(f), dir, "a value of the campaign drives the diagnosis out of range");
  return f;
}

namespace {

std::string header(const FolderDiagnosis& f) {
  const validation::Campaign& c = f.campaign;
  std::string t = "diagnose " + f.dir + "\n";
  t += fmt::format("{} static readings, {} shaker runs ({} skipped)\n", c.statics.size(), c.runs.size(), c.skipped.size());
  for (const auto& s : c.skipped) t += "  skipped: " + s + "\n";
  if (!f.manifest.dynamics_given) t += "Nominal dynamics: defaults (the manifest has no [dynamics])\n";
  t += motion_summary_text(f.diagnosis, c);
  return t;
}

}  // namespace

std::string FolderDiagnosis::BriefReport() const { return header(*this) + diagnosis.BriefReport(); }

std::string FolderDiagnosis::CheckReport() const {
  const validation::Campaign& c = campaign;
  int random = 0, sine_on_random = 0, referenced = 0;
  for (const auto& r : c.runs) {
    if (r.random) ++(r.sine_part ? sine_on_random : random);
    if (r.motion) ++referenced;
  }
  return header(*this) +
         fmt::format("Read and checked (no diagnosis): {} sine, {} random and {} sine-on-random runs; {} with a reference "
                     "channel; the settings ({}) valid\n",
                     c.runs.size() - static_cast<std::size_t>(random + sine_on_random), random, sine_on_random, referenced,
                     settings_from);
}

std::string FolderDiagnosis::FullReport() const {
  return header(*this) + diagnosis.FullReport(wall_s);
}

}  // namespace vrelab::io
