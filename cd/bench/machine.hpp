// The machine a benchmark ran on, as key/value pairs written next to its
// results (results without the machine named cannot be compared).
#pragma once
#include <omp.h>
#include <unistd.h>

#include <ctime>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace cdbench {

// First line of a file starting with key ("" for the first line), value after ':'.
inline std::string read_line(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (key.empty()) return line;
    if (line.rfind(key, 0) != 0) continue;
    const auto c = line.find(':');
    return c == std::string::npos ? line : line.substr(line.find_first_not_of(" \t", c + 1));
  }
  return "unknown";
}

inline std::string load_average() { return read_line("/proc/loadavg", ""); }

inline std::string utc_now() {
  char buf[32];
  const std::time_t t = std::time(nullptr);
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// load_start: /proc/loadavg when the run began (a loaded machine makes
// every time, and above all the multi-thread ones, worse).
inline std::vector<std::pair<std::string, std::string>> machine(const std::string& load_start) {
  return {{"date_utc", utc_now()},
          {"cpu_model", read_line("/proc/cpuinfo", "model name")},
          {"nproc", std::to_string(sysconf(_SC_NPROCESSORS_ONLN))},
          {"omp_max_threads", std::to_string(omp_get_max_threads())},
          {"compiler", "g++ " __VERSION__},
          {"build_type", CDLAB_BUILD_TYPE},
          {"cxx_flags", CDLAB_CXX_FLAGS},
          {"load_avg_start", load_start},
          {"load_avg_end", load_average()}};
}

inline std::string csv_quote(const std::string& s) {
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

inline void write_machine_csv(const std::string& path,
                              const std::vector<std::pair<std::string, std::string>>& m) {
  std::ofstream f(path);
  f << "key,value\n";
  for (const auto& [k, v] : m) f << k << "," << csv_quote(v) << "\n";
}

}  // namespace cdbench
