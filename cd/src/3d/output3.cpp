#include "output3.hpp"
#include "vtk_files.hpp"

#include <cmath>
#include <filesystem>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

#include "files.hpp"

namespace cd {

void write_spheres_vtp(const World3& w, const std::string& path) {
  const Bodies3& b = w.bodies;
  vtkIdType n = 0;
  for (std::size_t i = 0; i < b.size(); ++i) n += b.is_dynamic(i) && b.shape[i] == Shape3::Sphere;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n);
  vtkNew<vtkCellArray> verts;
  auto id = make_array<vtkIntArray>("id", 1, n);
  auto radius = make_array<vtkDoubleArray>("radius", 1, n);
  auto vel = make_array<vtkDoubleArray>("velocity", 3, n);
  auto omega = make_array<vtkDoubleArray>("omega", 3, n);
  auto orient = make_array<vtkDoubleArray>("orientation", 4, n);
  auto mass = make_array<vtkDoubleArray>("mass", 1, n);
  vtkIdType k = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (!b.is_dynamic(i) || b.shape[i] != Shape3::Sphere) continue;
    pts->SetPoint(k, b.pos[i].x(), b.pos[i].y(), b.pos[i].z());
    verts->InsertNextCell(1, &k);
    id->SetValue(k, static_cast<int>(i));
    radius->SetValue(k, b.radius[i]);
    vel->SetTuple3(k, b.vel[i].v.x(), b.vel[i].v.y(), b.vel[i].v.z());
    omega->SetTuple3(k, b.vel[i].w.x(), b.vel[i].w.y(), b.vel[i].w.z());
    orient->SetTuple4(k, b.orient[i].w(), b.orient[i].x(), b.orient[i].y(), b.orient[i].z());
    mass->SetValue(k, b.mass[i]);
    ++k;
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetVerts(verts);
  add_arrays(pd->GetPointData(), id, radius, vel, omega, orient, mass);
  pd->GetPointData()->SetActiveScalars("radius");

  write_vtp(pd, path);
}

int contact_status3(const SphereRow& r) {
  const double s = r.r[0] + r.adh;
  if (s <= 0.0) return 0;
  if (r.mu > 0.0 && std::hypot(r.r[1], r.r[2]) >= r.mu * s * (1.0 - 1e-9)) return 2;
  return 1;
}

void write_contacts3_vtp(const World3& w, const std::string& path) {
  const Bodies3& b = w.bodies;
  const auto& rows = w.rows();
  const auto& info = w.infos();
  const auto n = static_cast<vtkIdType>(rows.size());
  const double inv_dt = 1.0 / w.params().dt;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  auto fn = make_array<vtkDoubleArray>("fn", 1, n);
  auto ft = make_array<vtkDoubleArray>("ft", 3, n);
  auto force = make_array<vtkDoubleArray>("force", 3, n);
  auto normal = make_array<vtkDoubleArray>("normal", 3, n);
  auto gap = make_array<vtkDoubleArray>("gap", 1, n);
  auto status = make_array<vtkUnsignedCharArray>("status", 1, n);
  auto b1 = make_array<vtkIntArray>("b1", 1, n);
  auto b2 = make_array<vtkIntArray>("b2", 1, n);
  auto kind = make_array<vtkUnsignedCharArray>("kind", 1, n);
  auto branch = make_array<vtkDoubleArray>("branch", 3, n);
  vtkIdType ids[3];
  int np = 0;
  const auto point = [&](const Vec3& x) { ids[np++] = pts->InsertNextPoint(x.x(), x.y(), x.z()); };
  for (vtkIdType k = 0; k < n; ++k) {
    const SphereRow& r = rows[k];
    const ContactInfo3& c = info[k];
    np = 0;
    if (c.kind == 0) {  // spheres: centre to centre; a plane's branch ends at the sphere's foot on it
      const Vec3 x2 = b.pos[r.b2];
      point(x2 - c.branch);
      point(x2);
    } else {  // a polyhedron's point: the row's lever arms, through the point
      if (b.shape[r.b1] != Shape3::Plane) point(c.point - r.c1);
      point(c.point);
      point(c.point - r.c2);
    }
    lines->InsertNextCell(np, ids);
    const Vec3 t = (r.r[1] * r.t1 + r.r[2] * r.t2) * inv_dt;
    const Vec3 f = r.to_world(r.r) * inv_dt;
    fn->SetValue(k, r.r[0] * inv_dt);
    ft->SetTuple3(k, t.x(), t.y(), t.z());
    force->SetTuple3(k, f.x(), f.y(), f.z());
    normal->SetTuple3(k, r.n.x(), r.n.y(), r.n.z());
    gap->SetValue(k, c.gap);
    status->SetValue(k, static_cast<unsigned char>(contact_status3(r)));
    b1->SetValue(k, r.b1);
    b2->SetValue(k, r.b2);
    kind->SetValue(k, c.kind);
    branch->SetTuple3(k, c.branch.x(), c.branch.y(), c.branch.z());
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  add_arrays(pd->GetCellData(), fn, ft, force, normal, gap, status, b1, b2, kind, branch);
  pd->GetCellData()->SetActiveScalars("fn");
  write_vtp(pd, path);
}

void write_polyhedra_vtp(const World3& w, const std::string& path) {
  const Bodies3& b = w.bodies;
  vtkIdType n = 0;  // faces
  for (std::size_t i = 0; i < b.size(); ++i)
    if (b.shape[i] == Shape3::Polyhedron) n += static_cast<vtkIdType>(b.polyhedron(i).faces().size());
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> polys;
  auto id = make_array<vtkIntArray>("id", 1, n);
  auto shape = make_array<vtkIntArray>("shape_id", 1, n);
  auto radius = make_array<vtkDoubleArray>("radius", 1, n);
  auto vel = make_array<vtkDoubleArray>("velocity", 3, n);
  auto omega = make_array<vtkDoubleArray>("omega", 3, n);
  auto centre = make_array<vtkDoubleArray>("centre", 3, n);  // the body's centroid (the analysis' body list)
  std::vector<vtkIdType> cell;
  vtkIdType k = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (b.shape[i] != Shape3::Polyhedron) continue;
    const ConvexPolyhedron& s = b.polyhedron(i);
    const vtkIdType first = pts->GetNumberOfPoints();
    for (const Vec3& v : s.vertices()) {
      const Vec3 x = b.pos[i] + b.orient[i] * v;
      pts->InsertNextPoint(x.x(), x.y(), x.z());
    }
    for (const PolyFace& f : s.faces()) {
      cell.assign(f.loop.begin(), f.loop.end());
      for (vtkIdType& p : cell) p += first;
      polys->InsertNextCell(static_cast<vtkIdType>(cell.size()), cell.data());
      id->SetValue(k, static_cast<int>(i));
      shape->SetValue(k, b.shape_id[i]);
      radius->SetValue(k, b.radius[i]);
      vel->SetTuple3(k, b.vel[i].v.x(), b.vel[i].v.y(), b.vel[i].v.z());
      omega->SetTuple3(k, b.vel[i].w.x(), b.vel[i].w.y(), b.vel[i].w.z());
      centre->SetTuple3(k, b.pos[i].x(), b.pos[i].y(), b.pos[i].z());
      ++k;
    }
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  add_arrays(pd->GetCellData(), id, shape, radius, vel, omega, centre);
  write_vtp(pd, path);
}

void Snapshots3::write(const World3& w) {
  namespace fs = std::filesystem;
  const std::string num = fmt::format("{:05d}", n_);
  const fs::path d(dir_);
  write_spheres_vtp(w, (d / ("spheres_" + num + ".vtp")).string());
  write_contacts3_vtp(w, (d / ("contacts_" + num + ".vtp")).string());
  const bool poly = w.bodies.has_polyhedra();
  if (poly) write_polyhedra_vtp(w, (d / ("polyhedra_" + num + ".vtp")).string());
  // The collections are rewritten only once all files of the frame are in
  // place, so they never list a missing file.
  if (n_ == 0) write_file_atomic((d / "view.py").string(), paraview_view_script());
  frames_.emplace_back(w.time, num);
  for (const char* stem : {"spheres", "contacts", "polyhedra"})
    if (poly || std::string_view(stem) != "polyhedra")
      write_file_atomic((d / (std::string(stem) + ".pvd")).string(), pvd_collection(frames_, stem));
  ++n_;
}

}  // namespace cd
