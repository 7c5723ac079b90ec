// Runs a command line and collects its exit code and output (stdout and
// stderr), for the tests that drive the executables as a user would.
#pragma once
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

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

// summary.toml's "key = value" lines, values as written (the comments
// after them cut).
inline std::map<std::string, std::string> summary_fields(const std::filesystem::path& p) {
  std::istringstream in(slurp(p));
  std::map<std::string, std::string> f;
  for (std::string line; std::getline(in, line);) {
    const auto eq = line.find(" = ");
    if (line.starts_with("#") || eq == std::string::npos) continue;
    std::string v = line.substr(eq + 3, line.find(" #") - eq - 3);
    while (!v.empty() && v.back() == ' ') v.pop_back();
    f[line.substr(0, eq)] = v;
  }
  return f;
}

// An empty folder BUILD/<test>/<name> for a test's files (emptied first).
// Every key of a resolved scene as cdsim --print-scene prints it (TOML
// sections of `key = value # comment` lines), as section.key -> value.
inline std::map<std::string, std::string> printed_keys(const std::string& printed) {
  std::map<std::string, std::string> out;
  std::istringstream in(printed);
  std::string section;
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("[")) section = line.substr(1, line.find(']') - 1);
    std::istringstream ls(line);
    std::string key, eq, value;
    ls >> key >> eq >> value;
    if (eq == "=") out[section + "." + key] = value;
  }
  return out;
}

inline std::filesystem::path scratch_dir(const std::string& test, const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(CDLAB_BINARY_DIR) / test / name;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

// Starts args[0] with the arguments args, without waiting, its stdout and
// stderr to the file `out` (/dev/null if empty); own_group: in a process
// group of its own (its pid), as a command run under GNU timeout, so that a
// signal can be sent as timeout sends it. Returns its pid, or -1.
inline pid_t spawn(std::vector<std::string> args, const std::string& out = "", bool own_group = false) {
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.empty() ? "/dev/null" : out.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawnattr_t at;
  posix_spawnattr_init(&at);
  if (own_group) {
    posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&at, 0);
  }
  pid_t pid;
  const int rc = posix_spawn(&pid, argv[0], &fa, &at, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&at);
  return rc == 0 ? pid : -1;
}

}  // namespace cdtest
