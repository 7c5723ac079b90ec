// Campaigns know their parameters: make writes a manifest
// of what made a campaign folder, refuses, naming the difference, to add
// runs made with another N or STRAIN to it (also under make -n, writing
// nothing), accepts more values of I, and `make campaign-status` tells each
// run's state. A tiny real campaign: 60 disks, a 250-step preparation (not
// jammed: enough for make's bookkeeping), one shear run of 4 steps.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>

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
