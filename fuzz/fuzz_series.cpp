// libFuzzer entry point of the series reader (fuzz/readers.hpp).
#include "fuzz/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vrelab::fuzz::series(data, size);
  return 0;
}
