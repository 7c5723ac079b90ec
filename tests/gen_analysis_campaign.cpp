// Writes the synthetic mu(I) campaign committed in tests/data/analysis/mu_i/
// (see the README there). Known answer: mu(I) = mu1 + (mu2 - mu1)/(1 + I0/I)
// with the values below, written to truth.toml in the fit-TOML layout so a
// test can read it with read_fit_toml. Rerun only on purpose (the stored
// fits.toml is the reference the regression test compares against):
//   tests/data/analysis/regenerate.sh BUILD_DIR
#include <fmt/core.h>

#include <filesystem>
#include <fstream>

#include "analysis_synth.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    fmt::print(stderr, "usage: gen_analysis_campaign OUT_DIR\n");
    return 1;
  }
  const std::filesystem::path out = argv[1];
  constexpr double mu1 = 0.26, mu2 = 0.60, I0 = 0.08;
  const double Is[] = {1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3};
  std::uint64_t seed = 20240501;
  for (double I : Is) {
    synth::RunSpec s;
    s.I = I;
    s.mu = synth::mu_of_I(mu1, mu2, I0, I);
    s.seed = seed++;
    synth::write_run(out / fmt::format("I_{:g}", I), s);
  }
  std::ofstream(out / "truth.toml") << fmt::format(
      "# True parameters of the synthetic campaign (tests/gen_analysis_campaign.cpp); errors are 0.\n"
      "# Rows: 300 per run, q_over_p noise AR(1) a = 0.5 (tau_int 1.5 rows), sd 0.02.\n"
      "[mu_I]\nformula = \"mu = mu1 + (mu2 - mu1)/(1 + I0/I)\"\nnames = [\"mu1\", \"mu2\", \"I0\"]\n\n"
      "[mu_I.params.mu1]\nvalue = {}\nerror = 0.0\n\n[mu_I.params.mu2]\nvalue = {}\nerror = 0.0\n\n"
      "[mu_I.params.I0]\nvalue = {}\nerror = 0.0\n",
      mu1, mu2, I0);
  fmt::print("wrote {} runs and truth.toml to {}\n", std::size(Is), out.string());
  return 0;
}
