// libFuzzer entry point of the psd_table reader (fuzz/readers.hpp).
#include "fuzz/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vrelab::fuzz::psd_table(data, size);
  return 0;
}
