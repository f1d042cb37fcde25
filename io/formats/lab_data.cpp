#include "io/formats/lab_data.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "io/formats/case_file.hpp"
#include "io/formats/csv.hpp"
#include "io/formats/output.hpp"
#include "io/formats/paths.hpp"
#include "io/formats/ranges.hpp"
#include "io/formats/raw_hdf5.hpp"
#include "io/formats/series.hpp"
#include "io/formats/settings_toml.hpp"
#include "rectification/measurement/reference.hpp"
#include "rectification/measurement/series.hpp"
#include "validation/diagnosis/diagnose.hpp"
#include "validation/identification/dividing_head.hpp"

namespace vrelab::io {
namespace {

namespace fs = std::filesystem;

// A CSV file with a header: rows with their line numbers; '#' lines and blank lines skipped.
// Text checked line by line (UTF-8, a byte-order mark dropped, the header's separator: ',',
// ';' or a tab); a row with more cells than the header, or a header naming a column twice, is
// refused.
struct Csv {
  std::string path;
  std::map<std::string, std::size_t> column;
  std::vector<std::string> names;  // the header, in order
  std::vector<std::pair<int, std::vector<std::string>>> rows;
  bool has(const std::string& c) const { return column.count(c) > 0; }
};

// `what` names the file in messages ("the runs table"); more than `max_rows` rows is refused
// at the first row past it (`rows_what`, `rows_why`: what the rows are and why they are bounded).
struct CsvLimit {
  std::size_t max_rows;
  std::string rows_what, rows_why;
};
Csv read_csv(const std::string& path, const std::string& what, const CsvLimit& limit) {
  require_readable_file(path, what);
  std::ifstream in(path);
  if (!in) throw FormatError({.file = path}, fmt::format("cannot open {}", what));
  Csv csv;
  csv.path = path;
  std::string line;
  int n = 0;
  bool header = false;
  char separator = ',';
  while (std::getline(in, line)) {
    ++n;
    check_text_line(line, n, path);
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (!header) separator = header_separator(line);
    std::vector<std::string> cells = split_csv_line(line, path, n, separator);
    if (!header) {
      check_header_names(cells, path, n);
      for (std::size_t i = 0; i < cells.size(); ++i) csv.column[cells[i]] = i;
      csv.names = cells;
      header = true;
      continue;
    }
    if (cells.size() > csv.names.size())
      throw FormatError({.file = path, .line = n, .column = static_cast<long>(csv.names.size() + 1)},
                        fmt::format("{} cells, the header has {} (a {} inside a cell? quote the cell)", cells.size(),
                                    csv.names.size(), separator == '\t' ? std::string("tab") : separator_name(separator)));
    if (csv.rows.size() == limit.max_rows)
      throw FormatError({.file = path, .line = n}, rows_problem(limit.max_rows, limit.rows_what, limit.rows_why));
    csv.rows.emplace_back(n, std::move(cells));
  }
  if (!header) throw FormatError({.file = path}, "no header line");
  return csv;
}

// The value of `col` in a row as a number; nullopt with `why` set when absent or not a finite
// decimal (the file, the line, the cell and the column's name).
std::optional<double> number(const Csv& csv, const std::pair<int, std::vector<std::string>>& row, const std::string& col,
                             std::optional<FormatError>* why) {
  const auto it = csv.column.find(col);
  if (it == csv.column.end() || it->second >= row.second.size() || row.second[it->second].empty()) {
    why->emplace(FormatLocation{.file = csv.path, .line = row.first, .key = col, .kind = KeyKind::csv_column}, "missing value");
    return std::nullopt;
  }
  const std::string& s = row.second[it->second];
  const auto x = parse_decimal(s);
  if (!x) {
    const std::string reason = why_not_decimal(s);
    why->emplace(FormatLocation{.file = csv.path, .line = row.first, .column = static_cast<long>(it->second + 1), .key = col,
                                .kind = KeyKind::csv_column},
                 reason == "not finite" ? s + " is not a finite number" : fmt::format("'{}' is not a number ({})", s, reason));
    return std::nullopt;
  }
  return x;
}

// " (the header has: a, b, c); did you mean 'wanted' for 'close'?" for a column `wanted` that
// is not there, `close` the header's closest name.
std::string columns_found(const Csv& csv, const std::string& wanted) {
  std::string found;
  for (const auto& n : csv.names) found += (found.empty() ? "" : ", ") + n;
  std::string out = fmt::format(" (the header has: {})", found);
  const std::string close = closest_name(wanted, csv.names);
  if (!close.empty()) {
    out += fmt::format("; did you mean '{}' for '{}'?", wanted, close);
    std::string a = close, b = wanted;
    for (char& ch : a) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    for (char& ch : b) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (a == b) out += " (column names are case-sensitive: units such as Hz are written as in SI)";
  }
  return out;
}

void require_columns(const Csv& csv, const std::vector<std::string>& cols, const std::string& hint = "") {
  for (const auto& c : cols)
    if (!csv.has(c))
      throw FormatError({.file = csv.path, .key = c}, fmt::format("the header lacks column '{}'{}{}", c, hint, columns_found(csv, c)));
}

// A random run's PSD file (docs/data-format.md): frequency_Hz and psd_<axis>_g2_per_Hz for
// the axes that move (a missing column: that axis at rest); breakpoints, straight lines on
// log-log axes between them, each frequency and level within its physical range and each
// table's rms at most kPsdMaxRms_g. Bad content throws FormatError at the file, line and column.
vibration::RandomProfile psd_file(const std::string& path, const std::string& coupling, const ChannelNames& names) {
  Csv csv = read_csv(path, "the PSD file", {kMaxPsdRows, "rows of a PSD table", "the breakpoints of a PSD table are read in full"});
  csv.names = with_vrelab_names(csv.names, names);
  check_header_names(csv.names, path, 0);  // (a lab's name mapped onto a column vrelab's name already has)
  csv.column.clear();
  for (std::size_t i = 0; i < csv.names.size(); ++i) csv.column[csv.names[i]] = i;
  require_columns(csv, {"frequency_Hz"});
  static const std::array<std::string, 3> cols{"psd_IA_g2_per_Hz", "psd_PA_g2_per_Hz", "psd_OA_g2_per_Hz"};
  vibration::RandomProfile p;
  p.coupling = coupling == "independent" ? vibration::AxisCoupling::independent : vibration::AxisCoupling::common;
  bool any = false;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!csv.has(cols[i])) continue;
    any = true;
    vibration::PsdTable t;
    for (const auto& row : csv.rows) {
      std::optional<FormatError> why;
      const auto f = number(csv, row, "frequency_Hz", &why), g = number(csv, row, cols[i], &why);
      if (!f || !g) throw *why;
      const auto cell = [&](const std::string& col) {
        return FormatLocation{.file = path, .line = row.first, .key = col, .kind = KeyKind::csv_column};
      };
      if (!(*f > 0) || (!t.rows.empty() && !(*f > t.rows.back().frequency_Hz)))
        throw FormatError(cell("frequency_Hz"), fmt::format("{:g} must be positive and above the previous row's", *f));
      if (const std::string out = range_problem(kFrequencyRange, *f); !out.empty()) throw FormatError(cell("frequency_Hz"), out);
      if (!(*g > 0))
        throw FormatError(cell(cols[i]), fmt::format("{:g} must be positive (an axis at rest: leave its column out)", *g));
      if (const std::string out = range_problem(kPsdLevelRange, *g); !out.empty()) throw FormatError(cell(cols[i]), out);
      t.rows.push_back(vibration::PsdRow::level(*f, *g));
    }
    try {
      vibration::validate(t);
    } catch (const std::invalid_argument& e) {
      throw FormatError({.file = path, .key = cols[i], .kind = KeyKind::csv_column}, e.what());
    }
    if (const double rms = vibration::rms_g(t); !(rms <= kPsdMaxRms_g))
      throw FormatError({.file = path, .key = cols[i], .kind = KeyKind::csv_column},
                        fmt::format("the table's rms is {:g} g, over the {:g} g a shaker's motion stays within "
                                    "(docs/data-format.md, Ranges and limits)",
                                    rms, kPsdMaxRms_g));
    p.psd[i] = t;
  }
  if (!any)
    throw FormatError({.file = path}, "the header needs at least one of psd_IA_g2_per_Hz, psd_PA_g2_per_Hz, psd_OA_g2_per_Hz");
  return p;
}

// The output column of a file must carry the manifest's unit: output_<unit>, sigma_<unit>.
void require_unit(const Csv& csv, const std::string& prefix, const std::string& unit) {
  if (csv.has(prefix + unit)) return;
  for (const auto& [name, i] : csv.column)
    if (name.rfind(prefix, 0) == 0)
      throw FormatError({.file = csv.path, .key = name},
                        fmt::format("column '{}' is in '{}', the manifest's output unit is '{}' (expected '{}{}')", name,
                                    name.substr(prefix.size()), unit, prefix, unit));
  throw FormatError({.file = csv.path, .key = prefix + unit},
                    fmt::format("the header lacks column '{}{}'{}", prefix, unit, columns_found(csv, prefix + unit)));
}

// The place of a manifest's key: its line, its table ("" at the top level), its name.
FormatLocation toml_place(const std::string& file, const toml::node* n, const std::string& table, const std::string& key) {
  return {.file = file, .line = n ? static_cast<long>(n->source().begin.line) : 0, .table = table, .key = key,
          .kind = KeyKind::toml_key};
}

double toml_number(const toml::table& t, const std::string& table, const char* key, double fallback, const std::string& file) {
  const toml::node* n = t.get(key);
  if (!n) return fallback;
  if (!n->is_number()) throw FormatError(toml_place(file, n, table, key), "expected a number");
  const double x = n->value<double>().value();
  if (!std::isfinite(x)) throw FormatError(toml_place(file, n, table, key), "must be finite");
  return x;
}

void check_keys(const toml::table& t, const std::string& table, const std::vector<std::string>& allowed, const std::string& file) {
  for (auto&& [k, v] : t) {
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == k.str();
    if (!ok) throw FormatError(toml_place(file, &v, table, std::string(k.str())), "unknown key");
  }
}

int coefficient_index(const std::string& name) {
  for (int i = 0; i < plant::kNumCoefficients; ++i)
    if (plant::coefficient_name(i) == name) return i;
  return -1;
}

// The manifest's [diagnose]: DiagnoseSettings by field name (its description), checked.
void read_diagnose_settings(const toml::table& t, const std::string& file, LabManifest& m) {
  m.diagnose_given = true;
  validation::DiagnoseSettings& s = m.diagnose;
  read_settings_table(t, s, [&](const toml::node* n, const std::string& key, const std::string& what) {
    throw FormatError({.file = file, .line = static_cast<long>(n->source().begin.line), .table = "diagnose", .key = key,
                       .kind = KeyKind::toml_table},
                      what);
  });
  std::string why;
  if (!s.IsValid(&why)) throw FormatError({.file = file, .table = "diagnose", .kind = KeyKind::toml_table}, why);
}

// A run's raw record as a CSV of time and output.
std::string raw_record_csv(const std::string& id, const validation::RawRecord& rec, const std::string& unit) {
  std::string text =
      fmt::format("# {} raw record: time in s, output in {}; at rest for t < 0\ntime_s,output_{}\n", id, unit, unit);
  for (std::size_t i = 0; i < rec.t_s.size(); ++i) text += fmt::format("{:.9g},{:.12g}\n", rec.t_s[i], rec.output[i]);
  return text;
}

// A run's measured motion from its reference channels (docs/data-format.md, "Reference
// channels"): a sine run's tones, a random run's Welch cross-spectral matrix over the
// commanded band, a sine on random run's fundamental and the Welch matrix of the rest; used
// by the prediction only with all three axes (else the departure is reported).
rectification::MeasuredMotion measured_motion(const validation::RunRecord& r, const rectification::ReferenceAnalysis& a) {
  rectification::MeasuredMotion mm;
  mm.present = a.present;
  mm.frequency_Hz = a.frequency_Hz;
  // Only a reference on all three axes gives the motion: an axis without a channel would keep
  // the commanded motion (no transverse part, and a phase unrelated to the measured axes'), so
  // the table-motion effects would be neither measured nor fitted there. With fewer axes the
  // departure is reported and the run is predicted from the command.
  const bool all_axes = a.present[0] && a.present[1] && a.present[2];
  if (!r.random || r.sine_part) {
    const vibration::SineVibration cmd = r.vibration();
    Vec3 signed_g;
    for (int i = 0; i < 3; ++i) signed_g[i] = cmd.amplitude_g[i] * std::cos(cmd.phase_rad[i]);
    mm.departure = rectification::sine_departure(a, signed_g);
    if (!r.random && all_axes)
      for (int h = 1; h <= 3; ++h) {
        Eigen::Vector3cd W = a.harmonic_g[static_cast<std::size_t>(h)];
        for (std::size_t i = 0; i < 3; ++i)
          if (!a.present[i]) W[static_cast<int>(i)] = h == 1 ? std::complex<double>(signed_g[static_cast<int>(i)], 0) : 0.0;
        mm.tones.emplace_back(h, W);
      }
    if (!r.random || !all_axes) return mm;
    // Sine on random: the sine's measured fundamental (transverse parts and phases included;
    // the prediction takes one sine), the random part below from the spectra with that
    // fundamental taken off (reference.hpp; the 2nd and 3rd harmonics stay in the spectra,
    // where their second moments are carried).
    mm.tones.emplace_back(1, a.harmonic_g[1]);
  } else {
    const Eigen::Matrix3d C = vibration::gaussian_equivalent(*r.random).covariance_g2();
    mm.departure = rectification::random_departure(a, C);
    if (!all_axes) return mm;
  }
  const vibration::RandomProfile& cmd = *r.random;
  double lo = INFINITY, hi = 0;
  for (const auto& t : cmd.psd)
    if (t) lo = std::min(lo, t->rows.front().frequency_Hz), hi = std::max(hi, t->rows.back().frequency_Hz);
  // Two bins beyond each end: the Hann window's main lobe spreads a sharp band edge over
  // +-2 bins, and that power is the motion's (left out, it would be ~1 % of a 20-500 Hz table's
  // variance at 7.8 Hz bins).
  lo = std::max(lo - 2 * a.resolution_Hz, a.bin_Hz.empty() ? 0.0 : a.bin_Hz.front());
  hi += 2 * a.resolution_Hz;
  vibration::RandomProfile p = cmd;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!a.present[i]) continue;
    // A flat channel has no PSD to take (a disconnected reference reads a constant).
    if (!(a.rms_g[static_cast<int>(i)] > 0))
      throw std::invalid_argument(fmt::format("reference channel {}: flat over the vibration window (rms 0 g): no PSD to take",
                                              i == 0 ? "ref_IA_g" : i == 1 ? "ref_PA_g" : "ref_OA_g"));
    vibration::PsdTable t = rectification::welch_table(a, static_cast<int>(i), lo, hi);
    if (t.rows.size() < 2)
      throw std::invalid_argument(fmt::format("reference channels: Welch's PSD ({:g} Hz bins) has fewer than 2 bins in the "
                                              "commanded band {:g} - {:g} Hz",
                                              a.resolution_Hz, lo, hi));
    p.psd[i] = t;
  }
  // The full measured cross-spectral matrix: the transverse motion's coherence and phase with
  // the drive as measured, not the run's `coupling` (a transverse part partly coherent with
  // IA, or delayed, rectifies through the cross terms by Re(H S H^H), not sqrt(G_i G_j)).
  p.measured = std::make_shared<const vibration::CrossSpectralMatrix>(rectification::welch_matrix(a, lo, hi));
  mm.random = p;
  return mm;
}

// The manifest parsed, its top-level tables checked and the keys every campaign states there.
toml::table parse_manifest(const std::string& mpath) {
  require_readable_file(mpath, "the manifest");
  toml::table root;
  try {
    root = toml::parse_file(mpath);
  } catch (const toml::parse_error& e) {
    throw FormatError({.file = mpath, .line = static_cast<long>(e.source().begin.line)}, std::string(e.description()));
  }
  check_keys(root, "", {"campaign", "instrument", "dynamics", "identification", "files", "diagnose", "names"}, mpath);
  // What every campaign states (an empty manifest would otherwise run on defaults and fail
  // later, on the identification's rank): the format, the output unit, and the held
  // coefficients (a 1 g test cannot separate the common part of k_PP, k_OO and k2 from k0, so
  // some must be held; an explicit `fixed = { }` is the lab's choice, judged by the rank check).
  {
    std::vector<std::string> missing;
    if (!root["campaign"]["format_version"]) missing.push_back("[campaign] format_version = 1");
    if (!root["instrument"]["output_unit"]) missing.push_back("[instrument] output_unit (e.g. \"mA\")");
    if (!root["identification"]["fixed"]) missing.push_back("[identification] fixed (e.g. { k_PP = 0.0 })");
    if (!missing.empty()) {
      std::string list;
      for (const auto& k : missing) list += (list.empty() ? "" : "; ") + k;
      throw FormatError({.file = mpath}, fmt::format("missing {} (docs/data-format.md)", list));
    }
  }
  return root;
}

// The manifest's [campaign]: the name, and format_version 1.
void read_manifest_campaign(const toml::table& root, const std::string& mpath, LabManifest& m) {
  if (auto* t = root["campaign"].as_table()) {
    check_keys(*t, "campaign", {"name", "format_version"}, mpath);
    m.name = (*t)["name"].value_or(m.name);
    const toml::node* fv = t->get("format_version");
    if (!fv->is_integer())
      throw FormatError(toml_place(mpath, fv, "campaign", "format_version"), "expected the whole number 1");
    if (const auto v = fv->value<std::int64_t>(); v && *v != 1)
      throw FormatError(toml_place(mpath, nullptr, "campaign", "format_version"),
                        fmt::format("{} is not supported (this program reads 1)", *v));
    if (const toml::node* nm = t->get("name"); nm && !nm->is_string())
      throw FormatError(toml_place(mpath, nm, "campaign", "name"), "expected a string");
  }
}

// The manifest's [instrument]: the output unit and the site's g.
void read_manifest_instrument(const toml::table& root, const std::string& mpath, LabManifest& m) {
  if (auto* t = root["instrument"].as_table()) {
    check_keys(*t, "instrument", {"output_unit", "g_m_per_s2"}, mpath);
    const toml::node* u = t->get("output_unit");
    if (!u->is_string() || u->value<std::string>()->empty() ||
        u->value<std::string>()->find_first_of(",\" \t") != std::string::npos)
      throw FormatError(toml_place(mpath, u, "instrument", "output_unit"),
                        "expected a unit name such as \"mA\" (no blanks, commas or quotes)");
    m.output_unit = *u->value<std::string>();
    m.g_m_per_s2 = toml_number(*t, "instrument", "g_m_per_s2", m.g_m_per_s2, mpath);
  }
}

// The manifest's [dynamics]: the nominal loop as the manufacturer states it, checked.
void read_manifest_dynamics(const toml::table& root, const std::string& mpath, LabManifest& m, plant::Dynamics& d) {
  if (auto* t = root["dynamics"].as_table()) {
    m.dynamics_given = true;
    check_keys(*t, "dynamics",
               {"pendulum_frequency_Hz", "pendulum_damping_ratio", "angle_gain_rad_per_s2_per_g", "loop_bandwidth_Hz",
                "phase_margin_deg", "integrator", "integrator_zero_ratio"},
               mpath);
    d.pendulum_frequency_Hz = toml_number(*t, "dynamics", "pendulum_frequency_Hz", d.pendulum_frequency_Hz, mpath);
    d.pendulum_damping_ratio = toml_number(*t, "dynamics", "pendulum_damping_ratio", d.pendulum_damping_ratio, mpath);
    d.angle_gain_rad_per_s2_per_g = toml_number(*t, "dynamics", "angle_gain_rad_per_s2_per_g", d.angle_gain_rad_per_s2_per_g, mpath);
    d.loop_bandwidth_Hz = toml_number(*t, "dynamics", "loop_bandwidth_Hz", d.loop_bandwidth_Hz, mpath);
    d.phase_margin_deg = toml_number(*t, "dynamics", "phase_margin_deg", d.phase_margin_deg, mpath);
    d.integrator = (*t)["integrator"].value_or(d.integrator);
    d.integrator_zero_ratio = toml_number(*t, "dynamics", "integrator_zero_ratio", d.integrator_zero_ratio, mpath);
    std::string why;
    if (!d.IsValid(&why)) throw FormatError(toml_place(mpath, nullptr, "dynamics", ""), why);
  }
}

// The manifest's [identification] fixed: the coefficients held, by name.
void read_manifest_fixed(const toml::table& root, const std::string& mpath, validation::Campaign& c) {
  if (auto* t = root["identification"].as_table()) {
    check_keys(*t, "identification", {"fixed"}, mpath);
    if (auto* f = (*t)["fixed"].as_table())
      for (auto&& [k, v] : *f) {
        const int i = coefficient_index(std::string(k.str()));
        if (i < 0 || !v.is_number())
          throw FormatError(toml_place(mpath, &v, "identification", "fixed"),
                            fmt::format("'{}' is not a coefficient of model (1) with a number", std::string(k.str())));
        c.fixed[i] = v.value<double>().value();
      }
  }
}

// The manifest's [names]: vrelab's name of a column or dataset in the files the runs reference
// = the lab's (a string; each of the lab's names once).
void read_manifest_names(const toml::table& root, const std::string& mpath, LabManifest& m) {
  auto* t = root["names"].as_table();
  if (!t) return;
  check_keys(*t, "names",
             {"frequency_Hz", "psd_IA_g2_per_Hz", "psd_PA_g2_per_Hz", "psd_OA_g2_per_Hz", "time_s", "output_" + m.output_unit,
              "ref_IA_g", "ref_PA_g", "ref_OA_g"},
             mpath);
  for (auto&& [k, v] : *t) {
    const std::string key(k.str());
    if (!v.is_string() || v.value<std::string>()->empty())
      throw FormatError(toml_place(mpath, &v, "names", key), "expected the lab's name of the column or dataset (a string)");
    const std::string theirs = *v.value<std::string>();
    for (const auto& [other, name] : m.names)
      if (name == theirs)
        throw FormatError(toml_place(mpath, &v, "names", key), fmt::format("'{}' is already the lab's name of {}", theirs, other));
    m.names[key] = theirs;
  }
}

// The manifest's [files]: the static readings' and the runs' files, relative to the folder.
struct ManifestFiles {
  std::string static_file = "static.csv", runs_file = "runs.csv";
};
ManifestFiles read_manifest_files(const toml::table& root, const std::string& mpath) {
  ManifestFiles files;
  if (auto* t = root["files"].as_table()) {
    check_keys(*t, "files", {"static", "runs"}, mpath);
    files.static_file = (*t)["static"].value_or(files.static_file);
    files.runs_file = (*t)["runs"].value_or(files.runs_file);
  }
  return files;
}

// The static readings: every row must be usable (the identification needs them all).
void read_static_readings(const std::string& path, const std::string& unit, validation::Campaign& c) {
  const Csv st = read_csv(path, "the static readings",
                           {kMaxStaticReadings, "static readings",
                            "the identification's work grows with them; average repeated readings of a position (count)"});
  require_unit(st, "output_", unit);
  require_unit(st, "sigma_", unit);
  const bool by_vector = st.has("a_IA_g");
  if (by_vector) require_columns(st, {"a_IA_g", "a_PA_g", "a_OA_g"});
  else require_columns(st, {"series", "angle_deg"}, " (give a_IA_g, a_PA_g, a_OA_g or series, angle_deg)");
  for (const auto& row : st.rows) {
    std::optional<FormatError> why;
    auto get = [&](const std::string& col) {
      const auto x = number(st, row, col, &why);
      if (!x) throw *why;
      return *x;
    };
    const auto cell = [&](const std::string& col, long column = 0) {
      return FormatLocation{.file = st.path, .line = row.first, .column = column, .key = col, .kind = KeyKind::csv_column};
    };
    validation::StaticRecord r;
    if (by_vector) {
      r.orientation_g = Vec3(get("a_IA_g"), get("a_PA_g"), get("a_OA_g"));
      if (std::abs(r.orientation_g.norm() - 1) > 0.01)
        throw FormatError({.file = st.path, .line = row.first},
                          fmt::format("the orientation has |a| = {:.4g} g; a static position is gravity, |a| = 1 g",
                                      r.orientation_g.norm()));
    } else {
      const double s = get("series");
      if (s != 1 && s != 2 && s != 3) throw FormatError(cell("series"), "must be 1, 2 or 3");
      r.orientation_g = validation::series_orientation(static_cast<int>(s), get("angle_deg") * std::numbers::pi / 180);
    }
    r.output = get("output_" + unit);
    const double sigma = get("sigma_" + unit);
    const bool has_count = st.has("count") && st.column.at("count") < row.second.size() && !row.second[st.column.at("count")].empty();
    const double count = has_count ? get("count") : 1.0;
    if (count != std::floor(count))
      throw FormatError(cell("count", static_cast<long>(st.column.at("count") + 1)),
                        fmt::format("{} is not a whole number of readings", row.second[st.column.at("count")]));
    if (!(sigma > 0)) throw FormatError(cell("sigma_" + unit), "must be positive");
    if (!(count >= 1)) throw FormatError(cell("count"), "must be at least 1");
    if (const std::string out = range_problem(kOutputRange, r.output); !out.empty()) throw FormatError(cell("output_" + unit), out);
    if (const std::string out = range_problem(kOutputSigmaRange, sigma); !out.empty()) throw FormatError(cell("sigma_" + unit), out);
    r.sigma_output = sigma / std::sqrt(count);
    r.where = fmt::format("{}:{}", st.path, row.first);
    c.statics.push_back(r);
  }
  if (c.statics.empty()) throw FormatError({.file = st.path}, "no static readings");
}

// K1 for raw records: the static readings' least-squares scale factor.
double static_scale_factor(const validation::Campaign& c) {
  std::vector<validation::Position> pos;
  std::vector<validation::Reading> rd;
  std::vector<double> w;
  for (std::size_t i = 0; i < c.statics.size(); ++i) {
    pos.push_back(validation::vector_position(c.statics[i].orientation_g.normalized()));
    rd.push_back({static_cast<int>(i), c.statics[i].output});
    w.push_back(1 / std::pow(c.statics[i].sigma_output, 2));
  }
  return validation::least_squares(pos, rd, w, c.fixed).estimate.value[plant::K1];
}

// The runs table with what its header gives: summaries (measured_ug, sigma_ug) and/or raw
// records (series with their windows), and K1 for the raw records.
struct RunsTable {
  Csv csv;
  bool summaries = false, series = false;
  double K1 = 0;
  ChannelNames names;  // the lab's names in the files the runs reference (the manifest's [names])
};
RunsTable read_runs_table(const std::string& path, const validation::Campaign& c) {
  RunsTable t;
  t.csv = read_csv(path, "the runs table",
                   {kMaxRuns, "shaker runs", "the diagnosis' work grows as the cube of the runs (a runs x runs covariance)"});
  const Csv& rn = t.csv;
  require_columns(rn, {"id", "frequency_Hz", "amplitude_g", "d_IA", "d_PA", "d_OA", "a_IA_g", "a_PA_g", "a_OA_g"});
  t.summaries = rn.has("measured_ug"), t.series = rn.has("series");
  if (!t.summaries && !t.series)
    throw FormatError({.file = rn.path}, "the header needs measured_ug and sigma_ug (summaries) or series (raw records)");
  if (t.summaries) require_columns(rn, {"sigma_ug"});
  if (t.series) require_columns(rn, {"rest_from_s", "rest_to_s", "on_from_s", "on_to_s"});
  if (t.series) t.K1 = static_scale_factor(c);
  return t;
}

// One row of the runs table as it is read: its cells, its place for messages (`label` with the
// file and line, `named` for a `why` that already names them) and why the last number asked for
// was not one.
struct RunRow {
  const Csv& csv;
  const std::pair<int, std::vector<std::string>>& row;
  std::string id, label, named;
  std::optional<FormatError> why;

  std::optional<double> get(const std::string& col) { return number(csv, row, col, &why); }
  std::string cell(const std::string& col) const {
    return csv.has(col) && csv.column.at(col) < row.second.size() ? row.second[csv.column.at(col)] : std::string();
  }
  std::string missing() const { return named + ": " + why->what(); }
};

// The run's kind (optional column, default sine) and, for a random one, its PSD file; the
// reason when the row is skipped.
std::optional<std::string> read_run_kind(const RunRow& rr, const std::string& dir, const ChannelNames& names,
                                         VibrationKind& kind_out, validation::RunRecord& r) {
  const std::string kind_text = rr.cell("kind");
  const auto kind = kind_text.empty() ? VibrationKind::sine : rectification::parse_vibration_kind(kind_text);
  if (!kind || kind == VibrationKind::swept_sine)
    return fmt::format("{}:{}: column kind: must be sine, random or sine_on_random, got '{}'", rr.csv.path, rr.row.first,
                       kind_text);
  kind_out = *kind;
  if (kind != VibrationKind::sine) {
    const std::string coupling = rr.cell("coupling").empty() ? "common" : rr.cell("coupling");
    if (coupling != "common" && coupling != "independent")
      return fmt::format("{}:{}: column coupling: must be common or independent, got '{}'", rr.csv.path, rr.row.first,
                         coupling);
    if (rr.cell("psd").empty())
      return fmt::format("{}:{}: column psd: a {} run needs its PSD file", rr.csv.path, rr.row.first,
                         rectification::to_string(*kind));
    try {
      r.random = psd_file((fs::path(dir) / rr.cell("psd")).string(), coupling, names);
    } catch (const FormatError& e) {
      return rr.label + ": " + e.what();
    }
    r.sine_part = kind == VibrationKind::sine_on_random;
  }
  return std::nullopt;
}

// The run's motion (a sine's frequency, amplitude and direction from the row; a random run's
// from its PSD) and its static orientation; the reason when the row is skipped.
std::optional<std::string> read_run_motion(RunRow& rr, VibrationKind kind, validation::RunRecord& r) {
  const auto o0 = rr.get("a_IA_g"), o1 = rr.get("a_PA_g"), o2 = rr.get("a_OA_g");
  if (!o0 || !o1 || !o2) return rr.missing();
  if (kind == VibrationKind::random) {
    // No sine: frequency, amplitude and direction describe the PSD; the row's cells are not read.
    validation::describe_random_motion(r);
    r.orientation_g = Vec3(*o0, *o1, *o2);
  } else {
    const auto f = rr.get("frequency_Hz"), a = rr.get("amplitude_g"), d0 = rr.get("d_IA"), d1 = rr.get("d_PA"),
               d2 = rr.get("d_OA");
    if (!f || !a || !d0 || !d1 || !d2) return rr.missing();
    const Vec3 d(*d0, *d1, *d2);
    if (!(*f > 0) || !(*a > 0) || !(d.norm() > 0))
      return rr.label + ": frequency, amplitude and direction must be positive / non-zero";
    if (const std::string out = range_problem(kFrequencyRange, *f); !out.empty()) return rr.label + ": column frequency_Hz: " + out;
    if (const std::string out = range_problem(kAmplitudeRange, *a); !out.empty()) return rr.label + ": column amplitude_g: " + out;
    r.frequency_Hz = *f, r.amplitude_g = *a, r.direction = d.normalized(), r.orientation_g = Vec3(*o0, *o1, *o2);
  }
  return std::nullopt;
}

// The run's orientation is gravity and its id new; the reason when the row is skipped.
std::optional<std::string> check_run(const RunRow& rr, const validation::RunRecord& r,
                                     const std::vector<validation::RunRecord>& earlier) {
  if (std::abs(r.orientation_g.norm() - 1) > 0.01)
    return fmt::format("{}: the static orientation has |a| = {:.4g} g; gravity is 1 g (a_*_g in g)", rr.label,
                       r.orientation_g.norm());
  if (std::any_of(earlier.begin(), earlier.end(), [&](const validation::RunRecord& x) { return x.id == rr.id; }))
    return rr.label + ": the id is used by an earlier run";
  return std::nullopt;
}

// The windows of a run's raw record from its row (the vibration window as given in *on_to_s);
// the reason when the row is skipped.
std::optional<std::string> record_windows(RunRow& rr, const validation::RunRecord& r, double K1,
                                          rectification::SeriesWindows& win, double* on_to_s) {
  const auto rf = rr.get("rest_from_s"), rt = rr.get("rest_to_s"), of = rr.get("on_from_s"), ot = rr.get("on_to_s");
  if (!rf || !rt || !of || !ot) return rr.missing();
  *on_to_s = *ot;
  win.baseline_from_s = *rf, win.baseline_to_s = *rt, win.on_from_s = *of, win.on_to_s = *ot;
  win.frequency_Hz = r.frequency_Hz, win.K1 = K1;
  // Batch means over whole periods: up to 8 blocks of equal whole numbers of periods (the
  // vibration window shortened to a multiple of the blocks). A random run (random or sine
  // on random, not periodic): 8 blocks over the window as given.
  if (r.random) win.frequency_Hz = 0, win.blocks = 8;
  const long periods = r.random ? 8 : static_cast<long>(std::floor((*ot - *of) * r.frequency_Hz + 1e-9));
  if (periods < 2)
    return fmt::format("{}: the vibration window holds {} whole period(s) of {:g} Hz; at least 2 are needed", rr.label,
                       periods, r.frequency_Hz);
  if (!r.random) {
    win.blocks = static_cast<int>(std::min<long>(8, periods));
    win.on_to_s = *of + static_cast<double>(periods / win.blocks * win.blocks) / r.frequency_Hz;
  }
  return std::nullopt;
}

// A run's raw record measured over its windows, and the table's motion from its reference
// channels; throws std::invalid_argument or FormatError for a record that cannot be used.
void measure_record(const std::string& spath, const rectification::SeriesWindows& win, double on_to_s,
                    const std::string& unit, const ChannelNames& names, validation::RunRecord& r) {
  win.validate();
  rectification::SeriesMeasurer meas(win);
  // Reference channels (docs/data-format.md, "Reference channels"): the table's motion
  // over the vibration window, analysed as it streams (harmonics, or Welch's PSD).
  rectification::ReferenceWindow rwin;
  rwin.from_s = win.on_from_s, rwin.to_s = rectification::used_on_to_s(win);
  rwin.frequency_Hz = r.random ? (r.sine_part ? r.frequency_Hz : 0.0) : r.frequency_Hz;
  rwin.sine_on_random = r.random && r.sine_part;
  std::optional<rectification::ReferenceAnalyzer> refan;
  const ReferenceSink reference = [&](double t_s, const std::array<double, 3>& ref_g, const std::array<bool, 3>& present) {
    if (!refan) refan.emplace(rwin);
    refan->add(t_s, ref_g, present);
  };
  // The record, CSV or HDF5 by its extension (io/formats/series.hpp): time_s, output_<unit> and
  // the optional reference channels.
  double last_t = -INFINITY, first_dt = 0;
  read_series(
      spath, "output_" + unit,
      [&](double t, double u) {
        if (std::isfinite(last_t) && first_dt == 0) first_dt = t - last_t;  // as SeriesMeasurer detects it
        last_t = t;
        meas.add(t, u);
      },
      reference, names);
  // Half-open windows, decided as `measure` does (rectification/measurement/series.hpp).
  if (!rectification::record_covers_window_end(rectification::used_on_to_s(win), last_t, first_dt))
    throw std::invalid_argument(fmt::format("{}: the record ends at {:g} s, before on_to_s = {:g} s", spath, last_t, on_to_s));
  const rectification::SeriesResult res = meas.finish();
  r.measured_g = res.measured_g, r.sigma_g = res.sigma_g;
  if (refan) {
    try {
      r.motion = measured_motion(r, refan->finish());
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("{}: {}", spath, e.what()));
    }
  }
}

// The run's vibration error from its raw record `file`; the reason when the row is skipped.
std::optional<std::string> read_run_record(RunRow& rr, const RunsTable& runs, const std::string& dir,
                                           const std::string& file, const std::string& unit, validation::RunRecord& r) {
  rectification::SeriesWindows win;
  double on_to_s = 0;
  if (auto skip = record_windows(rr, r, runs.K1, win, &on_to_s)) return skip;
  const std::string spath = (fs::path(dir) / file).string();
  try {
    measure_record(spath, win, on_to_s, unit, runs.names, r);
  } catch (const std::invalid_argument& e) {
    return rr.label + ": " + e.what();
  } catch (const FormatError& e) {
    return rr.label + ": " + e.what();
  }
  return std::nullopt;
}

// The run's vibration error from the row's summary (measured_ug, sigma_ug); the reason when
// the row is skipped.
std::optional<std::string> read_run_summary(RunRow& rr, const RunsTable& runs, validation::RunRecord& r) {
  if (!runs.summaries) return rr.label + ": neither a series nor measured_ug";
  const auto mu = rr.get("measured_ug"), su = rr.get("sigma_ug");
  if (!mu || !su) return rr.missing();
  if (!(*su > 0)) return rr.label + ": sigma_ug must be positive";
  if (const std::string out = range_problem(kErrorRange, *mu); !out.empty()) return rr.label + ": column measured_ug: " + out;
  if (const std::string out = range_problem(kSigmaUgRange, *su); !out.empty()) return rr.label + ": column sigma_ug: " + out;
  r.measured_g = *mu * 1e-6, r.sigma_g = *su * 1e-6;
  return std::nullopt;
}

// One row of the runs table into `r`: the reason when the row is skipped (a bad run is
// skipped with why, the others read).
std::optional<std::string> read_run(const RunsTable& runs, const std::pair<int, std::vector<std::string>>& row,
                                    const std::string& dir, const std::string& unit,
                                    const std::vector<validation::RunRecord>& earlier, validation::RunRecord& r) {
  const Csv& rn = runs.csv;
  const std::string idc = rn.column.at("id") < row.second.size() ? row.second[rn.column.at("id")] : "";
  RunRow rr{.csv = rn,
            .row = row,
            .id = idc,
            .label = fmt::format("{}:{} (run '{}')", rn.path, row.first, idc),
            .named = fmt::format("run '{}'", idc),  // `why` already names the file and line
            .why = std::nullopt};
  r.id = idc;
  r.where = fmt::format("{}:{}", rn.path, row.first);
  VibrationKind kind = VibrationKind::sine;
  if (auto skip = read_run_kind(rr, dir, runs.names, kind, r)) return skip;
  if (auto skip = read_run_motion(rr, kind, r)) return skip;
  if (auto skip = check_run(rr, r, earlier)) return skip;
  const std::string file = runs.series && rn.column.at("series") < row.second.size() ? row.second[rn.column.at("series")] : "";
  if (auto skip = file.empty() ? read_run_summary(rr, runs, r) : read_run_record(rr, runs, dir, file, unit, r)) return skip;
  // Optional: the run's time and the rest reading before it (a bias drift, docs/data-format.md).
  if (rn.has("time_h"))
    if (const auto t = rr.get("time_h")) r.time_h = *t;
  if (rn.has("rest_ug"))
    if (const auto x = rr.get("rest_ug")) r.rest_g = *x * 1e-6;
  return std::nullopt;
}

}  // namespace

validation::Campaign read_campaign(const std::string& dir, LabManifest* manifest_out) {
  const std::string mpath = (fs::path(dir) / "manifest.toml").string();
  const toml::table root = parse_manifest(mpath);
  validation::Campaign c;
  LabManifest m;
  read_manifest_campaign(root, mpath, m);
  c.name = m.name;
  read_manifest_instrument(root, mpath, m);
  read_manifest_dynamics(root, mpath, m, c.dynamics);
  read_manifest_fixed(root, mpath, c);
  if (auto* t = root["diagnose"].as_table()) read_diagnose_settings(*t, mpath, m);
  read_manifest_names(root, mpath, m);
  const ManifestFiles files = read_manifest_files(root, mpath);
  read_static_readings((fs::path(dir) / files.static_file).string(), m.output_unit, c);
  RunsTable runs = read_runs_table((fs::path(dir) / files.runs_file).string(), c);
  runs.names = m.names;
  for (const auto& row : runs.csv.rows) {
    validation::RunRecord r;
    if (const auto skip = read_run(runs, row, dir, m.output_unit, c.runs, r)) c.skipped.push_back(*skip);
    else c.runs.push_back(r);
  }
  if (manifest_out) *manifest_out = m;
  return c;
}

vibration::RandomProfile read_psd_file(const std::string& path, const std::string& coupling, const ChannelNames& names) {
  return psd_file(path, coupling, names);
}

namespace {
// A random run's PSD file (read_psd_file reads it back): the axes' tables at their shared
// frequencies, levels resolved (straight lines on log-log axes between rows, as they were).
std::string psd_file_text(const validation::RunRecord& r) {
  std::string head = "frequency_Hz", body;
  std::vector<vibration::ResolvedPsd> axes;
  for (int i = 0; i < 3; ++i)
    if (const auto& t = r.random->psd[static_cast<std::size_t>(i)]) {
      axes.push_back(vibration::resolve(*t));
      head += fmt::format(",psd_{}_g2_per_Hz", i == 0 ? "IA" : i == 1 ? "PA" : "OA");
    }
  for (const auto& a : axes)
    if (a.frequency_Hz != axes.front().frequency_Hz)
      throw std::invalid_argument("write_campaign: run " + r.id + ": the axes' PSD tables must share their frequencies (one frequency_Hz column)");
  for (std::size_t j = 0; j < axes.front().frequency_Hz.size(); ++j) {
    body += fmt::format("{:.10g}", axes.front().frequency_Hz[j]);
    for (const auto& a : axes) body += fmt::format(",{:.10g}", a.psd_g2_per_Hz[j]);
    body += "\n";
  }
  return fmt::format("# {}'s random part: one-sided PSD per sensor axis, g^2/Hz (docs/data-format.md, \"Random runs\")\n{}\n{}",
                     r.id, head, body);
}
}  // namespace

void write_campaign(const std::string& dir, const validation::Campaign& c, const LabManifest& m,
                    const std::vector<RawSeriesRef>& raw_series, RawFormat raw_format) {
  std::vector<RawSeriesRef> raw = raw_series;
  if (raw.empty())
    for (std::size_t k = 0; k < c.raw.size(); ++k) {
      const validation::RawRecord& rec = c.raw[k];
      const std::string file = "records/" + c.runs[k].id + (raw_format == RawFormat::hdf5 ? ".h5" : ".csv");
      if (raw_format == RawFormat::hdf5) {
        Hdf5SeriesWriter w(dir + "/" + file, m.output_unit, {}, c.runs[k].id, "at rest for t < 0");
        for (std::size_t i = 0; i < rec.t_s.size(); ++i) w.add(rec.t_s[i], rec.output[i]);
        w.commit();
      } else {
        write_atomic(dir + "/" + file, raw_record_csv(c.runs[k].id, rec, m.output_unit));
      }
      raw.push_back({file, rec.rest_from_s, rec.rest_to_s, rec.on_from_s, rec.on_to_s});
    }
  const plant::Dynamics& d = c.dynamics;
  std::string fixed;
  for (int i = 0; i < plant::kNumCoefficients; ++i)
    if (c.fixed[i]) fixed += fmt::format("{}{} = {:.10g}", fixed.empty() ? "" : ", ", plant::coefficient_name(i), *c.fixed[i]);
  write_atomic(dir + "/manifest.toml",
               fmt::format("# vrelab lab data format 1 (docs/data-format.md)\n[campaign]\nname = \"{}\"\nformat_version = 1\n\n"
                           "[instrument]\noutput_unit = \"{}\"\ng_m_per_s2 = {:.10g}\n\n"
                           "[dynamics]                      # nominal, as the manufacturer states them\n"
                           "pendulum_frequency_Hz = {:.10g}\npendulum_damping_ratio = {:.10g}\n"
                           "angle_gain_rad_per_s2_per_g = {:.10g}\nloop_bandwidth_Hz = {:.10g}\nphase_margin_deg = {:.10g}\n"
                           "integrator = {}\nintegrator_zero_ratio = {:.10g}\n\n"
                           "[identification]\nfixed = {{ {} }}\n\n[files]\nstatic = \"static.csv\"\nruns = \"runs.csv\"\n",
                           [&] {
                             std::string e;
                             for (char ch : m.name) e += ch == '"' || ch == '\\' ? std::string("\\") + ch : std::string(1, ch);
                             return e;
                           }(),
                           m.output_unit, m.g_m_per_s2, d.pendulum_frequency_Hz, d.pendulum_damping_ratio,
                           d.angle_gain_rad_per_s2_per_g, d.loop_bandwidth_Hz, d.phase_margin_deg, d.integrator ? "true" : "false",
                           d.integrator_zero_ratio, fixed));
  std::string st = fmt::format("# static readings: orientation in g (sensor axes), mean output and one reading's sigma in {}\n"
                               "a_IA_g,a_PA_g,a_OA_g,output_{},sigma_{},count\n",
                               m.output_unit, m.output_unit, m.output_unit);
  for (const auto& s : c.statics)
    st += fmt::format("{:.12g},{:.12g},{:.12g},{:.15g},{:.6g},1\n", s.orientation_g[0], s.orientation_g[1], s.orientation_g[2],
                      s.output, s.sigma_output);
  write_atomic(dir + "/static.csv", st);
  const bool any_random = std::any_of(c.runs.begin(), c.runs.end(), [](const validation::RunRecord& r) { return r.random.has_value(); });
  if (any_random && !raw.empty()) throw std::invalid_argument("write_campaign: raw records beside random runs are not written");
  std::string rn = "# shaker runs: sine, amplitude in g peak along d (sensor axes, in phase), static orientation a in g;\n"
                   "# measured vibration error and its sigma in ug, or a raw series (time_s, output) with its windows in s\n";
  if (any_random)
    rn += "# kind random: the PSD file's motion (frequency_Hz, amplitude_g and d_* empty); sine_on_random: the sine in\n"
          "# frequency_Hz, amplitude_g, d_* and the random part in the PSD file; coupling of the random part's axes\n";
  rn += raw.empty() ? std::string("id,frequency_Hz,amplitude_g,d_IA,d_PA,d_OA,a_IA_g,a_PA_g,a_OA_g,measured_ug,sigma_ug") +
                          (any_random ? ",kind,psd,coupling\n" : "\n")
                    : "id,frequency_Hz,amplitude_g,d_IA,d_PA,d_OA,a_IA_g,a_PA_g,a_OA_g,series,rest_from_s,rest_to_s,on_from_s,on_to_s\n";
  for (std::size_t k = 0; k < c.runs.size(); ++k) {
    const auto& r = c.runs[k];
    if (r.random && !r.sine_part)
      rn += fmt::format("{},,,,,,{:.12g},{:.12g},{:.12g},", r.id, r.orientation_g[0], r.orientation_g[1], r.orientation_g[2]);
    else
      rn += fmt::format("{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.12g},{:.12g},{:.12g},", r.id, r.frequency_Hz, r.amplitude_g,
                        r.direction[0], r.direction[1], r.direction[2], r.orientation_g[0], r.orientation_g[1], r.orientation_g[2]);
    if (any_random) {
      rn += fmt::format("{:.10g},{:.6g},", r.measured_g * 1e6, r.sigma_g * 1e6);
      if (!r.random) {
        rn += "sine,,\n";
        continue;
      }
      const std::string psd = "psd/" + r.id + ".csv";
      write_atomic(dir + "/" + psd, psd_file_text(r));
      rn += fmt::format("{},{},{}\n", r.sine_part ? "sine_on_random" : "random", psd,
                        r.random->coupling == vibration::AxisCoupling::common ? "common" : "independent");
    } else if (raw.empty())
      rn += fmt::format("{:.10g},{:.6g}\n", r.measured_g * 1e6, r.sigma_g * 1e6);
    else
      rn += fmt::format("{},{:.10g},{:.10g},{:.10g},{:.10g}\n", raw[k].file, raw[k].rest_from_s, raw[k].rest_to_s,
                        raw[k].on_from_s, raw[k].on_to_s);
  }
  write_atomic(dir + "/runs.csv", rn);
}

}  // namespace vrelab::io
