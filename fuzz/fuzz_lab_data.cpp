// libFuzzer entry point of the lab_data reader (fuzz/readers.hpp).
#include "fuzz/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vrelab::fuzz::lab_data(data, size);
  return 0;
}
