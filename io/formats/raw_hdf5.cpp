#include "io/formats/raw_hdf5.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>
#include <hdf5.h>

#include "io/formats/error.hpp"
#include "io/formats/paths.hpp"
#include "io/formats/ranges.hpp"

namespace vrelab::io {

// Named rather than anonymous: Hdf5SeriesWriter::State, a class with linkage, holds them (GCC's
// -Wsubobject-linkage when this file is compiled inside a unity build).
namespace raw_hdf5_internal {

// An HDF5 identifier closed when it leaves scope.
class Id {
 public:
  Id() = default;
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  Id(Id&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Id& operator=(Id&& o) noexcept {
    if (this != &o) reset(), id_ = o.id_, close_ = o.close_, o.id_ = -1;
    return *this;
  }
  ~Id() { reset(); }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = -1;
  }
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// One channel of a record: a 1-D dataset of numbers (floating point or integer, read as double).
struct Channel {
  std::string name;
  Id dataset, space;
  hsize_t length = 0;
  std::vector<double> block;
};

}  // namespace raw_hdf5_internal

namespace {

using raw_hdf5_internal::Channel;
using raw_hdf5_internal::Id;
namespace fs = std::filesystem;

// HDF5 prints its error stack on stderr by default; vrelab reports errors itself. The
// setting is per thread (the library is built thread-safe), so every entry point sets it.
void silence_hdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

// HDF5's own words for the last failure: the outermost description and, when different, the
// innermost one (e.g. "unable to open file: file signature not found"); "" when none.
std::string hdf5_reason() {
  struct Walk {
    std::string outer, inner;
  } w;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned n, const H5E_error2_t* e, void* data) -> herr_t {
        auto* walk = static_cast<Walk*>(data);
        const std::string d = e->desc ? e->desc : "";
        if (n == 0) walk->outer = d;
        walk->inner = d;
        return 0;
      },
      &w);
  if (w.outer.empty()) return "";
  return w.inner.empty() || w.inner == w.outer ? w.outer : w.outer + ": " + w.inner;
}

std::string with_reason(const std::string& message) {
  const std::string r = hdf5_reason();
  return r.empty() ? message : fmt::format("{} (HDF5: {})", message, r);
}

// The names of the links in the file's root group, in name order.
std::vector<std::string> root_names(hid_t file) {
  std::vector<std::string> names;
  H5Literate(
      file, H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->emplace_back(name);
        return 0;
      },
      &names);
  return names;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "nothing" : s;
}

// A string attribute of an object (fixed or variable length, as h5py writes it); nullopt
// when absent or not a string.
std::optional<std::string> string_attribute(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return std::nullopt;
  Id a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return std::nullopt;
  Id type(H5Aget_type(a.get()), H5Tclose);
  if (!type.ok() || H5Tget_class(type.get()) != H5T_STRING) return std::nullopt;
  Id space(H5Aget_space(a.get()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) return std::nullopt;
  if (H5Tis_variable_str(type.get()) > 0) {
    Id mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem.get(), H5T_VARIABLE);
    H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
    char* text = nullptr;
    if (H5Aread(a.get(), mem.get(), &text) < 0 || !text) return std::nullopt;
    std::string s(text);
    H5free_memory(text);
    return s;
  }
  const std::size_t size = H5Tget_size(type.get());
  std::string s(size, '\0');
  Id mem(H5Tcopy(type.get()), H5Tclose);
  if (H5Aread(a.get(), mem.get(), s.data()) < 0) return std::nullopt;
  s.resize(std::strlen(s.c_str()));  // fixed-length strings are NUL- or space-padded
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// The place of a dataset (or one of its elements) in a file.
FormatLocation dataset(const std::string& path, const std::string& name, long long element = -1) {
  return {.file = path, .key = name, .kind = KeyKind::hdf5_dataset, .element = element};
}

Channel open_channel(hid_t file, const std::string& path, const std::string& name, const std::string& unit) {
  Channel c;
  c.name = name;
  c.dataset = Id(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!c.dataset.ok())
    throw FormatError(dataset(path, name), with_reason("cannot be opened (a group or a link, not a dataset?)"));
  c.space = Id(H5Dget_space(c.dataset.get()), H5Sclose);
  if (!c.space.ok() || H5Sget_simple_extent_ndims(c.space.get()) != 1)
    throw FormatError(dataset(path, name), fmt::format("must be one-dimensional (one sample per element), has {} dimensions",
                                                       c.space.ok() ? H5Sget_simple_extent_ndims(c.space.get()) : -1));
  H5Sget_simple_extent_dims(c.space.get(), &c.length, nullptr);
  Id type(H5Dget_type(c.dataset.get()), H5Tclose);
  const H5T_class_t cls = type.ok() ? H5Tget_class(type.get()) : H5T_NO_CLASS;
  if (cls != H5T_FLOAT && cls != H5T_INTEGER)
    throw FormatError(dataset(path, name), fmt::format("must hold numbers (floating point, e.g. float64), not {}",
                                                       cls == H5T_STRING ? "strings" : "this type"));
  if (const auto u = string_attribute(c.dataset.get(), "units"); u && !unit.empty() && *u != unit)
    throw FormatError(dataset(path, name), fmt::format("attribute units = '{}', its name says '{}'", *u, unit));
  return c;
}

// Reads samples [from, from + n) of `c` into c.block.
void read_block(Channel& c, const std::string& path, hsize_t from, hsize_t n) {
  c.block.resize(n);
  if (H5Sselect_hyperslab(c.space.get(), H5S_SELECT_SET, &from, nullptr, &n, nullptr) < 0)
    throw FormatError(dataset(path, c.name), with_reason(fmt::format("cannot select samples {} to {}", from, from + n - 1)));
  Id mem(H5Screate_simple(1, &n, nullptr), H5Sclose);
  if (H5Dread(c.dataset.get(), H5T_NATIVE_DOUBLE, mem.get(), c.space.get(), H5P_DEFAULT, c.block.data()) < 0)
    throw FormatError(dataset(path, c.name), with_reason(fmt::format("cannot read samples {} to {}", from, from + n - 1)));
}

bool fsync_path(const std::string& p, bool directory) {
  const int fd = ::open(p.c_str(), (directory ? O_RDONLY | O_DIRECTORY : O_RDWR) | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0 || errno == EINVAL;
  return (::close(fd) == 0) && ok;
}

}  // namespace

bool is_hdf5_path(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".h5" || ext == ".hdf5";
}

std::string read_series_hdf5(const std::string& path, const std::string& column,
                             const std::function<void(double, double)>& sample, const ReferenceSink& reference,
                             const ChannelNames& lab_names) {
  silence_hdf5();
  require_readable_file(path, "the series");
  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw FormatError({.file = path},
                      "not an HDF5 file (a name ending in .h5 or .hdf5 is read as HDF5; a CSV record must end in .csv)");
  Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) throw FormatError({.file = path}, with_reason("cannot open the HDF5 file"));
  const std::vector<std::string> names = root_names(file.get());
  // vrelab's name of a dataset -> where it is in this file: the lab's path when the manifest
  // maps it (in any group), else the name in the root group.
  const auto lab = [&](const std::string& n) {
    const auto it = lab_names.find(n);
    return it == lab_names.end() ? n : it->second;
  };
  const auto has = [&](const std::string& n) {
    if (!lab_names.count(n)) return std::find(names.begin(), names.end(), n) != names.end();
    return H5Oexists_by_name(file.get(), lab(n).c_str(), H5P_DEFAULT) > 0;  // (a missing group on the way: < 0)
  };
  const auto missing = [&](const std::string& n, const std::string& what) {
    if (lab_names.count(n))
      return FormatError({.file = path, .key = lab(n)},
                         fmt::format("no dataset '{}' (the manifest's [names] {} = \"{}\"; {}; the root group has: {})", lab(n), n,
                                     lab(n), what, joined(names)));
    std::string msg = fmt::format("no dataset '{}' ({}; the file has: {})", n, what, joined(names));
    if (const std::string close = closest_name(n, names); !close.empty())
      msg += fmt::format("; did you mean '{}' for '{}'?", n, close);
    return FormatError({.file = path, .key = n}, msg);
  };
  if (!has("time_s")) throw missing("time_s", "a raw record needs time_s, in s, and output_<unit>");
  std::string out_name = column;
  if (out_name.empty()) {
    std::vector<std::string> outputs;
    for (const auto& [n, where] : lab_names)
      if (n.rfind("output_", 0) == 0) outputs.push_back(n);
    if (outputs.empty())
      for (const auto& n : names)
        if (n.rfind("output_", 0) == 0) outputs.push_back(n);
    if (outputs.size() != 1)
      throw FormatError({.file = path},
                        outputs.empty() ? fmt::format("no dataset output_<unit> (the file has: {})", joined(names))
                                        : fmt::format("several output datasets ({}); name one (measure --column)", joined(outputs)));
    out_name = outputs.front();
  }
  if (!has(out_name)) throw missing(out_name, "the output, in the unit its name gives");
  if (out_name == "time_s") throw FormatError({.file = path}, "the output dataset cannot be the time dataset");
  const std::string out_unit = out_name.rfind("output_", 0) == 0 ? out_name.substr(7) : "";
  std::vector<Channel> ch;
  ch.push_back(open_channel(file.get(), path, lab("time_s"), "s"));
  ch.push_back(open_channel(file.get(), path, lab(out_name), out_unit));
  // Reference channels, as read_series_csv finds them: ref_<axis>_g, else input_<axis>_g. Their
  // length is checked whether or not the caller reads them.
  static const std::array<const char*, 3> axes{"IA", "PA", "OA"};
  std::array<bool, 3> present{};
  std::array<std::size_t, 3> ref_index{};
  for (std::size_t i = 0; i < 3; ++i)
    for (const std::string prefix : {"ref_", "input_"}) {
      const std::string n = prefix + axes[i] + "_g";
      if (present[i] || !has(n)) continue;
      present[i] = true, ref_index[i] = ch.size();
      ch.push_back(open_channel(file.get(), path, lab(n), "g"));
    }
  const hsize_t n = ch[0].length;
  for (const Channel& c : ch)
    if (c.length != n)
      throw FormatError({.file = path, .key = c.name},
                        fmt::format("dataset {} has {} samples, time_s has {} (every channel of a record has one length)", c.name,
                                    c.length, n));
  const bool any_ref = reference && (present[0] || present[1] || present[2]);
  double last_t = -INFINITY;
  for (hsize_t from = 0; from < n; from += kHdf5BlockSamples) {
    const hsize_t m = std::min<hsize_t>(kHdf5BlockSamples, n - from);
    for (std::size_t k = 0; k < ch.size(); ++k)
      if (k < 2 || any_ref) read_block(ch[k], path, from, m);
    for (hsize_t j = 0; j < m; ++j) {
      const hsize_t at = from + j;
      const double t = ch[0].block[j], u = ch[1].block[j];
      for (std::size_t k = 0; k < 2; ++k) {
        if (!std::isfinite(ch[k].block[j]))
          throw FormatError(dataset(path, ch[k].name, static_cast<long long>(at)),
                            fmt::format("a sample is not a finite number ({})", ch[k].block[j]));
        if (const std::string out = range_problem(k == 0 ? kTimeRange : kOutputRange, ch[k].block[j]); !out.empty())
          throw FormatError(dataset(path, ch[k].name, static_cast<long long>(at)), out);
      }
      if (!(t > last_t))
        throw FormatError(dataset(path, "time_s", static_cast<long long>(at)),
                          fmt::format("time does not increase ({} s after {} s)", t, last_t));
      last_t = t;
      try {
        sample(t, u);
      } catch (const std::invalid_argument& e) {
        throw FormatError(dataset(path, out_name, static_cast<long long>(at)),
                          fmt::format("{} (t = {}, {} = {})", e.what(), t, out_name, u));
      }
      if (any_ref) {
        std::array<double, 3> g{};
        for (std::size_t i = 0; i < 3; ++i) {
          if (!present[i]) continue;
          const Channel& c = ch[ref_index[i]];
          if (!std::isfinite(c.block[j]))
            throw FormatError(dataset(path, c.name, static_cast<long long>(at)),
                              fmt::format("a sample is not a finite number ({})", c.block[j]));
          if (const std::string out = range_problem(kReferenceRange, c.block[j]); !out.empty())
            throw FormatError(dataset(path, c.name, static_cast<long long>(at)), out);
          g[i] = c.block[j];
        }
        try {
          reference(t, g, present);
        } catch (const std::invalid_argument& e) {
          throw FormatError({.file = path}, fmt::format("sample {} (t = {} s): {}", at, t, e.what()));
        }
      }
    }
  }
  return out_name;
}

// ---------------------------------------------------------------- writer

struct Hdf5SeriesWriter::State {
  std::string path, tmp;
  Id file;
  std::vector<Channel> ch;  // time_s, output_<unit>, then the reference channels written
  std::array<bool, 3> reference{};
  hsize_t written = 0;
  bool committed = false;
};

namespace {

void write_string_attribute(hid_t obj, const char* name, const std::string& value, const std::string& where) {
  Id type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<std::size_t>(1, value.size()));
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  Id space(H5Screate(H5S_SCALAR), H5Sclose);
  Id a(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  if (!a.ok() || H5Awrite(a.get(), type.get(), padded.data()) < 0)
    throw FormatError(with_reason(fmt::format("{}: cannot write the attribute {}", where, name)));
}

}  // namespace

Hdf5SeriesWriter::Hdf5SeriesWriter(const std::string& path, const std::string& output_unit, const std::array<bool, 3>& reference,
                                   const std::string& run_id, const std::string& comment)
    : s_(std::make_unique<State>()) {
  silence_hdf5();
  require_writable_file(path, "the record");
  s_->path = path, s_->tmp = path + ".tmp." + std::to_string(::getpid()), s_->reference = reference;
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  if (ec) throw FormatError("cannot create the folder of " + path + ": " + ec.message());
  s_->file = Id(H5Fcreate(s_->tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  if (!s_->file.ok()) throw FormatError(with_reason("cannot write " + s_->tmp));
  try {
    create_datasets(output_unit, run_id, comment);
  } catch (...) {
    s_->ch.clear();
    s_->file.reset();
    fs::remove(s_->tmp, ec);
    throw;
  }
}

void Hdf5SeriesWriter::create_datasets(const std::string& output_unit, const std::string& run_id, const std::string& comment) {
  write_string_attribute(s_->file.get(), "format", "vrelab raw record (docs/data-format.md)", s_->tmp);
  if (!run_id.empty()) write_string_attribute(s_->file.get(), "run_id", run_id, s_->tmp);
  if (!comment.empty()) write_string_attribute(s_->file.get(), "comment", comment, s_->tmp);
  std::vector<std::pair<std::string, std::string>> channels{{"time_s", "s"}, {"output_" + output_unit, output_unit}};
  static const std::array<const char*, 3> axes{"IA", "PA", "OA"};
  for (std::size_t i = 0; i < 3; ++i)
    if (s_->reference[i]) channels.emplace_back(std::string("ref_") + axes[i] + "_g", "g");
  const hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = kHdf5BlockSamples;
  for (const auto& [name, unit] : channels) {
    Id space(H5Screate_simple(1, &zero, &unlimited), H5Sclose);
    Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_chunk(dcpl.get(), 1, &chunk);
    Channel c;
    c.name = name;
    c.dataset = Id(H5Dcreate2(s_->file.get(), name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                   H5Dclose);
    if (!c.dataset.ok()) throw FormatError(with_reason(fmt::format("{}: cannot create the dataset {}", s_->tmp, name)));
    write_string_attribute(c.dataset.get(), "units", unit, fmt::format("{}: dataset {}", s_->tmp, name));
    c.block.reserve(kHdf5BlockSamples);
    s_->ch.push_back(std::move(c));
  }
}

Hdf5SeriesWriter::~Hdf5SeriesWriter() {
  if (!s_ || s_->committed) return;
  s_->ch.clear();
  s_->file.reset();
  std::error_code ec;
  fs::remove(s_->tmp, ec);
}

void Hdf5SeriesWriter::add(double t_s, double output, const std::array<double, 3>& ref_g) {
  s_->ch[0].block.push_back(t_s);
  s_->ch[1].block.push_back(output);
  std::size_t k = 2;
  for (std::size_t i = 0; i < 3; ++i)
    if (s_->reference[i]) s_->ch[k++].block.push_back(ref_g[i]);
  if (s_->ch[0].block.size() == kHdf5BlockSamples) flush();
}

void Hdf5SeriesWriter::flush() {
  const hsize_t m = s_->ch[0].block.size();
  if (m == 0) return;
  const hsize_t total = s_->written + m, from = s_->written;
  for (Channel& c : s_->ch) {
    if (H5Dset_extent(c.dataset.get(), &total) < 0)
      throw FormatError(with_reason(fmt::format("{}: dataset {}: cannot grow to {} samples", s_->tmp, c.name, total)));
    Id space(H5Dget_space(c.dataset.get()), H5Sclose);
    H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &from, nullptr, &m, nullptr);
    Id mem(H5Screate_simple(1, &m, nullptr), H5Sclose);
    if (H5Dwrite(c.dataset.get(), H5T_NATIVE_DOUBLE, mem.get(), space.get(), H5P_DEFAULT, c.block.data()) < 0)
      throw FormatError(with_reason(fmt::format("{}: dataset {}: cannot write samples {} to {}", s_->tmp, c.name, from, total - 1)));
    c.block.clear();
  }
  s_->written = total;
}

void Hdf5SeriesWriter::commit() {
  flush();
  s_->ch.clear();
  if (H5Fflush(s_->file.get(), H5F_SCOPE_GLOBAL) < 0) throw FormatError(with_reason("cannot write " + s_->tmp));
  const hid_t f = s_->file.get();
  if (H5Fclose(f) < 0) throw FormatError(with_reason("cannot write " + s_->tmp));
  s_->file = Id();
  // Durable as well as atomic, as write_atomic (io/formats/output.hpp): the data synced before the
  // rename, the folder after it.
  if (!fsync_path(s_->tmp, false)) throw FormatError("cannot write " + s_->tmp + ": " + std::strerror(errno));
  std::error_code ec;
  fs::rename(s_->tmp, s_->path, ec);
  if (ec) throw FormatError("cannot write " + s_->path + ": " + ec.message());
  s_->committed = true;
  const fs::path target(s_->path);
  fsync_path(target.has_parent_path() ? target.parent_path().string() : ".", true);
}

}  // namespace vrelab::io
