#include "snapshot.hpp"

#include <fmt/core.h>
#include <vtkCellArray.h>
#include <vtkLogger.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <regex>

namespace fs = std::filesystem;

namespace cda {

double Contact::nx() const { return std::cos(theta); }
double Contact::ny() const { return std::sin(theta); }
double Contact::ln() const { return lx * nx() + ly * ny(); }
double Contact::lt() const { return -lx * ny() + ly * nx(); }

std::vector<cd::obs::Contact<2>> as_forces(const ContactSet& cs) {
  std::vector<cd::obs::Contact<2>> out;
  out.reserve(cs.size());
  for (const auto& c : cs)
    out.push_back(cd::obs::contact_2d(c.b1, c.b2, c.nx(), c.ny(), c.fn, c.ft, c.lx, c.ly));
  return out;
}

std::vector<cd::obs::Contact<3>> as_forces(const ContactSet3& cs) {
  std::vector<cd::obs::Contact<3>> out;
  out.reserve(cs.size());
  for (const auto& c : cs) out.push_back(c.c);
  return out;
}

ContactSet of_type(const ContactSet& cs, int type) {
  ContactSet out;
  for (const auto& c : cs)
    if (c.type == type) out.push_back(c);
  return out;
}

ContactSet merge_side_side(const ContactSet& cs) {
  ContactSet out;
  std::map<std::pair<int, int>, std::size_t> ss;  // (b1, b2) -> index in out
  for (const auto& c : cs) {
    if (c.type != 2) {
      out.push_back(c);
      continue;
    }
    const auto key = std::make_pair(c.b1, c.b2);
    const auto it = ss.find(key);
    if (it == ss.end()) {
      ss.emplace(key, out.size());
      out.push_back(c);
    } else {
      auto& m = out[it->second];
      m.fn += c.fn;
      m.ft += c.ft;
      m.status = std::max(m.status, c.status);  // sliding if either point slides
    }
  }
  return out;
}

const char* kind3_name(int kind) {
  static constexpr const char* names[kKinds3] = {"sphere",    "vertex-face", "edge-face",    "face-face",
                                                 "edge-edge", "sphere-edge", "sphere-vertex"};
  return kind >= 0 && kind < kKinds3 ? names[kind] : "unknown";
}

ContactSet3 merge_points3(const ContactSet3& cs) {
  ContactSet3 out;
  std::map<std::pair<int, int>, std::size_t> pairs;  // (b1, b2) -> index in out
  for (const auto& c : cs) {
    if (c.kind == 0) {
      out.push_back(c);
      continue;
    }
    const auto [it, first] = pairs.emplace(std::make_pair(c.c.b1, c.c.b2), out.size());
    if (first) {
      out.push_back(c);
      continue;
    }
    auto& m = out[it->second];
    m.c.fn += c.c.fn;
    for (int a = 0; a < 3; ++a) m.c.ft[a] += c.c.ft[a];
    m.status = std::max(m.status, c.status);
  }
  return out;
}

double area_in_band(const Particle& p, double lo, double hi) {
  if (!(hi > lo)) return 0.0;
  const double r = p.radius;
  if (p.nsides <= 0) {
    // the disk's area below the height t above its centre
    const auto below = [r](double t) {
      const double u = std::clamp(t / r, -1.0, 1.0);
      return r * r * (std::asin(u) + u * std::sqrt(1.0 - u * u) + 0.5 * std::numbers::pi);
    };
    return below(hi - p.y) - below(lo - p.y);
  }
  std::vector<std::array<double, 2>> poly;
  for (int k = 0; k < p.nsides; ++k) {
    const double a = p.angle + 2.0 * std::numbers::pi * k / p.nsides;
    poly.push_back({p.x + r * std::cos(a), p.y + r * std::sin(a)});
  }
  // Sutherland-Hodgman against y >= lo, then y <= hi (sign -1)
  for (const auto& [h, sign] : {std::pair{lo, 1.0}, std::pair{hi, -1.0}}) {
    std::vector<std::array<double, 2>> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const auto& a = poly[i];
      const auto& b = poly[(i + 1) % poly.size()];
      const double da = sign * (a[1] - h), db = sign * (b[1] - h);
      if (da >= 0) out.push_back(a);
      if ((da >= 0) != (db >= 0)) {
        const double t = da / (da - db);
        out.push_back({a[0] + t * (b[0] - a[0]), h});
      }
    }
    poly = std::move(out);
  }
  double twice = 0.0;  // the shoelace
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const auto& a = poly[i];
    const auto& b = poly[(i + 1) % poly.size()];
    twice += a[0] * b[1] - b[0] * a[1];
  }
  return 0.5 * std::abs(twice);
}

namespace {

// VTK's messages while a file is read: counted, the first kept. VTK 9 sends
// them through vtkLogger (to stderr by default, from the parser, the reader
// and the pipeline: pages for one damaged file).
struct Captured {
  int count = 0;
  std::string first;
};
void capture_message(void* user, const vtkLogger::Message& m) {
  auto* c = static_cast<Captured*>(user);
  if (c->count++ == 0 && m.message) c->first = m.message;
}

vtkSmartPointer<vtkPolyData> read_polydata(const std::string& path) {
  std::error_code ec;
  refuse_folder(path);
  if (!fs::is_regular_file(path, ec))
    throw InputError(fmt::format("snapshot '{}' does not exist", path));
  vtkNew<vtkXMLPolyDataReader> reader;
  if (!reader->CanReadFile(path.c_str()))
    throw InputError(fmt::format("'{}' is not a VTK XML PolyData file", path));
  reader->SetFileName(path.c_str());
  // VTK reports a damaged file through its output window (pages of
  // messages, from the parser, the reader and the pipeline): capture them
  // while reading and keep the first for our own one-line message.
  Captured capture;
  const vtkLogger::Verbosity stderr_level = vtkLogger::GetCurrentVerbosityCutoff();
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  vtkLogger::AddCallback("cdanalysis-read", capture_message, &capture, vtkLogger::VERBOSITY_WARNING);
  reader->Update();
  vtkLogger::RemoveCallback("cdanalysis-read");
  vtkLogger::SetStderrVerbosity(stderr_level);
  if (reader->GetErrorCode() != 0 || capture.count > 0) {
    std::string first = capture.first;
    if (const auto k = first.find("): "); k != std::string::npos) first = first.substr(k + 3);
    while (!first.empty() && (first.back() == '\n' || first.back() == ' ')) first.pop_back();
    throw InputError(fmt::format("cannot read '{}': damaged VTK file ({} messages; first: {})", path,
                                 std::max(capture.count, 1), first.empty() ? "none" : first));
  }
  vtkSmartPointer<vtkPolyData> pd = reader->GetOutput();
  // Every point and every numeric array must be finite.
  if (vtkPoints* pts = pd->GetPoints())
    for (vtkIdType i = 0; i < pts->GetNumberOfPoints(); ++i) {
      double x[3];
      pts->GetPoint(i, x);
      if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
        throw InputError(fmt::format("'{}': point {} is not finite", path, i));
    }
  for (vtkDataSetAttributes* attr : {static_cast<vtkDataSetAttributes*>(pd->GetPointData()),
                                     static_cast<vtkDataSetAttributes*>(pd->GetCellData())})
    for (int a = 0; a < attr->GetNumberOfArrays(); ++a)
      if (vtkDataArray* arr = attr->GetArray(a))
        for (vtkIdType i = 0; i < arr->GetNumberOfTuples(); ++i)
          for (int c = 0; c < arr->GetNumberOfComponents(); ++c)
            if (!std::isfinite(arr->GetComponent(i, c)))
              throw InputError(fmt::format("'{}': array '{}', tuple {}, component {} is {}", path,
                                           arr->GetName() ? arr->GetName() : "?", i, c,
                                           arr->GetComponent(i, c)));
  return pd;
}

vtkDataArray* need(vtkDataSetAttributes* attr, const char* name, int comps,
                   const std::string& path) {
  vtkDataArray* a = attr->GetArray(name);
  if (!a) throw InputError(fmt::format("'{}' has no array '{}'", path, name));
  if (a->GetNumberOfComponents() < comps)
    throw InputError(fmt::format("'{}': array '{}' has {} components, {} expected", path, name,
                                    a->GetNumberOfComponents(), comps));
  return a;
}

// The test writers' pieces (write_contacts, write_contacts3, write_particles).
vtkSmartPointer<vtkDoubleArray> darr(const char* name, int comps) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(comps);
  return vtkSmartPointer<vtkDoubleArray>(a.GetPointer());
}
vtkSmartPointer<vtkIntArray> iarr(const char* name) {
  vtkNew<vtkIntArray> a;
  a->SetName(name);
  return vtkSmartPointer<vtkIntArray>(a.GetPointer());
}
void write_polydata(const std::string& path, vtkPolyData* pd) {
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(path.c_str());
  w->SetInputData(pd);
  w->SetDataModeToAppended();
  w->EncodeAppendedDataOff();
  if (w->Write() != 1) throw InputError(fmt::format("cannot write '{}'", path));
}

}  // namespace

ContactSet read_contacts(const std::string& path) {
  auto pd = read_polydata(path);
  ContactSet cs;
  const vtkIdType n = pd->GetNumberOfCells();
  if (n == 0) return cs;
  auto* cd = pd->GetCellData();
  auto* fn = need(cd, "fn", 1, path);
  auto* ft = need(cd, "ft", 1, path);
  auto* normal = need(cd, "normal", 2, path);
  const auto refuse_3d = [&](const std::string& why) {
    return InputError(fmt::format("'{}' is a 3D contact snapshot ({}): a 3D run needs dimension = 3 in its "
                                  "scene.toml",
                                  path, why));
  };
  if (ft->GetNumberOfComponents() > 1) throw refuse_3d("ft has 3 components");
  if (normal->GetNumberOfComponents() >= 3)
    for (vtkIdType i = 0; i < n; ++i)
      if (normal->GetComponent(i, 2) != 0) throw refuse_3d(fmt::format("normal {} has a z component", i));
  auto* status = need(cd, "status", 1, path);
  auto* type = need(cd, "type", 1, path);
  auto* b1 = need(cd, "b1", 1, path);
  auto* b2 = need(cd, "b2", 1, path);
  vtkDataArray* branch = cd->GetArray("branch");
  cs.reserve(static_cast<std::size_t>(n));
  vtkNew<vtkIdList> ids;
  for (vtkIdType i = 0; i < n; ++i) {
    Contact c;
    const double* nv = normal->GetTuple(i);
    c.theta = std::atan2(nv[1], nv[0]);
    c.fn = fn->GetTuple1(i);
    c.ft = ft->GetTuple1(i);
    c.status = static_cast<int>(status->GetTuple1(i));
    c.type = static_cast<int>(type->GetTuple1(i));
    c.b1 = static_cast<int>(b1->GetTuple1(i));
    c.b2 = static_cast<int>(b2->GetTuple1(i));
    if (branch) {
      const double* l = branch->GetTuple(i);
      c.lx = l[0];
      c.ly = l[1];
    } else {
      pd->GetCellPoints(i, ids);
      if (ids->GetNumberOfIds() != 2)
        throw InputError(fmt::format("'{}': contact cell {} is not a line of 2 points", path, i));
      double p1[3], p2[3];
      pd->GetPoint(ids->GetId(0), p1);
      pd->GetPoint(ids->GetId(1), p2);
      c.lx = p2[0] - p1[0];
      c.ly = p2[1] - p1[1];
    }
    cs.push_back(c);
  }
  return cs;
}

ContactSet3 read_contacts3(const std::string& path) {
  auto pd = read_polydata(path);
  ContactSet3 cs;
  const vtkIdType n = pd->GetNumberOfCells();
  if (n == 0) return cs;
  auto* cd = pd->GetCellData();
  auto* fn = need(cd, "fn", 1, path);
  auto* ft = need(cd, "ft", 1, path);
  if (ft->GetNumberOfComponents() != 3 || cd->GetArray("type"))
    throw InputError(fmt::format("'{}' is a 2D contact snapshot (ft has {} component{}): its scene.toml "
                                 "should not say dimension = 3",
                                 path, ft->GetNumberOfComponents(), ft->GetNumberOfComponents() == 1 ? "" : "s"));
  auto* normal = need(cd, "normal", 3, path);
  auto* status = need(cd, "status", 1, path);
  auto* b1 = need(cd, "b1", 1, path);
  auto* b2 = need(cd, "b2", 1, path);
  vtkDataArray* branch = cd->GetArray("branch");
  vtkDataArray* kind = cd->GetArray("kind");  // absent before polyhedra: every row a sphere's
  cs.reserve(static_cast<std::size_t>(n));
  vtkNew<vtkIdList> ids;
  for (vtkIdType i = 0; i < n; ++i) {
    Contact3 c;
    if (kind) {
      const double k = kind->GetTuple1(i);
      if (!(k >= 0 && k < kKinds3) || k != std::floor(k))
        throw InputError(fmt::format("'{}': contact cell {} has kind {} (0 to {} expected)", path, i, k, kKinds3 - 1));
      c.kind = static_cast<int>(k);
    }
    const double* nv = normal->GetTuple(i);
    const double nn = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
    if (std::abs(nn - 1) > 1e-6)
      throw InputError(fmt::format("'{}': contact cell {} has a normal of length {} (unit expected)", path, i, nn));
    for (int a = 0; a < 3; ++a) c.c.n[a] = nv[a];
    c.c.fn = fn->GetTuple1(i);
    const double* t = ft->GetTuple(i);
    for (int a = 0; a < 3; ++a) c.c.ft[a] = t[a];
    c.status = static_cast<int>(status->GetTuple1(i));
    c.c.b1 = static_cast<std::int32_t>(b1->GetTuple1(i));
    c.c.b2 = static_cast<std::int32_t>(b2->GetTuple1(i));
    if (branch && branch->GetNumberOfComponents() >= 3) {
      const double* l = branch->GetTuple(i);
      for (int a = 0; a < 3; ++a) c.c.l[a] = l[a];
    } else {
      pd->GetCellPoints(i, ids);
      if (ids->GetNumberOfIds() != 2)
        throw InputError(fmt::format("'{}': contact cell {} is not a line of 2 points", path, i));
      double p1[3], p2[3];
      pd->GetPoint(ids->GetId(0), p1);
      pd->GetPoint(ids->GetId(1), p2);
      for (int a = 0; a < 3; ++a) c.c.l[a] = p2[a] - p1[a];
    }
    cs.push_back(c);
  }
  return cs;
}

std::optional<std::string> companion_snapshot(const std::string& snapshot, const std::string& stem) {
  const std::filesystem::path f(snapshot);
  const std::string name = f.filename().string();
  const auto us = name.rfind('_');
  if (us == std::string::npos) return std::nullopt;
  const std::string p = (f.parent_path() / (stem + name.substr(us))).string();
  std::error_code ec;
  if (!std::filesystem::exists(p, ec)) return std::nullopt;
  return p;
}

ParticleSet read_polyhedra(const std::string& path) {
  auto pd = read_polydata(path);
  ParticleSet ps;
  const vtkIdType n = pd->GetNumberOfCells();
  if (n == 0) return ps;
  auto* cd = pd->GetCellData();
  auto* id = need(cd, "id", 1, path);
  auto* radius = need(cd, "radius", 1, path);
  auto* centre = need(cd, "centre", 3, path);
  vtkDataArray* vel = cd->GetArray("velocity");
  std::map<int, std::size_t> seen;
  for (vtkIdType i = 0; i < n; ++i) {
    const int b = static_cast<int>(id->GetTuple1(i));
    if (!seen.emplace(b, ps.size()).second) continue;
    Particle p;
    p.id = b;
    const double* x = centre->GetTuple(i);
    p.x = x[0];
    p.y = x[1];
    p.z = x[2];
    p.radius = radius->GetTuple1(i);
    if (vel && vel->GetNumberOfComponents() >= 3) {
      p.vx = vel->GetComponent(i, 0);
      p.vy = vel->GetComponent(i, 1);
      p.vz = vel->GetComponent(i, 2);
    }
    ps.push_back(p);
  }
  return ps;
}

std::map<int, std::vector<std::array<double, 2>>> polyhedra_sections(const std::string& path, double z0) {
  auto pd = read_polydata(path);
  std::map<int, std::vector<std::array<double, 2>>> out;
  const vtkIdType n = pd->GetNumberOfCells();
  if (n == 0) return out;
  auto* id = need(pd->GetCellData(), "id", 1, path);
  vtkNew<vtkIdList> loop;
  for (vtkIdType c = 0; c < n; ++c) {
    pd->GetCellPoints(c, loop);
    const vtkIdType m = loop->GetNumberOfIds();
    for (vtkIdType k = 0; k < m; ++k) {
      // Each edge is on two faces: taken once, from a to b with a < b.
      const vtkIdType ia = loop->GetId(k), ib = loop->GetId((k + 1) % m);
      if (ia > ib) continue;
      double a[3], b[3];
      pd->GetPoint(ia, a);
      pd->GetPoint(ib, b);
      if ((a[2] < z0) == (b[2] < z0)) continue;
      const double u = (z0 - a[2]) / (b[2] - a[2]);
      out[static_cast<int>(id->GetTuple1(c))].push_back({a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])});
    }
  }
  for (auto& [body, pts] : out) {
    double cx = 0, cy = 0;
    for (const auto& q : pts) cx += q[0], cy += q[1];
    cx /= static_cast<double>(pts.size());
    cy /= static_cast<double>(pts.size());
    std::sort(pts.begin(), pts.end(), [&](const auto& p, const auto& q) {
      return std::atan2(p[1] - cy, p[0] - cx) < std::atan2(q[1] - cy, q[0] - cx);
    });
  }
  return out;
}

ParticleSet read_particles(const std::string& path) {
  auto pd = read_polydata(path);
  ParticleSet ps;
  const vtkIdType n = pd->GetNumberOfPoints();
  if (n == 0) return ps;
  auto* pdat = pd->GetPointData();
  auto* id = need(pdat, "id", 1, path);
  auto* radius = need(pdat, "radius", 1, path);
  vtkDataArray* vel = pdat->GetArray("velocity");
  vtkDataArray* omega = pdat->GetArray("omega");
  vtkDataArray* angle = pdat->GetArray("angle");
  vtkDataArray* mass = pdat->GetArray("mass");
  vtkDataArray* nsides = pdat->GetArray("nsides");
  for (vtkIdType i = 0; i < n; ++i) {
    Particle p;
    double x[3];
    pd->GetPoint(i, x);
    p.x = x[0];
    p.y = x[1];
    p.z = x[2];
    p.id = static_cast<int>(id->GetTuple1(i));
    p.radius = radius->GetTuple1(i);
    if (vel) {
      p.vx = vel->GetComponent(i, 0);
      p.vy = vel->GetComponent(i, 1);
      if (vel->GetNumberOfComponents() >= 3) p.vz = vel->GetComponent(i, 2);
    }
    if (omega && omega->GetNumberOfComponents() == 1) p.omega = omega->GetTuple1(i);  // 2D: a scalar
    if (angle) p.angle = angle->GetTuple1(i);
    if (mass) p.mass = mass->GetTuple1(i);
    p.nsides = nsides ? static_cast<int>(nsides->GetTuple1(i)) : -1;
    ps.push_back(p);
  }
  return ps;
}

void write_contacts(const std::string& path, const ContactSet& cs, const ParticleSet& centres,
                    bool with_branch) {
  std::map<int, const Particle*> by_id;
  for (const auto& p : centres) by_id[p.id] = &p;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();  // float32 would cost 1e-7 relative on branch vectors
  vtkNew<vtkCellArray> lines;
  auto fn = darr("fn", 1), ft = darr("ft", 1), force = darr("force", 3), normal = darr("normal", 3),
       gap = darr("gap", 1), branch = darr("branch", 3);
  auto status = iarr("status"), type = iarr("type"), b1 = iarr("b1"), b2 = iarr("b2");
  for (const auto& c : cs) {
    double x1 = 0, y1 = 0;
    if (auto it = by_id.find(c.b1); it != by_id.end()) {
      x1 = it->second->x;
      y1 = it->second->y;
    }
    const vtkIdType i1 = pts->InsertNextPoint(x1, y1, 0);
    const vtkIdType i2 = pts->InsertNextPoint(x1 + c.lx, y1 + c.ly, 0);
    const vtkIdType line[2] = {i1, i2};
    lines->InsertNextCell(2, line);
    const double nx = c.nx(), ny = c.ny();
    fn->InsertNextValue(c.fn);
    ft->InsertNextValue(c.ft);
    force->InsertNextTuple3(c.fn * nx - c.ft * ny, c.fn * ny + c.ft * nx, 0);
    normal->InsertNextTuple3(nx, ny, 0);
    gap->InsertNextValue(0);
    branch->InsertNextTuple3(c.lx, c.ly, 0);
    status->InsertNextValue(c.status);
    type->InsertNextValue(c.type);
    b1->InsertNextValue(c.b1);
    b2->InsertNextValue(c.b2);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  for (auto& a : {fn, ft, force, normal, gap}) pd->GetCellData()->AddArray(a);
  if (with_branch) pd->GetCellData()->AddArray(branch);
  for (auto& a : {status, type, b1, b2}) pd->GetCellData()->AddArray(a);
  write_polydata(path, pd);
}

void write_contacts3(const std::string& path, const ContactSet3& cs, const ParticleSet& centres) {
  std::map<int, const Particle*> by_id;
  for (const auto& p : centres) by_id[p.id] = &p;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  auto fn = darr("fn", 1), ft = darr("ft", 3), force = darr("force", 3), normal = darr("normal", 3),
       gap = darr("gap", 1);
  auto status = iarr("status"), b1 = iarr("b1"), b2 = iarr("b2"), kind = iarr("kind");
  const bool kinds = std::any_of(cs.begin(), cs.end(), [](const Contact3& k) { return k.kind != 0; });
  for (const auto& k : cs) {
    const auto& c = k.c;
    double x2[3] = {0, 0, 0};
    if (auto it = by_id.find(c.b2); it != by_id.end()) {
      x2[0] = it->second->x;
      x2[1] = it->second->y;
      x2[2] = it->second->z;
    }
    const vtkIdType i1 = pts->InsertNextPoint(x2[0] - c.l[0], x2[1] - c.l[1], x2[2] - c.l[2]);
    const vtkIdType i2 = pts->InsertNextPoint(x2);
    const vtkIdType line[2] = {i1, i2};
    lines->InsertNextCell(2, line);
    const auto f = c.force();
    fn->InsertNextValue(c.fn);
    ft->InsertNextTuple3(c.ft[0], c.ft[1], c.ft[2]);
    force->InsertNextTuple3(f[0], f[1], f[2]);
    normal->InsertNextTuple3(c.n[0], c.n[1], c.n[2]);
    gap->InsertNextValue(0);
    status->InsertNextValue(k.status);
    b1->InsertNextValue(c.b1);
    b2->InsertNextValue(c.b2);
    kind->InsertNextValue(k.kind);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  for (auto& a : {fn, ft, force, normal, gap}) pd->GetCellData()->AddArray(a);
  for (auto& a : {status, b1, b2}) pd->GetCellData()->AddArray(a);
  if (kinds) pd->GetCellData()->AddArray(kind);
  write_polydata(path, pd);
}

void write_particles(const std::string& path, const ParticleSet& ps) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();  // float32 would cost 1e-7 relative on branch vectors
  vtkNew<vtkIntArray> id, nsides;
  id->SetName("id");
  nsides->SetName("nsides");
  vtkNew<vtkDoubleArray> radius, vel, omega, angle, mass;
  radius->SetName("radius");
  vel->SetName("velocity");
  vel->SetNumberOfComponents(3);
  omega->SetName("omega");
  angle->SetName("angle");
  mass->SetName("mass");
  for (const auto& p : ps) {
    pts->InsertNextPoint(p.x, p.y, p.z);
    id->InsertNextValue(p.id);
    nsides->InsertNextValue(p.nsides < 0 ? 0 : p.nsides);
    radius->InsertNextValue(p.radius);
    vel->InsertNextTuple3(p.vx, p.vy, p.vz);
    omega->InsertNextValue(p.omega);
    angle->InsertNextValue(p.angle);
    mass->InsertNextValue(p.mass);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->GetPointData()->AddArray(id);
  pd->GetPointData()->AddArray(nsides);
  for (vtkDataArray* a : {static_cast<vtkDataArray*>(radius), static_cast<vtkDataArray*>(vel),
                          static_cast<vtkDataArray*>(omega), static_cast<vtkDataArray*>(angle),
                          static_cast<vtkDataArray*>(mass)})
    pd->GetPointData()->AddArray(a);
  write_polydata(path, pd);
}

std::vector<std::string> list_snapshots(const std::string& run_dir, const std::string& prefix) {
  std::error_code ec;
  if (!fs::is_directory(run_dir, ec))
    throw InputError(fmt::format("run folder '{}' does not exist", run_dir));
  const std::regex re(prefix + R"(_(\d+)\.vtp)");
  std::vector<std::pair<long, std::string>> found;
  for (const auto& e : fs::directory_iterator(run_dir)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, m, re)) found.emplace_back(std::stol(m[1].str()), e.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& f : found) out.push_back(f.second);
  return out;
}

std::string snapshot_path(const std::string& run_dir, const std::string& prefix, int k) {
  const auto all = list_snapshots(run_dir, prefix);
  if (all.empty())
    throw InputError(fmt::format("run folder '{}' has no {}_NNNNN.vtp snapshot", run_dir, prefix));
  const long n = static_cast<long>(all.size());
  const long i = k < 0 ? n + k : k;
  if (i < 0 || i >= n)
    throw InputError(fmt::format("run folder '{}' has {} {} snapshots; snapshot {} does not exist",
                                    run_dir, n, prefix, k));
  return all[static_cast<std::size_t>(i)];
}

}  // namespace cda
