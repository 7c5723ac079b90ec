#include "plot.hpp"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace cda {

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("cannot write '{}'", path));
  out << text;
}

std::string toml_num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::string s = fmt::format("{:.17g}", v);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

bool run_gnuplot(const std::string& script) {
  const std::string cmd = fmt::format("gnuplot '{}' > '{}.log' 2>&1", script, script);
  return std::system(cmd.c_str()) == 0;
}

bool plot_both(const std::string& dir, const std::string& stem, const std::string& body, int width,
               int height) {
  const std::string gp = (fs::path(dir) / (stem + ".gp")).string();
  const std::string s = fmt::format(
      "# cdanalysis plot; rerun with: gnuplot {0}.gp\ncd '{1}'\n"
      "set terminal pngcairo size {2},{3} enhanced\nset output '{0}.png'\n{4}\n"
      "set terminal svg size {2},{3} dynamic enhanced\nset output '{0}.svg'\nreplot\nunset output\n",
      stem, fs::absolute(dir).string(), width, height, body);
  write_text(gp, s);
  return run_gnuplot(gp);
}

std::string column_label(const std::string& column) {
  static const std::pair<const char*, const char*> labels[] = {
      {"q_over_p", "q/p"},
      {"shear_stress_ratio", "μ = −(σ_xy + σ_yx)/2σ_yy"},
      {"packing_fraction", "packing fraction φ"},
      {"inertial_number", "inertial number I"},
      {"kinetic_energy", "kinetic energy (J)"},
      {"z", "coordination z"},
      {"strain", "shear strain γ"},
      {"time", "time (s)"},
  };
  for (const auto& [c, l] : labels)
    if (column == c) return fmt::format("{} ({})", l, column);
  return column;
}

bool plot_series(const std::string& dir, const std::string& stem, const Table& series,
                 const std::string& x_column, const std::string& column, const SteadyStats* s) {
  Table t({x_column, column});
  const auto& x = series.column(x_column);
  const auto& y = series.column(column);
  for (std::size_t i = 0; i < x.size(); ++i) t.add_row({x[i], y[i]});
  t.write_csv((fs::path(dir) / (stem + ".csv")).string());
  std::string body = fmt::format("set datafile separator ','\nset key top right\nset xlabel '{}' noenhanced\n"
                                 "set ylabel '{}' noenhanced\nset grid\n",
                                 column_label(x_column), column_label(column));
  std::string mean;
  if (s) {
    const Window& w = s->window;
    body += fmt::format("set object 1 rect from {},graph 0 to {},graph 1 fc rgb '#cce5ff' fs solid 0.5 behind\n",
                        w.x_begin, w.x_end);
    // The steady mean over the window, drawn across it, its value and error in the key.
    mean = fmt::format(", \\\n     [{}:{}] {} with lines lw 2 dt 2 lc rgb '#b03a2e' title 'steady mean {:.4g} ± {:.2g}' "
                       "noenhanced",
                       toml_num(w.x_begin), toml_num(w.x_end), toml_num(s->mean), s->mean, s->error());
  }
  body += fmt::format("plot '{}.csv' using 1:2 every ::1 with lines lc rgb '#1f3b73' title '{}{}' noenhanced{}\n",
                      stem, column, s ? " (steady window shaded)" : "", mean);
  return plot_both(dir, stem, body);
}

}  // namespace cda
