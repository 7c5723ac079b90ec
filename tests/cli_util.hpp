// Runs a command line and collects its exit code and output (stdout and
// stderr), for the tests that drive the executables as a user would.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

namespace cdtest {

struct CmdResult {
  int code;         // exit code, -1 if killed by a signal
  std::string out;  // stdout and stderr
};

inline CmdResult run_command(const std::string& cmd) {
  std::unique_ptr<FILE, int (*)(FILE*)> p(popen((cmd + " 2>&1").c_str(), "r"), pclose);
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p.get())) out += buf.data();
  const int status = pclose(p.release());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// A file's bytes ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// An empty folder BUILD/<test>/<name> for a test's files (emptied first).
inline std::filesystem::path scratch_dir(const std::string& test, const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(CDLAB_BINARY_DIR) / test / name;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

}  // namespace cdtest
