// cdanalysis compare-fits REFERENCE NEW: the parameters of two fit TOML
// files compared one by one (compare.hpp); the regression gate of make regress.
#include <fmt/core.h>

#include <memory>

#include "analysis/app/command.hpp"
#include "analysis/src/compare.hpp"

namespace cda::cli {

Handler compare_fits(CLI::App& sub) {
  struct Opt {
    std::string ref_toml, new_toml;
    double tol_sigma = 3, tol_rel = 0;
  };
  auto o = std::make_shared<Opt>();
  sub.add_option("reference", o->ref_toml, "reference fit TOML")->required();
  sub.add_option("new", o->new_toml, "new fit TOML")->required();
  sub.add_option("--tol-sigma", o->tol_sigma, "combined standard uncertainties allowed")
      ->check(non_negative_number())->capture_default_str();
  sub.add_option("--tol-rel", o->tol_rel, "relative change allowed (0: the sigma test alone)")
      ->check(non_negative_number())->capture_default_str();
  return [o] {
    const auto a = read_fit_toml(o->ref_toml);
    const auto b = read_fit_toml(o->new_toml);
    const auto c = cda::compare_fits(a, b, o->tol_sigma, o->tol_rel);
    fmt::print("reference {}\nnew       {}\n{}", o->ref_toml, o->new_toml, format_comparison(c, o->tol_sigma, o->tol_rel));
    return c.ok() ? 0 : 1;
  };
}

}  // namespace cda::cli
