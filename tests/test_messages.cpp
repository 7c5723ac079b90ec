// The messages a newcomer meets first: a misspelt scene key
// or command-line option gets the closest valid one, every message line
// starts with the program's name, a shear scene run before its preparation
// names the scene that makes the sample, and --help-scene reads in a
// terminal (the Markdown table behind --help-scene=md).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.hpp"
#include "suggest.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kCdsim = CDLAB_BINARY_DIR "/cd/cdsim";
const std::string kCdproblem = CDLAB_BINARY_DIR "/cd/cdproblem";
const std::string kCdanalysis = CDLAB_BINARY_DIR "/analysis/cdanalysis";
const std::string kConfigs = CDLAB_SOURCE_DIR "/configs";

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// Every line of a refusal starts with "prog: ", and the exit code is 2.
void expect_refusal(const std::string& prog, const std::string& args, const std::string& wanted) {
  const cdtest::CmdResult r =
      cdtest::run_command((prog == "cdsim" ? kCdsim : prog == "cdproblem" ? kCdproblem : kCdanalysis) + " " + args +
                          " </dev/null");
  EXPECT_EQ(r.code, 2) << prog << " " << args << "\n" << r.out;
  EXPECT_NE(r.out.find(wanted), std::string::npos) << prog << " " << args << "\n" << r.out;
  ASSERT_FALSE(r.out.empty());
  for (const std::string& l : lines_of(r.out))
    EXPECT_EQ(l.rfind(prog + ": ", 0), 0u) << prog << " " << args << ": a line without the program's name: " << l;
}

}  // namespace

TEST(DidYouMean, ClosestNameBySpellingOrAsAShortenedKey) {
  const std::vector<std::string> keys = {"solver.tol", "solver.threads", "solver.max_iter", "contact.mu"};
  EXPECT_EQ(cd::closest("solver.tolerance", keys), "solver.tol");  // spelled out (6 edits)
  EXPECT_EQ(cd::closest("solver.thread", keys), "solver.threads");
  EXPECT_EQ(cd::closest("solver.mu", keys), "contact.mu");  // by the last part
  EXPECT_EQ(cd::closest("contact.tolerance", keys), "");    // a prefix counts in its own section only
  EXPECT_EQ(cd::closest("particles.n", keys), "");
  const std::vector<std::string> opts = {"--threads", "--out", "--tol", "-q"};
  EXPECT_EQ(cd::closest("--thread", opts), "--threads");
  EXPECT_EQ(cd::closest("--tolerance", opts), "--tol");
  EXPECT_EQ(cd::closest("--t", opts), "");  // too short to be a word of one
  EXPECT_EQ(cd::did_you_mean("--ot", opts), " (did you mean '--out'?)");
}

TEST(Messages, UnknownSceneKeyInSetGetsTheClosestKey) {
  expect_refusal("cdsim", kConfigs + "/default.toml --set solver.tolerance=1e-3",
                 "--set solver.tolerance=1e-3: unknown key 'solver.tolerance' (did you mean 'solver.tol'?)");
}

TEST(Messages, UnknownOptionNamesProgramOptionAndHint) {
  expect_refusal("cdsim", kConfigs + "/default.toml --thread 2",
                 "cdsim: unknown option '--thread' (did you mean '--threads'?)");
  expect_refusal("cdsim", kConfigs + "/default.toml --thread=2", "unknown option '--thread' (did you mean");
  expect_refusal("cdsim", kConfigs + "/default.toml extra.toml", "cdsim: unexpected argument 'extra.toml'");
  expect_refusal("cdproblem", "solve x.dat --tolerance 1e-3",
                 "cdproblem: unknown option '--tolerance' (did you mean '--tol'?)");
  expect_refusal("cdproblem", "solv x.dat", "cdproblem: unknown command 'solv' (did you mean 'solve'?)");
}

TEST(Messages, EveryRefusalCarriesTheProgramsName) {
  expect_refusal("cdsim", "", "no scene file given");
  // A step count names what it wants, not the range of a double (309 digits).
  for (const char* bad : {"abc", "0", "1.5", "-3", "99999999999999999999"}) {
    expect_refusal("cdsim", kConfigs + "/default.toml --max-steps " + bad,
                   "cdsim: --max-steps: '" + std::string(bad) + "' is not a whole number >= 1");
    expect_refusal("cdsim", kConfigs + "/default.toml --dump-problem " + bad, "is not a whole number >= 1");
  }
  expect_refusal("cdsim", kConfigs + "/default.toml --progress nan", "--progress: must be a finite number");
  expect_refusal("cdsim", "--help-scene=html", "--help-scene");
  expect_refusal("cdsim", "/nonexistent/scene.toml", "cannot open scene file");
  expect_refusal("cdproblem", "", "subcommand");
  expect_refusal("cdproblem", "solve", "file");
  expect_refusal("cdproblem", "solve /nonexistent/x.dat", "/nonexistent/x.dat");
  // cdanalysis' usage errors (CLI11's) as its other messages, with the commands meant.
  expect_refusal("cdanalysis", "", "cdanalysis: A subcommand is required (`cdanalysis` takes one of: steady,");
  expect_refusal("cdanalysis", "fit", "(`cdanalysis fit` takes one of: mu-i,");
  expect_refusal("cdanalysis", "fit mu", "cdanalysis: unknown command 'mu' (`cdanalysis fit` takes one of: mu-i,");
  expect_refusal("cdanalysis", "fit mu-i run --bogus", "cdanalysis: see `cdanalysis fit mu-i --help` for the options");
  expect_refusal("cdanalysis", "draw x --width abc", "--width");
}

// Run from a folder without outputs/: the shipped shear scenes' samples
// (outputs/shear-prep/, outputs/shear3-prep/) are missing, and the message
// names the scene of that name beside the scene run. Nothing is written.
TEST(Messages, MissingStartSampleNamesTheSceneThatMakesIt) {
  const fs::path d = cdtest::scratch_dir("test_messages", "missing_start");
  for (const auto& [scene, prep] : {std::pair{"shear-inertial", "shear-prep"}, {"shear3-inertial", "shear3-prep"},
                                    {"shear-cohesive", "shear-prep"}}) {
    const std::string cmd = "cd " + d.string() + " && " + kCdsim + " " + kConfigs + "/" + scene + ".toml --out run";
    const cdtest::CmdResult r = cdtest::run_command(cmd);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("cannot read checkpoint 'outputs/" + std::string(prep) + "/checkpoint.bin'; no such file: " +
                         kConfigs + "/" + prep + ".toml makes it (run `cdsim " + kConfigs + "/" + prep + ".toml` first)"),
              std::string::npos)
        << r.out;
    EXPECT_FALSE(fs::exists(d / "run"));
  }
  // A sample elsewhere: no scene makes it by default; the message says what would.
  const cdtest::CmdResult r = cdtest::run_command(
      "cd " + d.string() + " && " + kCdsim + " " + kConfigs + "/shear-inertial.toml --out run --set 'shear.start=\"prep/checkpoint.bin\"'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("'prep/checkpoint.bin'; no such file: it is the checkpoint.bin of a preparation run"),
            std::string::npos)
      << r.out;
  // A sample that exists but is no checkpoint: the reader's message, no hint.
  fs::create_directories(d / "outputs/shear-prep");
  std::ofstream(d / "outputs/shear-prep/checkpoint.bin") << "not a checkpoint";
  const cdtest::CmdResult bad =
      cdtest::run_command("cd " + d.string() + " && " + kCdsim + " " + kConfigs + "/shear-inertial.toml --out run");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find("is not a cdlab checkpoint"), std::string::npos) << bad.out;
  EXPECT_EQ(bad.out.find("no such file"), std::string::npos) << bad.out;
}

// Plain text by default: each key's line has its default in one column, its
// meaning is wrapped below it within 80 columns; the same keys as the
// Markdown table; a list's default as written ([0], not [0.0]) and no rule
// text like "a list of 3 or 3 numbers".
TEST(HelpScene, TextIsAlignedWrappedAndHasEveryKeyOfTheTable) {
  const cdtest::CmdResult text = cdtest::run_command(kCdsim + " --help-scene");
  const cdtest::CmdResult md = cdtest::run_command(kCdsim + " --help-scene=md");
  ASSERT_EQ(text.code, 0) << text.out;
  ASSERT_EQ(md.code, 0) << md.out;
  ASSERT_EQ(md.out.rfind("| key | default | unit | rule | meaning |\n", 0), 0u) << md.out.substr(0, 200);

  std::set<std::string> md_keys, text_keys;
  for (const std::string& l : lines_of(md.out))
    if (l.rfind("| `", 0) == 0) md_keys.insert(l.substr(3, l.find('`', 3) - 3));
  std::set<std::size_t> value_columns;
  for (const std::string& l : lines_of(text.out)) {
    if (l.empty()) continue;
    if (l[0] == ' ') {
      EXPECT_LE(l.size(), 80u) << l;
      continue;
    }
    const std::size_t key_end = l.find(' ');
    text_keys.insert(l.substr(0, key_end));
    value_columns.insert(l.find_first_not_of(' ', key_end));
    if (l.rfind("particles.nsides ", 0) == 0) {
      EXPECT_NE(l.find(" [0] "), std::string::npos) << l;
    }
    if (l.rfind("contact.axis_a ", 0) == 0) {
      EXPECT_NE(l.find("a list of 3 numbers"), std::string::npos) << l;
    }
  }
  EXPECT_EQ(text_keys, md_keys);
  EXPECT_GT(md_keys.size(), 60u);
  EXPECT_EQ(value_columns.size(), 1u) << "the defaults do not start in one column";
  for (const std::string& out : {text.out, md.out}) {
    EXPECT_EQ(out.find("3 or 3"), std::string::npos);
    EXPECT_EQ(out.find("[0.0]"), std::string::npos);
  }
  EXPECT_NE(md.out.find("| `particles.nsides` | `[0]` |"), std::string::npos);
}

// A campaign run passes output.quiet (no terminal progress line) and
// --progress: whole lines on stdout naming the folder, step and ETA
// (default.toml: dt = 2e-4 s, so 0.01 s is 50 steps).
TEST(Messages, ProgressLinesInQuietRuns) {
  const fs::path d = cdtest::scratch_dir("test_messages", "progress");
  const cdtest::CmdResult r = cdtest::run_command(
      kCdsim + " " + kConfigs + "/default.toml --quiet --progress 0.001 --set time.duration=0.01 --out " +
      (d / "run").string());
  ASSERT_EQ(r.code, 0) << r.out;
  int lines = 0;
  for (const std::string& l : lines_of(r.out))
    if (l.rfind("cdsim: " + (d / "run").string() + ": ", 0) == 0) {
      ++lines;
      EXPECT_NE(l.find(" % (step "), std::string::npos) << l;
      EXPECT_NE(l.find(" of 50), "), std::string::npos) << l;
      EXPECT_NE(l.find(", ETA "), std::string::npos) << l;
    }
  EXPECT_GT(lines, 0) << r.out;
  EXPECT_EQ(r.out.find('\r'), std::string::npos);  // no terminal line in a log
}
