// VTK files of both engines: one .vtp written atomically (a temporary name,
// then renamed, so ParaView never opens a partial file), and the .pvd
// collection that lists a stem's frames with their times.
#pragma once
#include <string>
#include <utility>
#include <vector>

class vtkPolyData;

namespace cd {

// Appended raw binary, zlib-compressed, 64-bit headers (no 4 GB limit on a
// data block). Throws WriteError naming `path` when it cannot be written.
void write_vtp(vtkPolyData* pd, const std::string& path);

// The .pvd text listing <stem>_<num>.vtp for every (time, num) of `frames`.
std::string pvd_collection(const std::vector<std::pair<double, std::string>>& frames,
                           const char* stem);

// The text of view.py, the ParaView script that each run folder with
// snapshots gets (written with the first snapshot): `paraview
// --script=view.py` opens the last snapshot's grains and force chains styled
// as the README's picture, `pvbatch view.py out.png` draws it. Generated at
// build time from docs/figures/chains.py and src/core/paraview/view_main.py.
const std::string& paraview_view_script();

}  // namespace cd
