#include "io/formats/output.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <fstream>
#include <stdexcept>

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

#include "io/formats/paths.hpp"
#include "vrelab_version.hpp"

namespace vrelab::io {

namespace {

// Flushes an open file (or folder) to the disk; false when the system says it could not.
// EINVAL: the file system cannot sync (e.g. some network or special file systems): nothing to do.
bool sync_fd(int fd) { return ::fsync(fd) == 0 || errno == EINVAL; }

}  // namespace

// Durable as well as atomic: the temporary file's data are fsync'ed before the rename (else
// a crash soon after could leave the new name on an empty or partial file: rename is ordered
// before the data on ext4's and XFS's delayed allocation), and the folder after it (so the
// new name itself survives a crash).
void write_atomic(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  require_writable_file(path, "the result");
  const fs::path target(path);
  std::error_code dir_error;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), dir_error);
  if (dir_error) throw FormatError("cannot create the folder of " + target.string() + ": " + dir_error.message());
  const fs::path tmp = target.string() + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw FormatError("cannot write " + tmp.string() + ": " + std::strerror(errno));
  std::size_t done = 0;
  bool ok = true;
  while (ok && done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  const std::string why = ok ? "" : std::strerror(errno);
  ok = ok && sync_fd(fd);
  ok = (::close(fd) == 0) && ok;
  if (!ok) {
    fs::remove(tmp, dir_error);
    throw FormatError("cannot write " + tmp.string() + (why.empty() ? "" : ": " + why));
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, dir_error);
    throw FormatError("cannot write " + target.string() + ": " + ec.message());
  }
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const int dfd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    sync_fd(dfd);
    ::close(dfd);
  }
}

std::string json_text(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

namespace {
std::string non_finite_at(const nlohmann::json& j, const std::string& at, double* value) {
  if (j.is_number_float() && !std::isfinite(j.get<double>())) {
    *value = j.get<double>();
    return at.empty() ? "/" : at;
  }
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it)
      if (std::string p = non_finite_at(it.value(), at + "/" + it.key(), value); !p.empty()) return p;
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i)
      if (std::string p = non_finite_at(j[i], at + "/" + std::to_string(i), value); !p.empty()) return p;
  return "";
}
}  // namespace

std::string first_non_finite(const nlohmann::json& j) {
  double value = 0;
  return non_finite_at(j, "", &value);
}

void require_finite(const nlohmann::json& j, const std::string& source, const std::string& why) {
  double value = 0;
  if (const std::string p = non_finite_at(j, "", &value); !p.empty())
    throw FormatError({.file = path_for_message(source)},
                      "the result " + p + " is not a finite number (" + (std::isnan(value) ? "nan" : "inf") + "): " + why);
}

nlohmann::json program_record() {
  return {{"name", "vrelab"}, {"version", kProgramVersion}, {"git", kGitDescribe}};
}

nlohmann::json case_record(const Case& c) { return {{"file", c.path}, {"content", c.content}}; }

nlohmann::json result_record(const std::string& command, const Case& c) {
  return {{"program", program_record()}, {"command", command}, {"case", case_record(c)}, {"seed", c.seed}};
}

using nlohmann::json;
using plant::kNumCoefficients;

std::string unit_of(int i, const Case& c) {
  const std::string u(plant::coefficient_info()[i].unit);
  return u == "out/g" ? c.output_unit + "/g" : u;
}

json coefficients_json(const plant::Coefficients& k, const validation::CoefFlags* available) {
  json j = json::object();
  for (int i = 0; i < kNumCoefficients; ++i) {
    const std::string name(plant::coefficient_name(i));
    j[name] = (available && !(*available)[i]) ? json(nullptr) : json(k[i]);
  }
  return j;
}

json vec_json(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

json plant_json(const plant::PlantConfig& p, bool physical) {
  const plant::Dynamics& d = p.dynamics;
  const plant::Servo sv = p.servo ? *p.servo : plant::design_servo(d);
  json loc = json::object();
  for (int i = 1; i < kNumCoefficients; ++i)
    loc[std::string(plant::coefficient_name(i))] = std::string(plant::location_name(p.location[i]));
  json effects = json::array();
  for (const auto& e : p.effects) effects.push_back(e->name());
  return {{"type", physical ? "physical" : "from_coefficients"},
          {"coefficients", coefficients_json(p.coefficients)},
          {"torquer_c2_per_g", p.torquer_c2_per_g},
          {"torquer_c3_per_g2", p.torquer_c3_per_g2},
          {"dynamics",
           {{"pendulum_frequency_Hz", d.pendulum_frequency_Hz},
            {"pendulum_damping_ratio", d.pendulum_damping_ratio},
            {"angle_gain_rad_per_s2_per_g", d.angle_gain_rad_per_s2_per_g},
            {"loop_bandwidth_Hz", d.loop_bandwidth_Hz},
            {"phase_margin_deg", d.phase_margin_deg},
            {"integrator", d.integrator},
            {"integrator_zero_ratio", d.integrator_zero_ratio},
            {"antialias_Hz", d.antialias_Hz}}},
          {"servo",
           {{"gain_g_per_rad", sv.gain_g_per_rad},
            {"lead_zero_Hz", sv.lead_zero_rad_per_s / (2 * std::numbers::pi)},
            {"lead_pole_Hz", sv.lead_pole_rad_per_s / (2 * std::numbers::pi)},
            {"integrator_Hz", sv.integrator_rad_per_s / (2 * std::numbers::pi)}}},
          {"location", loc},
          {"effects", effects}};
}

// The plot scripts are found from where the program is, never from a source path compiled
// in: VRELAB_PLOTS_DIR when set; else beside the executable's real path (/proc/self/exe), at
// ../share/vrelab/plots (an install: <prefix>/bin/vrelab) or share/vrelab/plots (the build
// tree, where the build copies tools/plots; the test programs sit in build/tests/ and find
// the same copy through ../share).
std::string run_plot_script(const std::string& script, const std::string& dir) {
  namespace fs = std::filesystem;
  std::vector<fs::path> places;
  if (const char* env = std::getenv("VRELAB_PLOTS_DIR"); env != nullptr && *env != '\0') {
    places.emplace_back(env);
  } else {
    std::error_code ec;
    const fs::path exe = fs::canonical("/proc/self/exe", ec);
    if (!ec) places = {exe.parent_path() / ".." / "share" / "vrelab" / "plots", exe.parent_path() / "share" / "vrelab" / "plots"};
  }
  fs::path script_path;
  std::string looked;
  for (const fs::path& place : places) {
    std::error_code ec;
    if (fs::is_regular_file(place / script, ec)) {
      script_path = (place / script).lexically_normal();
      break;
    }
    looked += (looked.empty() ? "" : ", ") + place.lexically_normal().string();
  }
  if (script_path.empty())
    return "plot script " + script + " not found (looked in " + (looked.empty() ? std::string("no place") : looked) +
           "; set VRELAB_PLOTS_DIR to the folder of the plot scripts)";
  std::string py;
  for (const char* candidate : {"/usr/bin/python3", "python3"}) {
    const std::string probe = std::string(candidate) + " -c 'import matplotlib' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) {
      py = candidate;
      break;
    }
  }
  if (py.empty()) return "no Python with matplotlib found (install it: apt-get install python3-matplotlib)";
  // Single-quoted for the shell, with any ' inside written as '\'' (a path may hold one).
  const auto quote = [](const std::string& x) {
    std::string q = "'";
    for (char ch : x) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return q + "'";
  };
  const std::string cmd = py + " " + quote(script_path.string()) + " " + quote(dir);
  if (std::system(cmd.c_str()) != 0) return "the figure script failed: " + cmd;
  return "";
}

}  // namespace vrelab::io
