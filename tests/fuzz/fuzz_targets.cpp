// The readers under fuzzing (fuzz_targets.hpp). Each writes the bytes to a
// file of its own (the readers read files, as the tools do), reads it, and
// returns 0 on acceptance or on a refusal by the reader's documented error
// type that names the file.
#include "fuzz_targets.hpp"

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "analysis/src/compare.hpp"
#include "analysis/src/error.hpp"
#include "analysis/src/table.hpp"
#include "checkpoint.hpp"
#include "checkpoint3.hpp"
#include "checkpoint_io.hpp"
#include "config.hpp"
#include "contact_problem.hpp"
#include "contact_problem3.hpp"
#include "derived.hpp"
#include "problem3.hpp"
#include "siconos_dat.hpp"
#include "solver.hpp"
#include "world.hpp"
#include "world3.hpp"

namespace cdfuzz {
namespace {

// The input as a file: one per target and process (libFuzzer's -fork and
// -jobs run processes side by side), under $TMPDIR, rewritten each call.
std::string as_file(const std::uint8_t* data, std::size_t size, const char* name) {
  static const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string path = (dir / ("cdlab-fuzz-" + std::to_string(getpid()) + "-" + name)).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw std::runtime_error("fuzz harness: cannot write " + path);
  return path;
}

// A refusal must say which file it refuses.
void named(const std::exception& e, const std::string& path) {
  if (std::string_view(e.what()).find(path) == std::string_view::npos)
    throw Finding(std::string("a refusal that does not name the file '") + path + "': " + e.what());
}

// Calls read() on the input's file; its documented error E is a clean
// refusal, anything else escapes.
template <class E, class Read>
int refused_or_read(const std::uint8_t* data, std::size_t size, const char* name, Read&& read) {
  const std::string path = as_file(data, size, name);
  try {
    read(path);
  } catch (const E& e) {
    named(e, path);
  }
  return 0;
}

// A checkpoint's bytes with their checksum made right (the last 8 bytes,
// FNV-1a of those before): otherwise nearly every mutation would stop at the
// checksum, and the fuzzer would never reach the field checks behind it.
std::string with_checksum(const std::uint8_t* data, std::size_t size) {
  std::string b(reinterpret_cast<const char*>(data), size);
  if (b.size() >= 8) {
    const std::uint64_t h = cd::fnv1a(std::string_view(b).substr(0, b.size() - 8));
    std::memcpy(b.data() + b.size() - 8, &h, 8);
  }
  return b;
}

}  // namespace

int fuzz_scene(const std::uint8_t* data, std::size_t size) {
  const std::string path = as_file(data, size, "scene.toml");
  cd::Scene s;
  try {
    s = cd::load_scene(path);
    cd::check_derived(s);
  } catch (const cd::ConfigError& e) {
    named(e, path);
    return 0;
  } catch (const cd::SceneError& e) {
    // Derived from several keys: named by the keys, not the file.
    return 0;
  }
  // A valid scene's resolved form (its run folder's scene.toml) reads back
  // to the same values.
  const std::string values = cd::resolved_values(s);
  cd::Scene back;
  try {
    back = cd::parse_scene(cd::resolved_toml(s), path + " (resolved)");
  } catch (const cd::ConfigError& e) {
    throw Finding(std::string("the resolved form of a valid scene is refused: ") + e.what());
  }
  if (cd::resolved_values(back) != values) throw Finding("the resolved form of a valid scene reads back different");
  return 0;
}

int fuzz_checkpoint2(const std::uint8_t* data, std::size_t size) {
  const std::string b = with_checksum(data, size);
  const auto* d = reinterpret_cast<const std::uint8_t*>(b.data());
  // As a start sample (no totals; no cell), and as a resumed shear run's
  // checkpoint (totals; a Lees-Edwards cell, whose state is checked against
  // the grains).
  refused_or_read<cd::CheckpointError>(d, b.size(), "ckpt2.bin", [](const std::string& p) {
    cd::World w{cd::WorldParams{}};
    cd::load_checkpoint(p, w);
  });
  return refused_or_read<cd::CheckpointError>(d, b.size(), "ckpt2.bin", [](const std::string& p) {
    cd::WorldParams prm;
    prm.cell.mode = cd::CellParams::Mode::LeesEdwards;
    cd::World w{prm};
    cd::RunTotals totals;
    cd::load_checkpoint(p, w, &totals);
  });
}

int fuzz_checkpoint3(const std::uint8_t* data, std::size_t size) {
  const std::string b = with_checksum(data, size);
  const auto* d = reinterpret_cast<const std::uint8_t*>(b.data());
  // Into a world without a cell, and into a tri-periodic Lees-Edwards cell
  // at imposed pressure (a 3D shear run's), with the totals.
  refused_or_read<cd::CheckpointError>(d, b.size(), "ckpt3.bin", [](const std::string& p) {
    cd::World3 w{cd::WorldParams3{}};
    cd::load_checkpoint3(p, w);
  });
  return refused_or_read<cd::CheckpointError>(d, b.size(), "ckpt3.bin", [](const std::string& p) {
    cd::WorldParams3 prm;
    prm.periodic = {true, true, true};
    prm.cell = cd::Vec3(1.0, 1.0, 1.0);
    prm.shear_rate = 1.0;
    prm.pressure = 1.0;
    prm.cell_mass = 1.0;
    prm.cell_dof = {false, true, false};
    cd::World3 w{prm};
    cd::RunTotals totals;
    cd::load_checkpoint3(p, w, &totals);
  });
}

int fuzz_cdp(const std::uint8_t* data, std::size_t size) {
  return refused_or_read<std::runtime_error>(data, size, "step.cdp", [](const std::string& p) {
    cd::SolverParams prm;
    cd::read_contact_problem(p, prm);
  });
}

int fuzz_cdp3(const std::uint8_t* data, std::size_t size) {
  return refused_or_read<std::runtime_error>(data, size, "step.cdp3", [](const std::string& p) {
    cd::SolverParams prm;
    cd::read_contact_problem3(p, prm);
  });
}

int fuzz_dat(const std::uint8_t* data, std::size_t size) {
  return refused_or_read<std::runtime_error>(data, size, "problem.dat",
                                             [](const std::string& p) { cd::read_siconos_dat(p); });
}

int fuzz_hdf5(const std::uint8_t* data, std::size_t size) {
  return refused_or_read<std::runtime_error>(data, size, "problem.hdf5",
                                             [](const std::string& p) { cd::read_fclib(p); });
}

int fuzz_csv(const std::uint8_t* data, std::size_t size) {
  return refused_or_read<cda::InputError>(data, size, "series.csv",
                                          [](const std::string& p) { cda::Table::read_csv(p); });
}

int fuzz_fit(const std::uint8_t* data, std::size_t size) {
  return refused_or_read<cda::AnalysisError>(data, size, "fits.toml",
                                             [](const std::string& p) { cda::read_fit_toml(p); });
}

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {
      {"scene", fuzz_scene}, {"checkpoint2", fuzz_checkpoint2}, {"checkpoint3", fuzz_checkpoint3},
      {"cdp", fuzz_cdp},     {"cdp3", fuzz_cdp3},               {"dat", fuzz_dat},
      {"hdf5", fuzz_hdf5},   {"csv", fuzz_csv},                 {"fit", fuzz_fit}};
  return all;
}

}  // namespace cdfuzz
