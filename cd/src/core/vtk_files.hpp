// VTK files of both engines: one .vtp written atomically (a temporary name,
// then renamed, so ParaView never opens a partial file), the .pvd
// collection that lists a stem's frames with their times, and the two
// pieces every snapshot writer builds its arrays with.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include <vtkFieldData.h>
#include <vtkNew.h>

class vtkPolyData;

namespace cd {

// A data array named `name` of n tuples of comps components.
template <class A>
vtkNew<A> make_array(const char* name, int comps, vtkIdType n) {
  vtkNew<A> a;
  a->SetName(name);
  a->SetNumberOfComponents(comps);
  a->SetNumberOfTuples(n);
  return a;
}

// Adds the arrays to fd (a point or cell data), in this order.
template <class... A>
void add_arrays(vtkFieldData* fd, A&... arrays) {
  (fd->AddArray(arrays), ...);
}

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
