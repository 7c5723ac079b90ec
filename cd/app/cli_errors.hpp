// Usage errors of the commands (cdsim, cdproblem), as the other messages are
// written: prefixed with the program's name, an unknown option with the
// closest known one, and where to find the options. CLI11's own text alone
// ("The following arguments were not expected: 2 --thread") names neither
// the program nor what was meant.
#pragma once
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "suggest.hpp"

namespace cd {

namespace detail {
// Every option name of the command and its subcommands ("--threads", "-q").
inline void option_names(const CLI::App& app, std::vector<std::string>& out) {
  for (const CLI::Option* o : app.get_options()) {
    for (const std::string& n : o->get_lnames()) out.push_back("--" + n);
    for (const std::string& n : o->get_snames()) out.push_back("-" + n);
  }
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    option_names(*sub, out);
}
}  // namespace detail

// The exit code of a parse error: --help prints and gives 0; any other is
// bad input (2), told on stderr as `prog: what was wrong`, one line each.
inline int cli_error(CLI::App& app, const CLI::ParseError& e, const std::string& prog) {
  if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
  std::vector<std::string> lines;
  if (dynamic_cast<const CLI::ExtrasError*>(&e)) {
    std::vector<std::string> names;
    detail::option_names(app, names);
    std::vector<std::string> words;
    for (const std::string& a : app.remaining(true))
      if (a.size() > 1 && a[0] == '-') {
        const std::string name = a.substr(0, a.find('='));
        lines.push_back("unknown option '" + name + "'" + did_you_mean(name, names));
      } else {
        words.push_back(a);
      }
    // Arguments after an unknown option are most likely its values: named
    // only when nothing else explains the error.
    if (lines.empty())
      for (const std::string& w : words) lines.push_back("unexpected argument '" + w + "'");
  }
  // A misspelt subcommand (cdproblem solv) is taken for a positional word.
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    commands.push_back(sub->get_name());
  if (lines.empty() && !commands.empty() && app.get_subcommands().empty())
    for (const std::string& a : app.remaining(true))
      if (a[0] != '-') {
        lines.push_back("unknown command '" + a + "'" + did_you_mean(a, commands));
        break;
      }
  if (lines.empty()) lines.push_back(e.what());
  for (const std::string& l : lines) std::cerr << prog << ": " << l << "\n";
  std::cerr << prog << ": see `" << prog << " --help` for the options\n";
  return 2;
}

}  // namespace cd
