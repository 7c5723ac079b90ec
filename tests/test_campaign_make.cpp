// Campaigns know their parameters: make writes a manifest
// of what made a campaign folder, refuses, naming the difference, to add
// runs made with another N or STRAIN to it (also under make -n, writing
// nothing), accepts more values of I, and `make campaign-status` tells each
// run's state. A tiny real campaign: 60 disks, a 250-step preparation (not
// jammed: enough for make's bookkeeping), one shear run of 4 steps.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace fs = std::filesystem;

namespace {

// make in the source tree as a user runs it (nothing inherited from a make
// that runs ctest), with the test's build (its cdsim); `programs` (the
// build of cdsim) is taken as done: ctest runs after the build.
cdtest::CmdResult make(const fs::path& campaigns, const std::string& args) {
  return cdtest::run_command("env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s -C " CDLAB_SOURCE_DIR
                             " -o programs BUILD=" CDLAB_BINARY_DIR " THREADS=1 CAMPAIGNS=" +
                             campaigns.string() + " " + args);
}

// Every file under a folder with its size and modification time.
std::map<std::string, std::string> listing(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    out[e.path().string()] =
        e.is_regular_file() ? std::to_string(e.file_size()) + "@" +
                                  std::to_string(e.last_write_time().time_since_epoch().count())
                            : "dir";
  return out;
}

const std::string kTiny = "PREP_SET='--set time.duration=0.002' INERTIAL_I=0.1 ";

}  // namespace

TEST(CampaignMake, ManifestWrittenAndOtherParametersRefusedNamingThem) {
  const fs::path c = cdtest::scratch_dir("test_campaign_make", "campaigns");
  const cdtest::CmdResult first = make(c, "campaign-inertial N=60 STRAIN=0.02 " + kTiny);
  ASSERT_EQ(first.code, 0) << first.out;
  ASSERT_TRUE(fs::exists(c / "inertial/I_0.1/.done")) << first.out;
  const std::string prep = cdtest::slurp(c / "prep/manifest.toml");
  const std::string inertial = cdtest::slurp(c / "inertial/manifest.toml");
  for (const char* kv : {"DIM = \"2\"", "N = \"60\"", "P = \"100\"", "SIZE_RATIO = \"2\"", "SIZE_DIST = \"uniform_area\"",
                         "PREP_SET = \"--set time.duration=0.002\""}) {
    EXPECT_NE(prep.find(std::string("\n") + kv + "\n"), std::string::npos) << kv << "\n" << prep;
    EXPECT_NE(inertial.find(std::string("\n") + kv + "\n"), std::string::npos) << kv << "\n" << inertial;
  }
  for (const char* kv : {"STRAIN = \"0.02\"", "SHEAR_TOL = \"\"", "INERTIAL_I = \"0.1\"", "builds = \""})
    EXPECT_NE(inertial.find(std::string("\n") + kv), std::string::npos) << kv << "\n" << inertial;
  const auto before = listing(c);

  // Another N: refused naming N, nothing run or written (the new I too).
  const cdtest::CmdResult n = make(c, "campaign-inertial N=80 STRAIN=0.02 PREP_SET='--set time.duration=0.002' "
                                      "INERTIAL_I='0.1 0.2'");
  EXPECT_EQ(n.code, 2) << n.out;
  EXPECT_NE(n.out.find("campaign folder " + c.string() + " (its samples, " + c.string() +
                       "/prep/) was made with N=60, you asked N=80: use CAMPAIGNS=<another folder> or remove " +
                       c.string()),
            std::string::npos)
      << n.out;
  // Another strain: the inertial campaign refuses, naming STRAIN.
  const cdtest::CmdResult s = make(c, "campaign-inertial N=60 STRAIN=0.05 " + kTiny);
  EXPECT_EQ(s.code, 2) << s.out;
  EXPECT_NE(s.out.find("campaign " + c.string() + "/inertial was made with STRAIN=0.02, you asked STRAIN=0.05"),
            std::string::npos)
      << s.out;
  // make -n refuses the same way.
  const cdtest::CmdResult dry = make(c, "-n campaign-inertial N=80 STRAIN=0.02 " + kTiny);
  EXPECT_EQ(dry.code, 2) << dry.out;
  EXPECT_NE(dry.out.find("was made with N=60, you asked N=80"), std::string::npos) << dry.out;
  EXPECT_EQ(listing(c), before);

  // More values of I with the same parameters are more runs of the same
  // campaign: accepted (make -n: would run I = 0.2 only, writes nothing).
  const cdtest::CmdResult more = make(c, "-n campaign-inertial N=60 STRAIN=0.02 PREP_SET='--set time.duration=0.002' "
                                         "INERTIAL_I='0.1 0.2'");
  EXPECT_EQ(more.code, 0) << more.out;
  EXPECT_NE(more.out.find("--out " + c.string() + "/inertial/I_0.2 "), std::string::npos) << more.out;
  EXPECT_EQ(more.out.find("--out " + c.string() + "/inertial/I_0.1 "), std::string::npos) << more.out;
  EXPECT_EQ(listing(c), before);

  // The status: the sample and I = 0.1 done with their cost, I = 0.2 not started.
  const cdtest::CmdResult st = make(c, "campaign-status N=60 INERTIAL_I='0.1 0.2'");
  EXPECT_EQ(st.code, 0) << st.out;
  EXPECT_NE(st.out.find("  ns_0                 100 %    CPU "), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("  I_0.1                100 %    CPU "), std::string::npos) << st.out;
  EXPECT_NE(st.out.find(", 4 steps"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("  I_0.2                -        -"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("not started\n"), std::string::npos) << st.out;
  EXPECT_NE(st.out.find("2 done, 1 not started"), std::string::npos) << st.out;
}

namespace {

// The cdsim commands of a make -n output (continued lines joined) that
// write into `out_under`.
std::vector<std::string> commands(const std::string& made, const std::string& out_under) {
  std::vector<std::string> cmds;
  std::istringstream in(made);
  std::string joined;
  for (std::string line; std::getline(in, line);) {
    if (line.ends_with("\\")) {
      joined += line.substr(0, line.size() - 1);
      continue;
    }
    joined += line;
    if (joined.find("/cdsim ") != std::string::npos && joined.find("--out " + out_under) != std::string::npos)
      cmds.push_back(joined);
    joined.clear();
  }
  return cmds;
}

// What follows `--set key=` in a command, up to the next space.
std::string set_value(const std::string& cmd, const std::string& key) {
  const std::string k = "--set " + key + "=";
  const auto at = cmd.find(k);
  if (at == std::string::npos) return "";
  const auto from = at + k.size();
  return cmd.substr(from, cmd.find(' ', from) - from);
}

// Every key of a resolved scene printed by cdsim --print-scene, as
// section.key -> value.
std::map<std::string, std::string> printed_scene(const std::string& cmd) {
  const auto r = cdtest::run_command(std::string("cd ") + CDLAB_SOURCE_DIR + " && " + cmd + " --print-scene");
  EXPECT_EQ(r.code, 0) << cmd << "\n" << r.out;
  return cdtest::printed_keys(r.out);
}

// The mean packing fraction over the second half of a committed reference
// run (tests/data/regress*: cdsim at imposed pressure and I).
double reference_phi(const std::string& run) {
  std::istringstream in(cdtest::slurp(fs::path(CDLAB_TEST_DATA) / run / "series.csv"));
  std::string line;
  std::getline(in, line);
  int col = -1, k = 0;
  for (std::istringstream h(line); std::getline(h, line, ','); ++k)
    if (line == "packing_fraction") col = k;
  EXPECT_GE(col, 0) << run;
  std::vector<double> phi;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::string cell;
    for (int j = 0; j <= col; ++j) std::getline(r, cell, ',');
    phi.push_back(std::stod(cell));
  }
  double sum = 0;
  for (std::size_t i = phi.size() / 2; i < phi.size(); ++i) sum += phi[i];
  return sum / static_cast<double>(phi.size() - phi.size() / 2);
}

}  // namespace

// make campaign-volume, dry: one cdsim run per packing fraction of
// VOLUME_PHI into volume/phi_<phi>, each from the campaign's compacted
// sample (prep/ns_0, the rule campaign-inertial uses), at imposed volume
// with the rate given in units of 1/t_p (shear.rate_tp: the Makefile
// computes no rate and decides no setting), writing nothing. The defaults
// lie in the dense flow below jamming: between the packing fractions the
// committed reference campaigns measured at I = 0.3 and at their lowest I
// (2D: 0.01, 3D: 0.02; jamming lies above). And a volume point resolves to
// the settings of an inertial point at I = its nominal I, VOLUME_RATE_TP.
TEST(CampaignMake, VolumeSeriesDryRun) {
  struct Dim {
    const char* dim;
    const char* densest_ref;
    const char* loosest_ref;
    const char* prep;
  };
  for (const Dim& d : {Dim{"2", "regress/inertial/I_0.01", "regress/inertial/I_0.3", "configs/shear-prep.toml"},
                       Dim{"3", "regress3d/inertial/I_0.02", "regress3d/inertial/I_0.3", "configs/shear3-prep.toml"}}) {
    const fs::path c = cdtest::scratch_dir("test_campaign_make", std::string("volume") + d.dim);
    const cdtest::CmdResult dry = make(c, std::string("-n campaign-volume DIM=") + d.dim);
    ASSERT_EQ(dry.code, 0) << dry.out;
    EXPECT_TRUE(fs::is_empty(c)) << "make -n writes nothing";
    EXPECT_EQ(commands(dry.out, (c / "prep/ns_0 ").string()).size(), 1u) << dry.out;
    EXPECT_NE(dry.out.find(d.prep), std::string::npos) << dry.out;
    const auto runs = commands(dry.out, (c / "volume/phi_").string());
    ASSERT_GE(runs.size(), 3u) << dry.out;
    const double hi = reference_phi(d.densest_ref), lo = reference_phi(d.loosest_ref);
    std::set<std::string> phis;
    std::string densest;
    for (const std::string& cmd : runs) {
      const std::string phi = set_value(cmd, "shear.volume_fraction");
      ASSERT_FALSE(phi.empty()) << cmd;
      phis.insert(phi);
      EXPECT_NE(cmd.find("--out " + (c / "volume").string() + "/phi_" + phi + " "), std::string::npos) << cmd;
      EXPECT_EQ(set_value(cmd, "shear.control"), "'\"volume\"'") << cmd;
      EXPECT_EQ(set_value(cmd, "shear.start"), "'\"" + (c / "prep/ns_0/checkpoint.bin").string() + "\"'") << cmd;
      EXPECT_EQ(set_value(cmd, "shear.strain"), "2") << cmd;
      EXPECT_GT(std::stod(set_value(cmd, "shear.rate_tp")), 0) << cmd;
      EXPECT_EQ(cmd.find("shear.rate="), std::string::npos) << "no rate in 1/s computed by make: " << cmd;
      EXPECT_EQ(cmd.find("solver.tol"), std::string::npos) << "the Makefile decides no setting: " << cmd;
      EXPECT_GT(std::stod(phi), lo) << "DIM=" << d.dim << ": in the dense flow";
      EXPECT_LT(std::stod(phi), hi) << "DIM=" << d.dim << ": below jamming";
      if (densest.empty() || std::stod(phi) > std::stod(set_value(densest, "shear.volume_fraction"))) densest = cmd;
    }
    EXPECT_EQ(phis.size(), runs.size()) << "one run per packing fraction";

    // The run, resolved by cdsim: imposed volume, no imposed I, and the
    // settings of an inertial campaign point at I = rate_tp.
    const std::string rate_tp = set_value(densest, "shear.rate_tp");
    const auto v = printed_scene(densest);
    EXPECT_EQ(v.at("shear.control"), "\"volume\"");
    EXPECT_EQ(std::stod(v.at("shear.rate_tp")), std::stod(rate_tp));
    EXPECT_EQ(std::stod(v.at("shear.inertial_number")), 0.0);
    EXPECT_EQ(std::stod(v.at("shear.rate")), 0.0);
    const cdtest::CmdResult in =
        make(c, std::string("-n DIM=") + d.dim + " " + (c / "inertial/I_").string() + rate_tp + "/.done");
    ASSERT_EQ(in.code, 0) << in.out;
    const auto ic = commands(in.out, (c / "inertial/I_").string());
    ASSERT_EQ(ic.size(), 1u) << in.out;
    const auto p = printed_scene(ic[0]);
    for (const char* key : {"solver.tol", "solver.residual_tol", "shear.dt_tp", "contact.overlap_projection",
                            "solver.anderson", "solver.subspace"})
      EXPECT_EQ(v.at(key), p.at(key)) << "DIM=" << d.dim << " " << key;
  }
}
