// python/vrelab_module.cpp -- vrelab._core: the Python binding of the library (pybind11).
//
// A thin layer: each function reads or takes a Case, calls the same library function as the
// CLI command of its name (io/services/studies.hpp, io/services/diagnosis.hpp, io/services/reproduce_run.hpp) and returns
// an object holding the C++ result. Its to_dict() is the CLI's JSON for the same case, made by
// the same writers (io/services/results_json.hpp, io/services/diagnosis_json.hpp) and converted from
// nlohmann::json to Python objects; its typed attributes read the C++ struct. No physics here.
//
// Errors: io::InputError and std::invalid_argument (the CLI's exit code 2) raise
// vrelab.InputError (a ValueError) with the same message; plant::SolverError raises
// vrelab.SolverError (call, flag, t_s). Calls that simulate run with the GIL released and can
// be stopped with Ctrl-C (interruptible below: the library's cancel flag, core/cancel.hpp).
#include <Python.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <toml++/toml.h>

#include "core/cancel.hpp"
#include "io/formats/case_file.hpp"
#include "io/services/diagnosis.hpp"
#include "io/services/diagnosis_json.hpp"
#include "io/formats/output.hpp"
#include "io/formats/paths.hpp"
#include "io/formats/ranges.hpp"
#include "io/services/reproduce_report.hpp"
#include "io/services/reproduce_run.hpp"
#include "io/services/results_json.hpp"
#include "io/services/studies.hpp"
#include "plant/model1.hpp"
#include "plant/ode_solver.hpp"
#include "validation/diagnosis/diagnosis_text.hpp"
#include "vrelab_version.hpp"

namespace py = pybind11;
using namespace vrelab;

namespace {

// ---------------------------------------------------------------- JSON <-> Python

// nlohmann::json -> dict/list/float/int/str/bool/None. Non-finite numbers become None, as the
// CLI's JSON files write them (null), so to_dict() equals json.load of the CLI's file.
py::object to_py(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: {
      const double x = j.get<double>();
      return std::isfinite(x) ? py::object(py::float_(x)) : py::object(py::none());
    }
    case nlohmann::json::value_t::string: return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& e : j) l.append(to_py(e));
      return py::object(std::move(l));
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (auto it = j.begin(); it != j.end(); ++it) d[py::str(it.key())] = to_py(it.value());
      return py::object(std::move(d));
    }
    default: return py::none();
  }
}

// ---------------------------------------------------------------- dict -> TOML -> Case

// A case dict's conversion to TOML: iterative in spirit, bounded in fact. A case is tables of
// values two or three levels deep; the conversion recurses once per level and stops at
// kMaxCaseDepth, and a dict or list that holds itself (on the way from the top) is named, so
// neither a self-containing dict nor one nested 100 000 deep can exhaust the C++ stack.
constexpr int kMaxCaseDepth = 32;

struct Nesting {
  std::string argument;              // the argument converted, for messages ("Case.from_dict(d)")
  std::vector<const PyObject*> open;  // the containers on the way from the top
};

std::string place(const std::string& where) { return where.empty() ? "the top level" : where; }

// Enters container `v` at `where`: refuses a container already on the way (it holds itself)
// and a depth beyond kMaxCaseDepth.
void enter(Nesting& n, const py::handle& v, const std::string& where) {
  if (std::find(n.open.begin(), n.open.end(), v.ptr()) != n.open.end())
    throw io::InputError(n.argument + ": " + place(where) + " holds a dict or list that contains itself; a case is a tree of tables");
  if (static_cast<int>(n.open.size()) >= kMaxCaseDepth)
    throw io::InputError(n.argument + ": " + place(where) + " nests deeper than " + std::to_string(kMaxCaseDepth) +
                         " levels; a case is tables of values, two or three levels deep");
  n.open.push_back(v.ptr());
}

toml::array to_toml_array(const py::handle& seq, const std::string& where, Nesting& n);

// One value of a case dict as TOML (bool, int, float, str, list/tuple/array, dict).
template <class Insert>
void put_toml(const py::handle& v, const std::string& where, Nesting& n, Insert&& insert);

toml::table to_toml_table(const py::dict& d, const std::string& where, Nesting& n) {
  enter(n, d, where);
  toml::table t;
  for (const auto& [k, v] : d) {
    if (!py::isinstance<py::str>(k)) throw io::InputError(n.argument + ": " + place(where) + ": keys must be strings");
    const std::string key = k.cast<std::string>();
    const std::string at = where.empty() ? key : where + "." + key;
    put_toml(v, at, n, [&](auto&& node) { t.insert_or_assign(key, std::forward<decltype(node)>(node)); });
  }
  n.open.pop_back();
  return t;
}

template <class Insert>
void put_toml(const py::handle& v, const std::string& where, Nesting& n, Insert&& insert) {
  if (py::isinstance<py::bool_>(v)) return insert(v.cast<bool>());
  if (py::isinstance<py::int_>(v)) {
    int overflow = 0;
    const long long i = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
    if (overflow != 0) throw io::InputError(n.argument + ": " + place(where) + ": the integer does not fit in 64 bits (TOML's range)");
    return insert(static_cast<std::int64_t>(i));
  }
  if (py::isinstance<py::float_>(v)) return insert(v.cast<double>());
  if (py::isinstance<py::str>(v)) return insert(v.cast<std::string>());
  if (py::isinstance<py::dict>(v)) return insert(to_toml_table(v.cast<py::dict>(), where, n));
  if (py::hasattr(v, "tolist")) {  // NumPy arrays and scalars (a level of its own: tolist() may return anything)
    enter(n, v, where);
    const py::object plain = v.attr("tolist")();
    put_toml(plain, where, n, std::forward<Insert>(insert));
    n.open.pop_back();
    return;
  }
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) return insert(to_toml_array(v, where, n));
  throw io::InputError(n.argument + ": " + place(where) + ": cannot be written as TOML (a " +
                       std::string(py::str(v.get_type().attr("__name__"))) + ")");
}

toml::array to_toml_array(const py::handle& seq, const std::string& where, Nesting& n) {
  enter(n, seq, where);
  toml::array a;
  for (const auto& e : seq) {
    if (py::isinstance<py::dict>(e)) {
      a.push_back(to_toml_table(e.cast<py::dict>(), where, n));  // an array of tables
      continue;
    }
    put_toml(e, where, n, [&](auto&& node) { a.push_back(std::forward<decltype(node)>(node)); });
  }
  n.open.pop_back();
  return a;
}

// `argument`: how messages name the dict ("Case.from_dict(d)").
std::string case_toml(const py::dict& d, const std::string& argument) {
  Nesting n{argument, {}};
  std::ostringstream s;
  s << to_toml_table(d, "", n) << "\n";
  return s.str();
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t p = s.find(from); !from.empty() && p != std::string::npos; p = s.find(from, p + to.size()))
    s.replace(p, from.size(), to);
  return s;
}

// The same case reader as for a file: the TOML text goes through a private temporary file,
// whose path the case and its messages then name as `name`.
io::Case case_from_toml(const std::string& text, const std::string& name) {
  namespace fs = std::filesystem;
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("vrelab-case-" + std::to_string(rd()) + std::to_string(rd()));
  fs::create_directories(dir);
  const fs::path file = dir / "case.toml";
  struct Cleanup {
    fs::path d;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(d, ec);
    }
  } cleanup{dir};
  {
    std::ofstream out(file);
    out << text;
    if (!out) throw io::InputError(name + ": cannot write a temporary case file in " + dir.string());
  }
  try {
    io::Case c = io::read_case(file.string());
    c.path = name;
    return c;
  } catch (const io::InputError& e) {
    throw io::InputError(replace_all(e.what(), file.string(), name));
  }
}

// ---------------------------------------------------------------- results

struct IdentifyResult {
  io::Case c;
  io::IdentifyStudy s;
};
struct PredictResult {
  io::Case c;
  io::PredictStudy s;
};
struct Series {
  std::vector<double> t_s, in_IA, in_PA, in_OA, out;
};
struct ShakeResult {
  io::Case c;
  io::ShakeStudy s;
  std::shared_ptr<Series> series;  // null unless asked for
};
struct FrequencyResult {
  io::Case c;
  io::FrequencyStudy s;
};
struct SweepResult {
  io::SweepStudy s;
  std::string path;
};
struct ReproduceResult {
  io::Case c;
  io::ReproduceRun run;
};

py::array_t<double> array(const std::vector<double>& v) { return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data()); }

py::dict coefficient_dict(const plant::Coefficients& k) {
  py::dict d;
  for (int i = 0; i < plant::kNumCoefficients; ++i) d[py::str(std::string(plant::coefficient_name(i)))] = k[i];
  return d;
}
template <class A>
py::dict coefficient_dict_of(const A& a) {
  py::dict d;
  for (int i = 0; i < plant::kNumCoefficients; ++i) d[py::str(std::string(plant::coefficient_name(i)))] = a[static_cast<std::size_t>(i)];
  return d;
}

py::dict terms_dict(const rectification::Eq3Terms& t) {
  py::dict d;
  for (int i = 0; i < rectification::kNumTerms; ++i) d[py::str(std::string(rectification::term_name(i)))] = t.g[static_cast<std::size_t>(i)];
  return d;
}

const validation::MethodResult& method_named(const IdentifyResult& r, const std::string& name) {
  for (const auto& m : r.s.report.methods)
    if (m.name == name) return m;
  std::string known;
  for (const auto& m : r.s.report.methods) known += (known.empty() ? "" : ", ") + m.name;
  throw py::key_error("no method \"" + name + "\" (the methods: " + known + ")");
}

// A long library call, interruptible with Ctrl-C: it runs on a thread of its own with the GIL
// released, while the calling thread runs Python's signal handlers every 50 ms. A
// KeyboardInterrupt sets the call's cancel flag (core/cancel.hpp); the call ends at its next
// check (the next ODE output time or work item) with core::Cancelled, before what it writes at
// its end, and the KeyboardInterrupt is raised here. Signals reach Python's main thread only:
// called from another thread, the call runs to its end.
template <class F>
auto interruptible(F&& f) -> decltype(f()) {
  using R = decltype(f());
  std::atomic<bool> cancel{false};
  std::optional<R> result;
  std::exception_ptr failure;
  bool interrupted = false;
  {
    py::gil_scoped_release nogil;
    std::mutex m;
    std::condition_variable cv;
    bool done = false;
    std::thread worker([&] {
      core::CancelScope scope(&cancel);
      try {
        result.emplace(f());
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard<std::mutex> g(m);
      done = true;
      cv.notify_one();
    });
    std::unique_lock<std::mutex> lock(m);
    while (!cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) {
      if (interrupted) continue;
      lock.unlock();
      {
        py::gil_scoped_acquire gil;
        interrupted = PyErr_CheckSignals() != 0;  // the handler's exception stays set
      }
      if (interrupted) cancel = true;
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  if (interrupted) throw py::error_already_set();
  if (failure) std::rethrow_exception(failure);
  return std::move(*result);
}

template <class T>
const char* py_type_name() {
  if constexpr (std::is_same_v<T, bool>) return "bool";
  else if constexpr (std::is_integral_v<T>) return "int";
  else return "float";
}

// Keywords onto DiagnoseSettings overrides: each a field of the description (None: not
// given); an unknown keyword or a value of the wrong type raises TypeError.
io::DiagnoseOverrides diagnose_overrides(const char* function, const py::kwargs& kw) {
  io::DiagnoseOverrides o;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    bool known = false;
    core::for_each_field<validation::DiagnoseSettings>([&](const auto& f) {
      using T = typename std::decay_t<decltype(f)>::Type;
      if (f.name != key) return;
      known = true;
      if (v.is_none()) return;
      const bool ok = std::is_same_v<T, bool> ? py::isinstance<py::bool_>(v)
                                              : !py::isinstance<py::bool_>(v) && (std::is_integral_v<T> ? py::isinstance<py::int_>(v)
                                                                                                        : py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v));
      if (!ok)
        throw py::type_error(std::string(function) + "(): " + key + " takes a " + py_type_name<T>() + ", got " +
                             std::string(Py_TYPE(v.ptr())->tp_name));
      o.set(f.member, v.cast<T>());
    });
    if (!known) throw py::type_error(std::string(function) + "() got an unexpected keyword argument '" + key + "'");
  }
  return o;
}

// The keywords' section of diagnose's docstring.
std::string diagnose_keywords_doc() {
  const validation::DiagnoseSettings d;
  std::string doc = "Keywords (the diagnosis' settings, docs/diagnose.md):\n";
  core::for_each_field<validation::DiagnoseSettings>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    doc += "  " + std::string(f.name) + " (" + py_type_name<T>() + ", default " + core::format_value(d.*f.member);
    if (f.range.has_min || f.range.has_max) doc += "; " + core::range_text(f.range, f.unit);
    doc += "): " + std::string(f.help) + "\n";
  });
  return doc;
}

// DiagnoseSettings' description as a list of dicts (the Python tests iterate it).
py::list diagnose_settings_description() {
  const validation::DiagnoseSettings d;
  py::list out;
  core::for_each_field<validation::DiagnoseSettings>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    py::dict e;
    e["name"] = std::string(f.name);
    e["type"] = py_type_name<T>();
    e["unit"] = std::string(f.unit);
    e["default"] = d.*f.member;
    e["min"] = f.range.has_min ? py::object(py::float_(f.range.min)) : py::object(py::none());
    e["max"] = f.range.has_max ? py::object(py::float_(f.range.max)) : py::object(py::none());
    e["min_open"] = f.range.min_open;
    e["max_open"] = f.range.max_open;
    e["help"] = std::string(f.help);
    out.append(e);
  });
  return out;
}

// ---------------------------------------------------------------- predict's frequency_Hz, amplitude_g

// predict(case, frequency_Hz=, amplitude_g=) sets the sine of the case's [vibration] (a "sine"
// or "sine_on_random"): refuses any other vibration, naming the case.
void require_sine(const io::Case& c) {
  if (!c.vibration)
    throw io::InputError(c.path + ": predict's frequency_Hz and amplitude_g set the sine of a [vibration] table; the case has none");
  const auto type = c.vibration->type;
  if (type != rectification::VibrationKind::sine && type != rectification::VibrationKind::sine_on_random)
    throw io::InputError(c.path + ": predict's frequency_Hz and amplitude_g set a \"sine\" or \"sine_on_random\" [vibration]'s sine, not a \"" +
                         rectification::to_string(type) + "\"");
}

// A number as the case reader's messages write it (printf's %g).
std::string g_text(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// Sets `s`'s frequency (Hz, finite, as the case file's frequency_Hz: >= 0 for a sine, > 0 for
// a sine on random) and amplitude (g, the peak along the case's direction: its amplitude vector
// scaled to this length, phases kept; 0 to 1000 g as the case file's). `index`: the element of
// predict's arrays, named in messages ("frequency_Hz[3]").
void set_sine(const io::Case& c, vibration::SineVibration& s, std::optional<double> frequency_Hz, std::optional<double> amplitude_g,
              std::optional<std::size_t> index) {
  const auto at = [&] {  // built for a message only
    std::string text;
    if (index) text.append("[").append(std::to_string(*index)).append("]");
    return text;
  };
  if (frequency_Hz) {
    const bool sine = c.vibration->type == rectification::VibrationKind::sine;
    if (!(std::isfinite(*frequency_Hz) && (*frequency_Hz > 0 || (sine && *frequency_Hz == 0))))
      throw io::InputError(c.path + ": predict(): frequency_Hz" + at() + " must be a finite number " + (sine ? ">= 0" : "> 0") +
                           " Hz, got " + g_text(*frequency_Hz));
    s.frequency_Hz = *frequency_Hz;
  }
  if (amplitude_g) {
    if (!(*amplitude_g >= 0 && *amplitude_g <= io::kAmplitudeRange.max))
      throw io::InputError(c.path + ": predict(): amplitude_g" + at() + " must be between 0 and " + g_text(io::kAmplitudeRange.max) +
                           " g (the case files' limit), got " + g_text(*amplitude_g));
    const double norm = s.amplitude_g.norm();
    if (!(norm > 0))
      throw io::InputError(c.path + ": predict(): amplitude_g scales the case's [vibration] amplitude_g, which is zero: no direction to scale");
    s.amplitude_g *= *amplitude_g / norm;
  }
}

// The case with its sine set (the scalar call): its content records the values too, so that
// to_dict() is the JSON of a case file holding them.
io::Case with_sine(io::Case c, std::optional<double> frequency_Hz, std::optional<double> amplitude_g) {
  if (!frequency_Hz && !amplitude_g) return c;
  require_sine(c);
  vibration::SineVibration& s = c.vibration->sine;
  set_sine(c, s, frequency_Hz, amplitude_g, std::nullopt);
  if (frequency_Hz) c.content["vibration"]["frequency_Hz"] = s.frequency_Hz;
  if (amplitude_g) c.content["vibration"]["amplitude_g"] = {s.amplitude_g[0], s.amplitude_g[1], s.amplitude_g[2]};
  return c;
}

// predict over arrays: element i is io::predict of the case with frequency_Hz[i] and
// amplitude_g[i] set by set_sine, as the scalar call sets them (not given: the case's own), so
// each element equals the scalar call's number exactly. The arrays given have one length (the
// package broadcasts them). Runs with the GIL released; Ctrl-C stops it between elements.
py::dict predict_arrays(const io::Case& c, bool frequency_dependent, const std::optional<std::vector<double>>& frequency_Hz,
                        const std::optional<std::vector<double>>& amplitude_g) {
  require_sine(c);
  if (!frequency_Hz && !amplitude_g) throw std::invalid_argument("predict(): neither frequency_Hz nor amplitude_g given");
  const std::size_t n = frequency_Hz ? frequency_Hz->size() : amplitude_g->size();
  if (frequency_Hz && amplitude_g && amplitude_g->size() != n)
    throw std::invalid_argument("predict(): frequency_Hz and amplitude_g differ in length");
  struct Columns {
    std::vector<double> f_Hz, a_g, total_g, printed_g, omitted_g, at_frequency_g;
    std::array<std::vector<double>, rectification::kNumTerms> terms, at_frequency_terms;
  } out;
  interruptible([&] {
    io::Case w = c;
    for (std::size_t i = 0; i < n; ++i) {
      core::throw_if_cancelled();
      w.vibration->sine = c.vibration->sine;
      set_sine(c, w.vibration->sine, frequency_Hz ? std::optional((*frequency_Hz)[i]) : std::nullopt,
               amplitude_g ? std::optional((*amplitude_g)[i]) : std::nullopt, i);
      const io::PredictStudy s = io::predict(w, frequency_dependent);
      out.f_Hz.push_back(w.vibration->sine.frequency_Hz);
      out.a_g.push_back(amplitude_g ? (*amplitude_g)[i] : w.vibration->sine.amplitude_g.norm());
      out.total_g.push_back(s.terms.total_g());
      out.printed_g.push_back(s.printed_g.value_or(std::nan("")));
      out.omitted_g.push_back(s.terms.omitted_by_paper_g());
      for (std::size_t t = 0; t < out.terms.size(); ++t) out.terms[t].push_back(s.terms.g[t]);
      if (s.at_frequency) {
        out.at_frequency_g.push_back(s.at_frequency->total_g());
        for (std::size_t t = 0; t < out.terms.size(); ++t) out.at_frequency_terms[t].push_back(s.at_frequency->terms.g[t]);
      }
    }
    return 0;
  });
  const auto terms = [](const std::array<std::vector<double>, rectification::kNumTerms>& a) {
    py::dict d;
    for (int t = 0; t < rectification::kNumTerms; ++t) d[py::str(std::string(rectification::term_name(t)))] = array(a[static_cast<std::size_t>(t)]);
    return d;
  };
  py::dict d;
  d["frequency_Hz"] = array(out.f_Hz);
  d["amplitude_g"] = array(out.a_g);
  d["total_g"] = array(out.total_g);
  d["terms"] = terms(out.terms);
  d["printed_g"] = array(out.printed_g);
  d["omitted_by_paper_g"] = array(out.omitted_g);
  d["frequency_dependent_g"] = frequency_dependent ? py::object(array(out.at_frequency_g)) : py::object(py::none());
  d["frequency_terms"] = frequency_dependent ? py::object(terms(out.at_frequency_terms)) : py::object(py::none());
  return d;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "vrelab: the virtual shaker laboratory's library (C++), bound with pybind11. See help(vrelab).";
  m.attr("__version__") = std::string(kProgramVersion);
  m.attr("git_describe") = std::string(kGitDescribe);

  static py::exception<io::InputError> input_error(m, "InputError", PyExc_ValueError);
  input_error.doc() =
      "Bad input (a case, a folder, a setting): the CLI's exit code 2, with the same message, naming the file, the "
      "line and the key.";
  static py::exception<plant::SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
  input_error.attr("__module__") = "vrelab";
  solver_error.attr("__module__") = "vrelab";
  solver_error.doc() = "The ODE solver (SUNDIALS CVODE) failed: the message names the call and the simulated time t_s.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const io::InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const plant::SolverError& e) {
      py::object err = py::reinterpret_borrow<py::object>(solver_error.ptr())(py::str(e.what()));
      err.attr("call") = e.call;
      err.attr("flag") = e.flag;
      err.attr("t_s") = e.t_s;
      PyErr_SetObject(solver_error.ptr(), err.ptr());
    } catch (const std::invalid_argument& e) {  // parameters the physics rejects: exit code 2 in the CLI too
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const std::filesystem::filesystem_error& e) {  // a path the system refuses: the caller's, as in the CLI
      PyErr_SetString(input_error.ptr(), (io::path_for_message(e.path1().string()) + ": " + e.code().message()).c_str());
    }
  });
  // The size limits of lab data (io/formats/ranges.hpp): diagnose_data checks its columns against them before
  // writing them out.
  py::dict limits;
  limits["static_readings"] = io::kMaxStaticReadings;
  limits["runs"] = io::kMaxRuns;
  limits["psd_rows"] = io::kMaxPsdRows;
  m.attr("limits") = limits;

  // ------------------------------------------------------------ Case
  py::class_<io::Case>(m, "Case",
                       "A case: the inputs of every study (docs/case-files.md). Build one with vrelab.load_case(path), "
                       "vrelab.Case.from_file(path) or vrelab.Case.from_dict(d).")
      .def_static("from_file", &io::read_case, py::arg("path"),
                  "Reads a case file (TOML). Bad input raises vrelab.InputError naming the file, the line and the key.")
      .def_static(
          "from_dict", [](const py::dict& d, const std::string& name) { return case_from_toml(case_toml(d, "Case.from_dict(d)"), name); },
          py::arg("d"), py::arg("name") = "<dict>",
          "Builds a case from a dict of tables ({'coefficients': {'K1': 1.25, ...}, 'vibration': {...}}): the dict is "
          "written as TOML (vrelab.case_toml(d)) and read by the same reader as a file, so the checks and messages are "
          "the file's; messages name `name` and the line of the TOML text.")
      .def_static("from_toml", &case_from_toml, py::arg("text"), py::arg("name") = "<toml>",
                  "Builds a case from TOML text (the case file format).")
      .def_readonly("path", &io::Case::path, "The case file (or the name given to a dict).")
      .def_readwrite("seed", &io::Case::seed, "[run] seed: the random draws of the static test, readout noise, campaign.")
      .def_readonly("g_m_per_s2", &io::Case::g_m_per_s2, "The site's gravity, m/s^2 (1 g).")
      .def_readonly("output_unit", &io::Case::output_unit, "[instrument] output_unit (K1 in output units per g).")
      .def_property_readonly(
          "coefficients", [](const io::Case& c) -> py::object { return c.coefficients ? py::object(coefficient_dict(*c.coefficients)) : py::none(); },
          "[coefficients] of model (1) by name (K1 in output units/g, k0 in g, k2 in 1/g, ...), or None.")
      .def_property_readonly("content", [](const io::Case& c) { return to_py(c.content); },
                             "The case as read (the parsed TOML as a dict), as recorded in every result.")
      .def("__repr__", [](const io::Case& c) { return "<vrelab.Case " + c.path + ">"; });

  m.def(
      "case_toml", [](const py::dict& d) { return case_toml(d, "case_toml(d)"); }, py::arg("d"),
      "The TOML text a case dict is read from (Case.from_dict). A dict that contains itself or nests deeper than 32 "
      "levels raises vrelab.InputError naming where.");

  // ------------------------------------------------------------ identify
  py::class_<IdentifyResult>(m, "IdentifyResult", "The static test on the dividing head and the three identifications.")
      .def_property_readonly("methods", [](const IdentifyResult& r) {
        std::vector<std::string> n;
        for (const auto& x : r.s.report.methods) n.push_back(x.name);
        return n;
      }, "The identification methods: paper_printed, paper_corrected, least_squares.")
      .def("estimate", [](const IdentifyResult& r, const std::string& method) { return coefficient_dict(method_named(r, method).estimate.value); },
           py::arg("method") = "least_squares", "The identified coefficients by name (coefficient units: K1 output/g, k0 g, k2 1/g, ...).")
      .def("sigma", [](const IdentifyResult& r, const std::string& method) { return coefficient_dict_of(method_named(r, method).first_order.sigma); },
           py::arg("method") = "least_squares", "First-order standard uncertainty of each coefficient (coefficient units).")
      .def_property_readonly("truth", [](const IdentifyResult& r) { return coefficient_dict(*r.c.coefficients); }, "The case's true coefficients.")
      .def_property_readonly("rank", [](const IdentifyResult& r) { return r.s.report.identifiability.rank; }, "Rank of the least-squares design.")
      .def_property_readonly("parameters", [](const IdentifyResult& r) { return r.s.report.identifiability.parameters; }, "Free coefficients.")
      .def_property_readonly("condition_number", [](const IdentifyResult& r) { return r.s.report.identifiability.condition_number; },
                             "Condition number of the column-scaled design (inf when rank-deficient).")
      .def_property_readonly("readings", [](const IdentifyResult& r) { return r.s.report.readings.size(); }, "Number of static readings.")
      .def_property_readonly("notes", [](const IdentifyResult& r) { return r.s.report.notes; })
      .def("report", [](const IdentifyResult& r) { return io::identify_report(r.c, r.s); }, "The text `vrelab identify` prints.")
      .def("to_dict", [](const IdentifyResult& r) { return to_py(io::identify_json(r.c, r.s)); }, "`vrelab identify --json` as a dict.");

  m.def(
      "identify",
      [](io::Case c, int monte_carlo, std::optional<std::uint64_t> seed) {
        if (seed) c.seed = *seed;
        io::IdentifyStudy s = interruptible([&] { return io::identify(c, monte_carlo); });
        return IdentifyResult{std::move(c), std::move(s)};
      },
      py::arg("case"), py::arg("monte_carlo") = 0, py::arg("seed") = py::none(),
      "identify(case, monte_carlo=0, seed=None) -> IdentifyResult\n\n"
      "The virtual static test on a dividing head ([coefficients], [dividing_head]): model (1)'s 13 coefficients "
      "identified three ways with first-order (and, with monte_carlo=N trials, Monte Carlo) standard uncertainty. "
      "Same as `vrelab identify CASE [--monte-carlo N] [--seed S]`.");

  // ------------------------------------------------------------ predict
  py::class_<PredictResult>(m, "PredictResult", "Eq. (3) corrected for the case's vibration (and through the dynamics).")
      .def_property_readonly("total_g", [](const PredictResult& r) { return r.s.terms.total_g(); }, "The vibration error, g.")
      .def_property_readonly("terms", [](const PredictResult& r) { return terms_dict(r.s.terms); }, "Each term's contribution, g.")
      .def_property_readonly("omitted_by_paper_g", [](const PredictResult& r) { return r.s.terms.omitted_by_paper_g(); },
                             "The k_PP and k_OO terms the printed eq. (3) omits, g.")
      .def_property_readonly("printed_g", [](const PredictResult& r) { return r.s.printed_g; }, "Eq. (3) as printed (sine), g, or None.")
      .def_property_readonly("description", [](const PredictResult& r) { return r.s.description; }, "The vibration in words.")
      .def_property_readonly("frequency_dependent_g", [](const PredictResult& r) -> std::optional<double> {
        if (!r.s.at_frequency) return std::nullopt;
        return r.s.at_frequency->total_g();
      }, "With frequency_dependent=True: eq. (3) through the plant's dynamics at [vibration] frequency_Hz, g; else None.")
      .def_property_readonly("frequency_terms", [](const PredictResult& r) -> py::object {
        if (!r.s.at_frequency) return py::none();
        return terms_dict(r.s.at_frequency->terms);
      }, "With frequency_dependent=True: each term at the frequency, g.")
      .def_property_readonly("second_order_g", [](const PredictResult& r) -> std::optional<double> {
        if (!r.s.at_frequency) return std::nullopt;
        return r.s.at_frequency->second_order_g;
      }, "With frequency_dependent=True: the pickoff nonlinearity beyond first order (included in frequency_dependent_g), g; else None.")
      .def_property_readonly("second_order_error_g", [](const PredictResult& r) -> std::optional<double> {
        if (!r.s.at_frequency) return std::nullopt;
        return r.s.at_frequency->second_order_error_g;
      }, "With frequency_dependent=True: second_order_g's own uncertainty (random motion; 0 where exact), g; else None.")
      .def("report", [](const PredictResult& r) { return io::predict_report(r.c, r.s); }, "The text `vrelab predict` prints.")
      .def("to_dict", [](const PredictResult& r) { return to_py(io::predict_json(r.c, r.s)); }, "`vrelab predict --json` as a dict.");

  m.def(
      "predict",
      [](const io::Case& c, bool frequency_dependent, std::optional<double> frequency_Hz, std::optional<double> amplitude_g) {
        io::Case w = with_sine(c, frequency_Hz, amplitude_g);
        io::PredictStudy s = io::predict(w, frequency_dependent);
        return PredictResult{std::move(w), std::move(s)};
      },
      py::arg("case"), py::arg("frequency_dependent") = false, py::kw_only(), py::arg("frequency_Hz") = py::none(),
      py::arg("amplitude_g") = py::none(),
      "predict(case, frequency_dependent=False, *, frequency_Hz=None, amplitude_g=None) -> PredictResult\n\n"
      "The vibration error implied by model (1): eq. (3) corrected, per term and total (g), for the case's "
      "[vibration] (sine: amplitude g peak, frequency Hz; random: rms g or PSD g^2/Hz; sine on random); with "
      "frequency_dependent=True also through the plant's dynamics at frequency_Hz. Same as `vrelab predict CASE "
      "[--frequency-dependent]`. frequency_Hz (Hz) and amplitude_g (g peak along the case's direction: its "
      "amplitude_g vector scaled to this length) set a \"sine\" or \"sine_on_random\" [vibration]'s sine, as a case "
      "file holding them would.");
  m.def("_predict_arrays", &predict_arrays, py::arg("case"), py::arg("frequency_dependent"), py::arg("frequency_Hz"),
        py::arg("amplitude_g"));
  m.def(
      "predict_total_g", [](const io::Case& c) { return io::predict_terms(c).total_g(); }, py::arg("case"),
      "Eq. (3) corrected for the case's vibration, total only (g): the library call io::predict_terms, without a "
      "result object.");

  // ------------------------------------------------------------ shake
  py::class_<ShakeResult>(m, "ShakeResult", "One run of the ODE accelerometer on the virtual shaker.")
      .def_property_readonly("measured_g", [](const ShakeResult& r) { return r.s.result.measured_g; },
                             "The measured vibration error <U/K1 under vibration> - U/K1 at rest, g.")
      .def_property_readonly("sigma_g", [](const ShakeResult& r) { return r.s.result.sigma_g; }, "Its standard uncertainty (batch means), g.")
      .def_property_readonly("predicted_g", [](const ShakeResult& r) { return r.s.predicted_g; }, "Eq. (3) corrected with the truth's coefficients, g.")
      .def_property_readonly("predicted_frequency_dependent_g", [](const ShakeResult& r) { return r.s.frequency_dependent_g; },
                             "Eq. (3) through the plant's dynamics (predict --frequency-dependent), g; None for a sweep, shaker "
                             "imperfections or a Gaussian given by its rms.")
      .def_property_readonly("integral_slope_g", [](const ShakeResult& r) { return r.s.result.integral_slope_g; },
                             "The paper's estimate: slope of the running integral, g.")
      .def_property_readonly("method", [](const ShakeResult& r) { return r.s.result.method; }, "\"continuous integral\" or \"sampled record\".")
      .def_property_readonly("sample_rate_Hz", [](const ShakeResult& r) { return r.s.result.sample_rate_Hz; }, "Sampled record's rate, Hz.")
      .def_property_readonly("samples", [](const ShakeResult& r) { return r.s.result.samples; }, "Samples in the sampled record.")
      .def_property_readonly("baseline_g", [](const ShakeResult& r) { return r.s.result.baseline_g; }, "U/K1 at rest, g.")
      .def_property_readonly("settle_s", [](const ShakeResult& r) { return r.s.result.settle_s; }, "Settling skipped before measuring, s.")
      .def_property_readonly("slowest_time_constant_s", [](const ShakeResult& r) { return r.s.result.slowest_time_constant_s; }, "The plant's slowest time constant, s (sets the settling).")
      .def_property_readonly("periods", [](const ShakeResult& r) { return r.s.result.periods; }, "Periods measured (periodic runs).")
      .def_property_readonly("steps", [](const ShakeResult& r) { return r.s.result.steps; }, "Solver steps.")
      .def_property_readonly("rhs_evaluations", [](const ShakeResult& r) { return r.s.result.rhs_evaluations; }, "Right-hand-side evaluations of the ODE.")
      .def_property_readonly("wall_s", [](const ShakeResult& r) { return r.s.wall_s; }, "The solver's wall time in the library call, s.")
      .def_property_readonly("series", [](const ShakeResult& r) -> py::object {
        if (!r.series) return py::none();
        py::dict d;
        d["time_s"] = array(r.series->t_s);
        d["input_IA_g"] = array(r.series->in_IA);
        d["input_PA_g"] = array(r.series->in_PA);
        d["input_OA_g"] = array(r.series->in_OA);
        d[py::str("output_" + r.c.output_unit)] = array(r.series->out);
        return py::object(std::move(d));
      }, "With series=True: the sampled record as NumPy arrays (time s: at rest for t < 0, vibration from t = 0; the "
         "table's dynamic input g per axis; the output in output units), the columns of `vrelab shake --series`.")
      .def("report", [](const ShakeResult& r) { return io::shake_report(r.c, r.s); }, "The text `vrelab shake` prints.")
      .def("to_dict", [](const ShakeResult& r) { return to_py(io::shake_json(r.c, r.s)); }, "`vrelab shake --json` as a dict.");

  m.def(
      "shake",
      [](io::Case c, bool series, std::optional<std::uint64_t> seed) {
        if (seed) c.seed = *seed, c.shake.readout.seed = *seed;
        ShakeResult r{std::move(c), {}, {}};
        if (!series) {
          r.s = interruptible([&] { return io::shake(r.c, std::string()); });
          return r;
        }
        r.series = std::make_shared<Series>();
        Series& out = *r.series;
        const rectification::SampleSink sink = [&out](double t, const Vec3& in, double u) {
          out.t_s.push_back(t), out.in_IA.push_back(in[0]), out.in_PA.push_back(in[1]), out.in_OA.push_back(in[2]);
          out.out.push_back(u);
        };
        r.s = interruptible([&] { return io::shake(r.c, sink); });
        return r;
      },
      py::arg("case"), py::arg("series") = false, py::arg("seed") = py::none(),
      "shake(case, series=False, seed=None) -> ShakeResult\n\n"
      "One run on the virtual shaker: the ODE accelerometer (SUNDIALS CVODE) under the case's [vibration] (sine, "
      "random PSD, sine on random, swept sine) in the static orientation [orientation] a_g (g). Gives the measured "
      "vibration error and its sigma (g) beside eq. (3). series=True also records the sampled output (like `vrelab "
      "shake --series`: the run is then a sampled record) as NumPy arrays in .series. Ctrl-C interrupts it. "
      "Releases the GIL. Same as `vrelab shake CASE [--seed S]`.");

  // ------------------------------------------------------------ sweep
  py::class_<SweepResult>(m, "SweepRun", "A sweep's counts (the rows are in the CSV file at .path).")
      .def_property_readonly("conditions", [](const SweepResult& r) { return r.s.conditions; }, "Conditions of the grid.")
      .def_property_readonly("ran", [](const SweepResult& r) { return r.s.ran; }, "Conditions run now (not resumed from the file).")
      .def_property_readonly("written", [](const SweepResult& r) { return r.s.written; }, "Rows this call wrote (failed conditions write none).")
      .def_property_readonly("failures", [](const SweepResult& r) { return r.s.failures; }, "Failed conditions, with the solver's message.")
      .def_property_readonly("wall_s", [](const SweepResult& r) { return r.s.wall_s; }, "s.")
      .def_readonly("path", &SweepResult::path)
      .def("report", [](const SweepResult& r) { return io::sweep_report(r.s, r.path); });
  m.def(
      "_sweep",
      [](const io::Case& c, const std::string& out_path, bool restart, int threads, bool progress) {
        io::SweepStudy s = interruptible([&] {
          std::ostringstream announce;
          return io::sweep(c, out_path, restart, threads, progress, announce);
        });
        return SweepResult{std::move(s), out_path};
      },
      py::arg("case"), py::arg("out_path"), py::arg("restart") = false, py::arg("threads") = -1, py::arg("progress") = false);

  // ------------------------------------------------------------ frequency
  py::class_<FrequencyResult>(m, "FrequencyResult", "The frequency study: e(f)/e_eq3 per mechanism, ODE points.")
      .def_property_readonly("wall_s", [](const FrequencyResult& r) { return r.s.wall_s; }, "s.")
      .def_property_readonly("mechanisms", [](const FrequencyResult& r) {
        std::vector<std::string> n;
        for (const auto& cv : r.s.curves) n.push_back(cv.name);
        return n;
      })
      .def("write", [](const FrequencyResult& r, const std::string& dir, bool figures) {
        io::write_frequency_data(r.c, r.s, dir);
        return figures ? io::run_plot_script("frequency.py", dir) : std::string("figures=False was given");
      }, py::arg("dir"), py::arg("figures") = true,
           "frequency.csv, ode_points.csv, summary.md, summary.json in dir, and with figures=True frequency.png/svg "
           "(as `vrelab frequency CASE --out DIR`). Returns \"\" when the figures were drawn, else why not.")
      .def("report", [](const FrequencyResult& r) { return io::frequency_report(r.c, r.s); })
      .def("to_dict", [](const FrequencyResult& r) { return to_py(io::frequency_json(r.c, r.s)); }, "summary.json of `vrelab frequency` as a dict.");
  m.def(
      "frequency",
      [](const io::Case& c) {
        return FrequencyResult{c, interruptible([&] { return io::frequency(c); })};
      },
      py::arg("case"),
      "frequency(case) -> FrequencyResult\n\nEq. (3) through the plant's dynamics against the ODE, per term and place, "
      "over the case's [frequency_study] grid (Hz). Same as `vrelab frequency CASE --out DIR` without the figures.");

  // ------------------------------------------------------------ campaign, diagnose
  py::class_<io::CampaignWritten>(m, "CampaignWritten", "A virtual campaign written in the lab data format.")
      .def_property_readonly("out_dir", [](const io::CampaignWritten& w) { return w.request.out_dir; })
      .def_property_readonly("key_path", [](const io::CampaignWritten& w) { return w.request.key_path; }, "The answer key (JSON).")
      .def_property_readonly("seed", [](const io::CampaignWritten& w) { return w.request.seed; })
      .def_readonly("statics", &io::CampaignWritten::statics)
      .def_readonly("runs", &io::CampaignWritten::runs)
      .def_readonly("raw_records", &io::CampaignWritten::raw_records)
      .def_readonly("wall_s", &io::CampaignWritten::wall_s, "Simulation and writing, s.")
      .def("report", &io::CampaignWritten::FullReport)
      .def("to_dict", [](const io::CampaignWritten& w) {
        py::dict d;
        d["out_dir"] = w.request.out_dir, d["key_path"] = w.request.key_path, d["seed"] = w.request.seed;
        d["statics"] = w.statics, d["runs"] = w.runs, d["raw_records"] = w.raw_records, d["wall_s"] = w.wall_s;
        return d;
      });
  m.def(
      "_campaign",
      [](const std::string& case_path, const std::string& out_dir, const std::string& key_path, std::optional<std::uint64_t> seed,
         const std::string& raw_format) {
        if (raw_format != "csv" && raw_format != "hdf5")
          throw io::InputError("campaign: raw_format must be 'csv' or 'hdf5', got '" + raw_format + "'");
        return interruptible([&] {
          return io::write_virtual_campaign(
              {case_path, out_dir, key_path, seed, false, raw_format == "hdf5" ? io::RawFormat::hdf5 : io::RawFormat::csv});
        });
      },
      py::arg("case_path"), py::arg("out_dir"), py::arg("key_path") = "", py::arg("seed") = py::none(),
      py::arg("raw_format") = "csv");

  py::class_<io::FolderDiagnosis>(m, "Diagnosis", "The diagnosis of a campaign folder: where the gap lies and what explains it.")
      .def_readwrite("dir", &io::FolderDiagnosis::dir, "The campaign folder (diagnose_data: the name given).")
      .def_readonly("settings_from", &io::FolderDiagnosis::settings_from)
      .def_readonly("wall_s", &io::FolderDiagnosis::wall_s, "The diagnosis alone, s.")
      .def_property_readonly("verdict", [](const io::FolderDiagnosis& f) { return validation::verdict_text(f.diagnosis); })
      .def_property_readonly("chosen", [](const io::FolderDiagnosis& f) { return validation::to_string(f.diagnosis.chosen); }, "The best effect (or \"A + B\").")
      .def_property_readonly("explained", [](const io::FolderDiagnosis& f) { return f.diagnosis.explained(); })
      .def_property_readonly("gap_significant", [](const io::FolderDiagnosis& f) { return f.diagnosis.gap_significant; })
      .def_property_readonly("significant_runs", [](const io::FolderDiagnosis& f) { return f.diagnosis.significant_runs; }, "Runs whose gap exceeds significance_sigma.")
      .def_property_readonly("runs", [](const io::FolderDiagnosis& f) { return f.diagnosis.runs.size(); })
      .def_property_readonly("max_abs_z", [](const io::FolderDiagnosis& f) { return f.diagnosis.max_abs_z; }, "Largest |z| over the runs: the gap the static test's coefficient errors cannot take up, over the run's sigma (1).")
      .def_property_readonly("rms_before_g", [](const io::FolderDiagnosis& f) { return f.diagnosis.rms_before_g; }, "Held-out rms gap, g.")
      .def_property_readonly("rms_after_g", [](const io::FolderDiagnosis& f) { return f.diagnosis.rms_after_g; }, "With the chosen effect, g.")
      .def_property_readonly("rms_floor_g", [](const io::FolderDiagnosis& f) { return f.diagnosis.rms_floor_g; },
                             "The held-out rms with no gap at all (noise, simulation accuracy, the coefficients' extrapolation), g: no effect removes it.")
      .def_property_readonly("shrinkage_above_floor", [](const io::FolderDiagnosis& f) { return f.diagnosis.shrinkage_above_floor(); },
                             "1 - (after above the floor) / (before above the floor), in quadrature (1); NaN when the gap before is within the floor.")
      .def_property_readonly("identified", [](const io::FolderDiagnosis& f) { return coefficient_dict(f.diagnosis.identified); }, "Model (1)'s coefficients from the static readings (K1 output units/g, k0 g, k2 1/g, ...).")
      .def("report", &io::FolderDiagnosis::FullReport, "The text `vrelab diagnose` prints (without the program's name).")
      .def("brief_report", &io::FolderDiagnosis::BriefReport)
      .def("to_dict", [](const io::FolderDiagnosis& f) { return to_py(io::to_json(f)); }, "`vrelab diagnose --json` as a dict.");
  // Every DiagnoseSettings field a keyword (its description: name, type, default, range, help).
  static const std::string diagnose_doc =
      "diagnose(dir, threads=0, **settings) -> Diagnosis\n\n"
      "The sim-to-real gap of a campaign folder in the lab data format (docs/data-format.md): static readings "
      "(output units) and shaker runs (measured error and sigma, g). Settings given here (keywords, None: not "
      "given) win over the manifest's [diagnose] table; `vrelab diagnose DIR` takes the same as flags "
      "(--significance-sigma for significance_sigma; --no-NAME for a flag). threads: the effects' fits on this "
      "many threads (0: all cores); the result does not depend on it. Releases the GIL.\n\n" +
      diagnose_keywords_doc();
  m.def(
      "diagnose",
      [](const std::string& dir, int threads, const py::kwargs& kw) {
        const io::DiagnoseOverrides o = diagnose_overrides("diagnose", kw);
        return interruptible([&] { return io::diagnose_folder(dir, o, threads); });
      },
      py::arg("dir"), py::arg("threads") = 0, diagnose_doc.c_str());
  m.def(
      "check_campaign",
      [](const std::string& dir, const py::kwargs& kw) {
        const io::DiagnoseOverrides o = diagnose_overrides("check_campaign", kw);
        const io::FolderDiagnosis f = interruptible([&] { return io::read_folder(dir, o); });
        nlohmann::json j = io::to_json(f.settings);
        j["from"] = f.settings_from;
        return to_py(nlohmann::json{{"settings", j}, {"runs", f.campaign.runs.size()}, {"skipped", f.campaign.skipped}});
      },
      py::arg("dir"),
      "check_campaign(dir, **settings) -> dict\n\n"
      "`vrelab diagnose DIR --check`: the folder read and checked, the settings (keywords as for diagnose) "
      "resolved over the manifest's [diagnose] and validated; no diagnosis. Returns {'settings': the settings "
      "used as in diagnose's to_dict(), with 'from'; 'runs': the usable runs; 'skipped': why runs were skipped}.");
  m.def("diagnose_settings", &diagnose_settings_description,
        "The diagnosis' settings, one dict a field: name, type, unit, default, min, max, min_open, max_open, help.");

  // ------------------------------------------------------------ reproduce
  py::class_<ReproduceResult>(m, "ReproduceResult", "The paper's experiment end to end, written to a folder.")
      .def_property_readonly("out_dir", [](const ReproduceResult& r) { return r.run.out_dir; })
      .def_property_readonly("wall_s", [](const ReproduceResult& r) { return r.run.wall_s; }, "s.")
      .def_property_readonly("figures_missing", [](const ReproduceResult& r) { return r.run.figures_missing; }, "\"\" when the figures were drawn.")
      .def_property_readonly("report_html", [](const ReproduceResult& r) { return r.run.out_dir + "/report.html"; })
      .def_property_readonly("identified", [](const ReproduceResult& r) { return coefficient_dict(r.run.result.identified); },
                             "Least-squares coefficients of the static test.")
      .def("report", [](const ReproduceResult& r) { return io::reproduce_brief_report(r.run.result); }, "The summary `vrelab reproduce` prints.")
      .def("to_dict", [](const ReproduceResult& r) { return to_py(io::reproduce_summary_json(r.c, r.run.settings, r.run.result, r.run.wall_s)); },
           "summary.json of the output folder as a dict.")
      .def("confirmation", [](const ReproduceResult& r) { return to_py(io::reproduce_confirmation_json(r.c, r.run.settings, r.run.result)); },
           "confirmation.json: the confirmation run's numbers.");
  m.def(
      "reproduce",
      [](const io::Case& c, const std::string& out_dir, int threads, bool plots) {
        return ReproduceResult{c, interruptible([&] { return io::reproduce_to_folder(c, out_dir, threads, plots); })};
      },
      py::arg("case"), py::arg("out_dir"), py::arg("threads") = -1, py::arg("plots") = true,
      "reproduce(case, out_dir, threads=-1, plots=True) -> ReproduceResult\n\n"
      "The paper's experiment end to end (static test, identification, confirmation run, shaker runs against eq. "
      "(3), the departure in frequency, the invisible k_PP/k_OO shift): report.html, report.md, figures and CSV/JSON "
      "in out_dir. threads=-1: the case's [reproduce] threads (0: all cores). Same as `vrelab reproduce CASE --out "
      "DIR`. Releases the GIL.");
}
