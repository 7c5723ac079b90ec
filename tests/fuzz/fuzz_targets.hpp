// One function per reader of the project's input files, each fed the bytes
// of a whole file: the libFuzzer entry points (fuzz_main.cpp, `make fuzz`)
// and the replay of the committed regression inputs (tests/test_fuzz_replay.cpp,
// `make test`) call the same functions.
//
// The contract each checks: the reader either accepts the bytes or refuses
// them with its documented error type, whose message names the file. Any
// other exception escapes (a libFuzzer finding, a failed replay test), as
// does a Finding (a refusal that does not name the file, a valid scene whose
// resolved form does not read back); crashes, sanitizer reports and leaks
// are the sanitizers'.
#pragma once
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace cdfuzz {

// A broken contract that is not a crash: the message says which.
struct Finding : std::logic_error {
  using std::logic_error::logic_error;
};

int fuzz_scene(const std::uint8_t* data, std::size_t size);        // scene TOML (load_scene, check_derived)
int fuzz_checkpoint2(const std::uint8_t* data, std::size_t size);  // 2D checkpoint.bin
int fuzz_checkpoint3(const std::uint8_t* data, std::size_t size);  // 3D checkpoint.bin
int fuzz_cdp(const std::uint8_t* data, std::size_t size);          // .cdp (2D dumped step)
int fuzz_cdp3(const std::uint8_t* data, std::size_t size);         // .cdp3 (3D dumped step)
int fuzz_dat(const std::uint8_t* data, std::size_t size);          // Siconos .dat (2D or 3D)
int fuzz_hdf5(const std::uint8_t* data, std::size_t size);         // FCLib .hdf5
int fuzz_csv(const std::uint8_t* data, std::size_t size);          // series.csv (Table::read_csv)
int fuzz_fit(const std::uint8_t* data, std::size_t size);          // fit TOML (read_fit_toml)

struct Target {
  const char* name;  // also the folder of its regression inputs, tests/data/fuzz/<name>/
  int (*run)(const std::uint8_t*, std::size_t);
};
// Every target, in the order above.
const std::vector<Target>& targets();

}  // namespace cdfuzz
