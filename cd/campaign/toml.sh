# Sourced by the campaign scripts (status.sh, validation_table.sh).
# toml FILE SECTION KEY: "key" of [section] in a TOML file (scene.toml,
# summary.toml: "" for the top), its quotes removed; nothing if absent.
toml() {
  awk -v s="$2" -v k="$3" '/^\[/ { sec = substr($0, 2, index($0, "]") - 2); next }
    sec == s && $1 == k && $2 == "=" { v = $3; gsub(/"/, "", v); print v; exit }' "$1" 2>/dev/null
}
