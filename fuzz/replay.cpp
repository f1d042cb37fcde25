// fuzz/replay.cpp -- the fuzz targets' kept inputs as a test of the normal build:
//   vrelab_fuzz_replay <target> <file or folder>...
// feeds every file (a folder: every file in it) to the target (fuzz/readers.hpp) and fails
// (exit 1, naming the file) when one escapes the reader as anything but a refusal of bad input.
// A path that does not exist, or no input at all, fails too (exit 2): a wrong regressions or
// seeds path would otherwise replay nothing and pass.
//   vrelab_fuzz_replay --write lab_data|raw_hdf5 <input> <out>
// writes the files the target gives its reader (a campaign folder, an HDF5 record) for the
// CLI to read them (tests/cli/cli_corpus.sh).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/readers.hpp"

namespace {

std::string read_bytes(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int write_files(const std::string& target, const std::string& input, const std::string& out) {
  const std::string bytes = read_bytes(input);
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (target == "lab_data") vrelab::fuzz::write_lab_data(data, bytes.size(), out);
  else if (target == "raw_hdf5") vrelab::fuzz::write_hdf5_record(data, bytes.size(), out);
  else {
    std::fprintf(stderr, "--write: lab_data or raw_hdf5, not %s\n", target.c_str());
    return 2;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc == 5 && std::string(argv[1]) == "--write") return write_files(argv[2], argv[3], argv[4]);
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: %s case_file|lab_data|series|psd_table|raw_csv|raw_hdf5 FILE_OR_FOLDER...\n"
                 "       %s --write lab_data|raw_hdf5 INPUT OUT\n",
                 argv[0], argv[0]);
    return 2;
  }
  const auto target = vrelab::fuzz::target(argv[1]);
  if (!target) {
    std::fprintf(stderr, "unknown target %s\n", argv[1]);
    return 2;
  }
  std::vector<fs::path> files;
  for (int i = 2; i < argc; ++i) {
    if (!fs::exists(argv[i])) {
      std::fprintf(stderr, "FAIL %s: no such file or folder\n", argv[i]);
      return 2;
    }
    if (fs::is_directory(argv[i])) {
      for (const auto& e : fs::directory_iterator(argv[i]))
        if (e.is_regular_file() && e.path().filename() != "README.md") files.push_back(e.path());
    } else {
      files.emplace_back(argv[i]);
    }
  }
  if (files.empty()) {
    std::fprintf(stderr, "FAIL %s: no inputs in the paths given\n", argv[1]);
    return 2;
  }
  std::sort(files.begin(), files.end());
  int failed = 0;
  for (const auto& f : files) {
    const std::string bytes = read_bytes(f);
    try {
      target(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "FAIL %s: %s\n", f.c_str(), e.what());
      ++failed;
    }
  }
  std::printf("%s: %zu inputs, %d failed\n", argv[1], files.size(), failed);
  return failed == 0 ? 0 : 1;
}
