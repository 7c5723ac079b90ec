// The libFuzzer entry point of one target: compiled once per target with
// CDLAB_FUZZ_TARGET set to its function (tests/fuzz/CMakeLists.txt).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return cdfuzz::CDLAB_FUZZ_TARGET(data, size);
}
