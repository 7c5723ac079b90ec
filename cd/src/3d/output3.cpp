#include "output3.hpp"
#include "vtk_files.hpp"

#include <cmath>
#include <filesystem>

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
  auto array = [n](auto a, const char* name, int comps) {
    a->SetName(name);
    a->SetNumberOfComponents(comps);
    a->SetNumberOfTuples(n);
    return a;
  };
  vtkNew<vtkIntArray> id;
  vtkNew<vtkDoubleArray> radius, vel, omega, orient, mass;
  array(id.Get(), "id", 1);
  array(radius.Get(), "radius", 1);
  array(vel.Get(), "velocity", 3);
  array(omega.Get(), "omega", 3);
  array(orient.Get(), "orientation", 4);
  array(mass.Get(), "mass", 1);
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
  for (vtkDataArray* a : {static_cast<vtkDataArray*>(id.Get()), static_cast<vtkDataArray*>(radius.Get()),
                          static_cast<vtkDataArray*>(vel.Get()), static_cast<vtkDataArray*>(omega.Get()),
                          static_cast<vtkDataArray*>(orient.Get()), static_cast<vtkDataArray*>(mass.Get())})
    pd->GetPointData()->AddArray(a);
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
  pts->SetNumberOfPoints(2 * n);
  vtkNew<vtkCellArray> lines;
  auto array = [n](auto a, const char* name, int comps) {
    a->SetName(name);
    a->SetNumberOfComponents(comps);
    a->SetNumberOfTuples(n);
    return a;
  };
  vtkNew<vtkDoubleArray> fn, ft, force, normal, gap;
  vtkNew<vtkUnsignedCharArray> status;
  vtkNew<vtkIntArray> b1, b2;
  array(fn.Get(), "fn", 1);
  array(ft.Get(), "ft", 3);
  array(force.Get(), "force", 3);
  array(normal.Get(), "normal", 3);
  array(gap.Get(), "gap", 1);
  array(status.Get(), "status", 1);
  array(b1.Get(), "b1", 1);
  array(b2.Get(), "b2", 1);
  for (vtkIdType k = 0; k < n; ++k) {
    const SphereRow& r = rows[k];
    const ContactInfo3& c = info[k];
    const Vec3 x2 = b.pos[r.b2];
    const Vec3 x1 = x2 - c.branch;  // a plane's branch ends at the sphere's foot on it
    pts->SetPoint(2 * k, x1.x(), x1.y(), x1.z());
    pts->SetPoint(2 * k + 1, x2.x(), x2.y(), x2.z());
    const vtkIdType ids[2] = {2 * k, 2 * k + 1};
    lines->InsertNextCell(2, ids);
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
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  for (vtkDataArray* a : {static_cast<vtkDataArray*>(fn.Get()), static_cast<vtkDataArray*>(ft.Get()),
                          static_cast<vtkDataArray*>(force.Get()), static_cast<vtkDataArray*>(normal.Get()),
                          static_cast<vtkDataArray*>(gap.Get()), static_cast<vtkDataArray*>(status.Get()),
                          static_cast<vtkDataArray*>(b1.Get()), static_cast<vtkDataArray*>(b2.Get())})
    pd->GetCellData()->AddArray(a);
  pd->GetCellData()->SetActiveScalars("fn");
  write_vtp(pd, path);
}

void Snapshots3::write(const World3& w) {
  namespace fs = std::filesystem;
  const std::string num = fmt::format("{:05d}", n_);
  const fs::path d(dir_);
  write_spheres_vtp(w, (d / ("spheres_" + num + ".vtp")).string());
  write_contacts3_vtp(w, (d / ("contacts_" + num + ".vtp")).string());
  // The collections are rewritten only once all files of the frame are in
  // place, so they never list a missing file.
  if (n_ == 0) write_file_atomic((d / "view.py").string(), paraview_view_script());
  frames_.emplace_back(w.time, num);
  for (const char* stem : {"spheres", "contacts"})
    write_file_atomic((d / (std::string(stem) + ".pvd")).string(), pvd_collection(frames_, stem));
  ++n_;
}

}  // namespace cd
