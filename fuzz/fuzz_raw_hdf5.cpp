// libFuzzer entry point of the raw_hdf5 reader (fuzz/readers.hpp).
#include "fuzz/readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  vrelab::fuzz::raw_hdf5(data, size);
  return 0;
}
