"""Reading a cdsim run folder's TOML files from the bench scripts
(accuracy_shear3.py, peers/shear_table.py, peers/ladder_table.py): flat
key = value lines, without a TOML library (Debian 12's python3 has none)."""


def summary(path):
    """The key = value lines of a flat summary.toml: floats where they parse, else strings unquoted."""
    out = {}
    for line in open(path):
        line = line.split("#", 1)[0].strip()
        if "=" not in line:
            continue
        k, v = (x.strip() for x in line.split("=", 1))
        try:
            out[k] = float(v)
        except ValueError:
            out[k] = v.strip('"')
    return out


def scene_value(path, section, key):
    """The text of [section] key of a resolved scene.toml (quotes stripped), None if absent."""
    sec = ""
    for line in open(path):
        line = line.split("#", 1)[0].strip()
        if line.startswith("["):
            sec = line.strip("[]")
        elif sec == section and "=" in line and line.split("=", 1)[0].strip() == key:
            return line.split("=", 1)[1].strip().strip('"')
    return None
