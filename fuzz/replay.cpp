// fuzz/replay.cpp -- the fuzz targets' kept inputs as a test of the normal build:
//   vrelab_fuzz_replay <target> <file or folder>...
// feeds every file (a folder: every file in it) to the target (fuzz/readers.hpp) and fails
// (exit 1, naming the file) when one escapes the reader as anything but a refusal of bad input.
// A path that does not exist, or no input at all, fails too (exit 2): a wrong regressions or
// seeds path would otherwise replay nothing and pass.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/readers.hpp"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s case_file|lab_data|series FILE_OR_FOLDER...\n", argv[0]);
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
    std::ifstream in(f, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
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
