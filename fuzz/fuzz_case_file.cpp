// libFuzzer entry point of the case_file reader (fuzz/readers.hpp).
#include "fuzz/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vrelab::fuzz::case_file(data, size);
  return 0;
}
