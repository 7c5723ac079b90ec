#include "output3.hpp"

#include <filesystem>

#include <fmt/format.h>
#include <vtkCellArray.h>
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

  const std::string tmp = tmp_name(path);
  vtkNew<vtkXMLPolyDataWriter> wr;
  wr->SetInputData(pd);
  wr->SetFileName(tmp.c_str());
  wr->SetDataModeToAppended();
  wr->EncodeAppendedDataOff();
  wr->SetCompressorTypeToZLib();
  wr->SetHeaderTypeToUInt64();
  if (wr->Write() != 1 || wr->GetErrorCode() != 0) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw OutputError(fmt::format("cannot write '{}'", path));
  }
  rename_into_place(tmp, path);
}

}  // namespace cd
