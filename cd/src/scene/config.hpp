// Scene files: TOML in, Scene out. Every parameter is bound once, in one
// table (config.cpp), to its section.key, its default (the Scene member's
// initialiser), its unit, its rule and its documentation; parsing, the
// resolved scene.toml, `cdsim --help-scene` and docs/scene-parameters.md
// (made from it by `make scene-doc`) all come from that table.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

#include "scene.hpp"

namespace cd {

// A scene error: the message names the file, the position (line:column when
// known), the key, and the rule broken (or the closest valid key).
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Reads a scene file and applies `section.key=value` overrides (TOML value
// syntax: numbers, true/false, "strings", [arrays]). Throws ConfigError.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// Parses scene text (path only names it in messages).
Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides = {});

// The resolved scene: every parameter with its value, as TOML that
// load_scene reads back to the same Scene.
std::string resolved_toml(const Scene& s);

// The same without the header and comments: the values alone, what a
// checkpoint's scene key hashes (core/run_plan.hpp), so that a change of
// documentation does not orphan the checkpoints of runs in progress.
std::string resolved_values(const Scene& s);

// Markdown table of every parameter: key, default, unit, rule, meaning.
std::string parameter_table_markdown();

// The same for a terminal: one line per key (key, default and unit, rule,
// aligned), its meaning wrapped below it, a blank line between sections.
std::string parameter_table_text();

}  // namespace cd
