#pragma once
// Test support: a raw HDF5 file from datasets given whole (the test's own writer, with the C
// API, for files the library's writer would never make: missing or mismatched datasets, or
// datasets of different lengths).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <hdf5.h>

namespace vrelab::test {

// Each dataset float64, contiguous, of its own length.
inline void write_h5(const std::filesystem::path& p, const std::vector<std::pair<std::string, std::vector<double>>>& datasets) {
  const hid_t f = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  for (const auto& [name, x] : datasets) {
    const hsize_t n = x.size();
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t d = H5Dcreate2(f, name.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x.data());
    H5Dclose(d), H5Sclose(space);
  }
  H5Fclose(f);
}

}  // namespace vrelab::test
