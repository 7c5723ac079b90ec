#include "output.hpp"

#include "polygon.hpp"
#include "vtk_files.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataWriter.h>

namespace cd {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Snapshots

namespace {

vtkSmartPointer<vtkPolyData> particles(const World& w) {
  const Bodies& b = w.bodies;
  vtkIdType n = 0;
  for (std::size_t i = 0; i < b.size(); ++i) n += b.is_dynamic(i);

  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n);
  vtkNew<vtkCellArray> verts;
  auto id = make_array<vtkIntArray>("id", 1, n);
  auto radius = make_array<vtkDoubleArray>("radius", 1, n);
  auto vel = make_array<vtkDoubleArray>("velocity", 3, n);
  auto omega = make_array<vtkDoubleArray>("omega", 1, n);
  auto angle = make_array<vtkDoubleArray>("angle", 1, n);
  auto mass = make_array<vtkDoubleArray>("mass", 1, n);
  auto nsides = make_array<vtkIntArray>("nsides", 1, n);
  vtkIdType k = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (!b.is_dynamic(i)) continue;
    pts->SetPoint(k, b.pos[i].x(), b.pos[i].y(), 0.0);
    verts->InsertNextCell(1, &k);
    id->SetValue(k, static_cast<int>(i));
    radius->SetValue(k, b.radius[i]);
    vel->SetTuple3(k, b.vel[i].vx, b.vel[i].vy, 0.0);
    omega->SetValue(k, b.vel[i].w);
    angle->SetValue(k, b.angle[i]);
    mass->SetValue(k, b.mass[i]);
    nsides->SetValue(k, b.nsides[i]);
    ++k;
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetVerts(verts);
  add_arrays(pd->GetPointData(), id, radius, vel, omega, angle, mass, nsides);
  return pd;
}

// True outlines: one polygon cell per particle (a regular polygon's own
// vertices; a disk drawn as a 36-gon), so ParaView shows hexagons as
// hexagons, turned by their angle, with no glyph set-up.
vtkSmartPointer<vtkPolyData> shapes(const World& w) {
  constexpr int kDiskSides = 36;
  const Bodies& b = w.bodies;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> polys;
  vtkNew<vtkIntArray> id, nsides;
  vtkNew<vtkDoubleArray> vel, omega;
  id->SetName("id");
  nsides->SetName("nsides");
  vel->SetName("velocity");
  vel->SetNumberOfComponents(3);
  omega->SetName("omega");
  std::vector<vtkIdType> cell;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (!b.is_dynamic(i)) continue;
    const int n = b.nsides[i] > 0 ? b.nsides[i] : kDiskSides;
    const PolyView P{b.pos[i], b.radius[i], b.angle[i], n};
    cell.resize(n);
    for (int k = 0; k < n; ++k) {
      const Vec2 v = P.vertex(k);
      cell[k] = pts->InsertNextPoint(v.x(), v.y(), 0.0);
    }
    polys->InsertNextCell(n, cell.data());
    id->InsertNextValue(static_cast<int>(i));
    nsides->InsertNextValue(b.nsides[i]);
    vel->InsertNextTuple3(b.vel[i].vx, b.vel[i].vy, 0.0);
    omega->InsertNextValue(b.vel[i].w);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  add_arrays(pd->GetCellData(), id, nsides, vel, omega);
  return pd;
}

vtkSmartPointer<vtkPolyData> contacts(const World& w) {
  const Bodies& b = w.bodies;
  const auto& rows = w.rows();
  const auto& infos = w.infos();
  const vtkIdType n = static_cast<vtkIdType>(rows.size());
  const double dt = w.params().dt;

  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(2 * n);
  vtkNew<vtkCellArray> lines;
  auto fn = make_array<vtkDoubleArray>("fn", 1, n);
  auto ft = make_array<vtkDoubleArray>("ft", 1, n);
  auto force = make_array<vtkDoubleArray>("force", 3, n);
  auto normal = make_array<vtkDoubleArray>("normal", 3, n);
  auto status = make_array<vtkUnsignedCharArray>("status", 1, n);
  auto type = make_array<vtkUnsignedCharArray>("type", 1, n);
  auto gap = make_array<vtkDoubleArray>("gap", 1, n);
  auto b1 = make_array<vtkIntArray>("b1", 1, n);
  auto b2 = make_array<vtkIntArray>("b2", 1, n);
  auto branch = make_array<vtkDoubleArray>("branch", 3, n);
  for (vtkIdType k = 0; k < n; ++k) {
    const ContactRow& r = rows[k];
    const ContactInfo& c = infos[k];
    // A wall's centre says nothing about where it is touched: draw the wall
    // end of the line at the contact point.
    auto end = [&](std::int32_t i) {
      return b.shape[i] == Shape::Segment ? Vec2(c.px, c.py) : b.pos[i];
    };
    // Across a periodic boundary the line goes to the image of body 2 that
    // is touched (x1 + branch), not across the cell.
    const Vec2 x1 = end(r.b1);
    const Vec2 x2 = (c.ix || c.iy) ? Vec2(x1 + Vec2(c.lx, c.ly)) : end(r.b2);
    pts->SetPoint(2 * k, x1.x(), x1.y(), 0.0);
    pts->SetPoint(2 * k + 1, x2.x(), x2.y(), 0.0);
    const vtkIdType ids[2] = {2 * k, 2 * k + 1};
    lines->InsertNextCell(2, ids);
    const double f_n = r.pn / dt, f_t = r.pt / dt;  // impulses over the step -> forces
    fn->SetValue(k, f_n);
    ft->SetValue(k, f_t);
    force->SetTuple3(k, f_n * r.nx - f_t * r.ny, f_n * r.ny + f_t * r.nx, 0.0);
    normal->SetTuple3(k, r.nx, r.ny, 0.0);
    status->SetValue(k, static_cast<unsigned char>(w.status(k)));
    type->SetValue(k, static_cast<unsigned char>(c.type));
    gap->SetValue(k, c.gap);
    b1->SetValue(k, r.b1);
    b2->SetValue(k, r.b2);
    branch->SetTuple3(k, c.lx, c.ly, 0.0);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetLines(lines);
  add_arrays(pd->GetCellData(), fn, ft, force, normal, status, type, gap, b1, b2, branch);
  return pd;
}

vtkSmartPointer<vtkPolyData> walls(const World& w) {
  const Bodies& b = w.bodies;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  vtkNew<vtkIntArray> id;
  id->SetName("id");
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.shape[i] != Shape::Segment) continue;
    Vec2 a, e;
    b.segment_ends(i, a, e);
    const vtkIdType ids[2] = {pts->InsertNextPoint(a.x(), a.y(), 0.0),
                              pts->InsertNextPoint(e.x(), e.y(), 0.0)};
    lines->InsertNextCell(2, ids);
    id->InsertNextValue(static_cast<int>(i));
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetLines(lines);
  pd->GetCellData()->AddArray(id);
  return pd;
}


}  // namespace

Snapshots::Snapshots(const std::string& dir) : dir_(dir) {}

void Snapshots::write(const World& w) {
  const std::string num = fmt::format("{:05d}", n_);
  const fs::path d(dir_);
  write_vtp(particles(w), (d / ("particles_" + num + ".vtp")).string());
  write_vtp(contacts(w), (d / ("contacts_" + num + ".vtp")).string());
  write_vtp(walls(w), (d / ("walls_" + num + ".vtp")).string());
  write_vtp(shapes(w), (d / ("shapes_" + num + ".vtp")).string());
  // The collections are rewritten only once all files of the frame are in
  // place, so they never list a missing file.
  if (n_ == 0) write_file_atomic((d / "view.py").string(), paraview_view_script());
  frames_.emplace_back(w.time, num);
  for (const char* stem : {"particles", "contacts", "walls", "shapes"})
    write_file_atomic((d / (std::string(stem) + ".pvd")).string(), pvd_collection(frames_, stem));
  ++n_;
}

}  // namespace cd
