// Raw records in HDF5 (io/formats/raw_hdf5.hpp, docs/data-format.md "Raw records in HDF5"), the
// reader and the writer alone: the reader delivers exactly what the CSV reader delivers for
// the same samples; a writer not committed leaves no file. In the commands (diagnose, measure,
// campaign): tests/validation/test_raw_hdf5.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <unistd.h>

#include <hdf5.h>

#include <fmt/format.h>

#include "io/formats/raw_hdf5.hpp"
#include "io/formats/series.hpp"
#include "support/files.hpp"
#include "support/lcg.hpp"

namespace vrelab::test_raw_hdf5 {
namespace {

namespace fs = std::filesystem;
using test::Lcg;
using test::TempDir;

struct Captured {
  std::vector<double> t, u, rt;
  std::vector<std::array<double, 3>> ref;
  std::vector<std::array<bool, 3>> present;
  std::string name;
};

Captured capture(const std::string& path, const std::string& column = "", bool with_reference = true) {
  Captured c;
  io::ReferenceSink sink;
  if (with_reference)
    sink = [&c](double t, const std::array<double, 3>& g, const std::array<bool, 3>& p) {
      c.rt.push_back(t), c.ref.push_back(g), c.present.push_back(p);
    };
  c.name = io::read_series(path, column, [&c](double t, double u) { c.t.push_back(t), c.u.push_back(u); }, sink);
  return c;
}

TEST(RawHdf5, DeliversExactlyWhatTheCsvReaderDelivers) {
  // 150001 samples (three 64 Ki blocks, the last partial) of output and three reference
  // channels, written as CSV with round-trip digits and as HDF5 by the library's writer: both
  // readers must hand over the same doubles in the same order, bit for bit.
  TempDir d;
  const std::string csv = (d.path / "r.csv").string(), h5 = (d.path / "r.h5").string();
  Lcg rng;
  {
    std::ofstream out(csv);
    out << "# a record\ntime_s,output_mA,ref_IA_g,ref_PA_g,ref_OA_g\n";
    io::Hdf5SeriesWriter w(h5, "mA", {true, true, true}, "r", "test");
    for (int i = 0; i <= 150000; ++i) {
      const double t = -1.0 + i / 20000.0, u = 0.88 + 0.3 * std::sin(2 * std::numbers::pi * 100 * t) + 1e-5 * rng.next();
      const std::array<double, 3> g{2 * std::sin(2 * std::numbers::pi * 100 * t), 0.1 * rng.next(), 1e-3 * rng.next()};
      out << fmt::format("{},{},{},{},{}\n", t, u, g[0], g[1], g[2]);
      w.add(t, u, g);
    }
    w.commit();
  }
  EXPECT_FALSE(fs::exists(h5 + ".tmp." + std::to_string(::getpid())));  // renamed into place
  const Captured a = capture(csv), b = capture(h5);
  ASSERT_EQ(a.t.size(), 150001u);
  EXPECT_EQ(a.name, "output_mA");
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.t, a.t);
  EXPECT_EQ(b.u, a.u);
  EXPECT_EQ(b.rt, a.rt);
  EXPECT_EQ(b.ref, a.ref);
  EXPECT_EQ(b.present, a.present);
  // Without a reference sink the channels are not read; the output chosen by name.
  const Captured c = capture(h5, "output_mA", false);
  EXPECT_EQ(c.u, a.u);
  EXPECT_TRUE(c.ref.empty());
}

// A DAQ's file keeps its channels where it keeps them (a group, its own names): the
// manifest's [names] maps vrelab's names to those paths (io::ChannelNames) and the reader
// delivers what it delivers from vrelab's layout, sample for sample. Unmapped, the file is
// refused naming what it lacks; a mapped path that is not there is refused naming the
// manifest's key and the path.
TEST(RawHdf5, ALabsOwnDatasetPathsAreReadThroughTheManifestsNames) {
  TempDir d;
  const std::string ours = (d.path / "ours.h5").string(), theirs = (d.path / "theirs.h5").string();
  for (const std::string& path : {ours, theirs}) {
    io::Hdf5SeriesWriter w(path, "mA", {true, false, false}, "r", "test");
    for (int i = 0; i <= 3000; ++i) {
      const double t = -0.5 + i / 2000.0;
      w.add(t, 0.9 + 0.2 * std::sin(2 * std::numbers::pi * 50 * t), {std::cos(2 * std::numbers::pi * 50 * t), 0, 0});
    }
    w.commit();
  }
  {  // theirs: the channels moved into the group /daq under the DAQ's names
    const hid_t f = H5Fopen(theirs.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    const hid_t g = H5Gcreate2(f, "/daq", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(g, 0);
    H5Gclose(g);
    ASSERT_GE(H5Lmove(f, "time_s", f, "/daq/t", H5P_DEFAULT, H5P_DEFAULT), 0);
    ASSERT_GE(H5Lmove(f, "output_mA", f, "/daq/ch0", H5P_DEFAULT, H5P_DEFAULT), 0);
    ASSERT_GE(H5Lmove(f, "ref_IA_g", f, "/daq/accel_x", H5P_DEFAULT, H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  const io::ChannelNames names{{"time_s", "/daq/t"}, {"output_mA", "/daq/ch0"}, {"ref_IA_g", "/daq/accel_x"}};
  Captured a = capture(ours), b;
  io::ReferenceSink sink = [&b](double t, const std::array<double, 3>& g, const std::array<bool, 3>& p) {
    b.rt.push_back(t), b.ref.push_back(g), b.present.push_back(p);
  };
  b.name = io::read_series(theirs, "", [&b](double t, double u) { b.t.push_back(t), b.u.push_back(u); }, sink, names);
  ASSERT_EQ(a.t.size(), 3001u);
  EXPECT_EQ(b.name, "output_mA");
  EXPECT_EQ(b.t, a.t);
  EXPECT_EQ(b.u, a.u);
  EXPECT_EQ(b.ref, a.ref);
  EXPECT_EQ(b.present, a.present);
  {  // The same names in a CSV record: its header's names put back to vrelab's.
    const std::string csv = (d.path / "theirs.csv").string();
    std::ofstream out(csv);
    out << "t,ch0,accel_x\n";
    for (std::size_t i = 0; i < a.t.size(); ++i) out << fmt::format("{},{},{}\n", a.t[i], a.u[i], a.ref[i][0]);
    out.close();
    Captured c;
    io::ReferenceSink csink = [&c](double t, const std::array<double, 3>& g, const std::array<bool, 3>& p) {
      c.ref.push_back(g), c.present.push_back(p);
      (void)t;
    };
    c.name = io::read_series(csv, "", [&c](double t, double u) { c.t.push_back(t), c.u.push_back(u); }, csink,
                             {{"time_s", "t"}, {"output_mA", "ch0"}, {"ref_IA_g", "accel_x"}});
    EXPECT_EQ(c.name, "output_mA");
    EXPECT_EQ(c.t, a.t);
    EXPECT_EQ(c.u, a.u);
    EXPECT_EQ(c.ref, a.ref);
  }
  const auto error = [&](const io::ChannelNames& n) {
    try {
      io::read_series(theirs, "", [](double, double) {}, {}, n);
    } catch (const io::FormatError& e) {
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  EXPECT_NE(error({}).find("no dataset 'time_s'"), std::string::npos) << error({});
  io::ChannelNames wrong = names;
  wrong["time_s"] = "/acq/t";
  EXPECT_NE(error(wrong).find("no dataset '/acq/t' (the manifest's [names] time_s = \"/acq/t\""), std::string::npos) << error(wrong);
}

TEST(RawHdf5, AWriterNotCommittedLeavesNoFile) {
  TempDir d;
  const fs::path p = d.path / "x.h5";
  {
    io::Hdf5SeriesWriter w(p.string(), "mA");
    w.add(0, 1);
  }
  EXPECT_TRUE(fs::is_empty(d.path)) << "a temporary file left behind";
  // Positive control: the same writer committed leaves the file, and only it.
  {
    io::Hdf5SeriesWriter w(p.string(), "mA");
    w.add(0, 1);
    w.commit();
  }
  EXPECT_TRUE(fs::exists(p));
  EXPECT_EQ(std::distance(fs::directory_iterator(d.path), fs::directory_iterator{}), 1);
}

}  // namespace
}  // namespace vrelab::test_raw_hdf5
