// cdanalysis fit fabric-bounds: the envelope z_min, z_max of (z, a_c)
// points (fabric_bounds.hpp); 2D fabric tables only.
#include <fmt/core.h>

#include <fstream>
#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/fabric_bounds.hpp"

namespace cda::cli {

Handler fit_fabric_bounds(CLI::App& sub) {
  struct Opt {
    std::string table;
    double k = 1.0;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("--table", o->table, "CSV with columns z, a_c (optionally z_err, a_c_err)")->required();
  sub.add_option("--k", o->k, "bound prefactor (1 from method.md's definition)")
      ->check(positive_number())
      ->capture_default_str();
  return [o] {
    {  // a 3D fabric table (the report's, with a_n) is refused before its values are read
      std::ifstream head(o->table);
      std::string line;
      std::getline(head, line);
      if (("," + line + ",").find(",a_n,") != std::string::npos)
        throw AnalysisError(fmt::format("fit fabric-bounds is 2D only: '{}' is a 3D fabric table (column a_n); "
                                        "the bounds of method.md §11 bound the 2D density (z/2pi)(1 + a_c cos "
                                        "2theta)",
                                        o->table));
    }
    const auto t = Table::read_csv(o->table);
    const auto b = fabric_bounds(t.column("z"), t.column("a_c"), col_or_empty(t, "z_err"),
                                 col_or_empty(t, "a_c_err"), o->k);
    fmt::print("fabric bounds (k = {}): z_min {:.4f} +- {:.2g} (row {}), z_max {:.4f} +- {:.2g} (row {})\n"
               "peak a_c* {:.4f} at z* {:.4f}\n",
               b.k, b.z_min, b.z_min_err, b.i_min + 1, b.z_max, b.z_max_err, b.i_max + 1, b.a_star(),
               b.z_star());
    return 0;
  };
}

}  // namespace cda::cli
