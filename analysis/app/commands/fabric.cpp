// cdanalysis fabric RUN: anisotropies, stress and connectivity of one
// contact snapshot (2D: Fourier and tensor estimates, polar plots; 3D: the
// spherical-harmonic forms of fabric3.hpp).
#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "analysis/app/command.hpp"
#include "analysis/src/report.hpp"
#include "analysis/src/scene_info.hpp"

namespace cda::cli {
namespace {

// z and rattlers of a fabric (2D and 3D), or why they are missing.
void print_connectivity(const std::optional<cda::Connectivity>& conn, const char* bodies) {
  if (!conn) {
    fmt::print("connect.   no {} snapshot next to the contacts: z not computed\n", bodies);
    return;
  }
  const auto& c = *conn;
  fmt::print("connect.   z {:.4f}  rattlers {} of {}  non-floating {:.4f}  P_c", c.z, c.rattlers, c.particles,
             c.non_floating);
  for (std::size_t i = 0; i < c.P.size(); ++i) fmt::print(" {}:{:.3f}", i, c.P[i]);
  fmt::print("\n");
}

void print_harmonics(const char* label, const Anisotropy& a) {
  fmt::print("{:<8} a_c {:.4f} ({:.1f} deg)  a_ln {:.4f}  a_lt {:.4f}  a_fn {:.4f} ({:.1f} deg)  "
             "a_ft {:.4f} ({:.1f} deg)  sum/2 {:.4f}\n",
             label, a.c.a(), a.c.theta() * 180 / M_PI, a.ln.a(), a.lt.a(), a.fn.a(),
             a.fn.theta() * 180 / M_PI, a.ft.a(), a.ft.theta() * 180 / M_PI, a.sum_half());
}

struct Opt {
  std::string run, out;
  int snapshot = -1, bins = 36;
  double volume = -1;
  double force_rel = cd::obs::kForceEpsRel;
};

// "force-bearing", and the threshold when it is not the series' own.
std::string bearing_label(const Opt& o) {
  if (o.force_rel == cd::obs::kForceEpsRel) return "force-bearing";
  return fmt::format("force-bearing: |f_n| + |f_t| > {:g} <|f_n|>", o.force_rel);
}

// Polyhedra: the contacts' kinds and what the face-face ones carry.
void print_kinds3(const RunFabric3& f) {
  fmt::print("kinds      face-face {:.4f}  edge-face {:.4f}  vertex-face {:.4f}  edge-edge {:.4f}",
             f.kind_share(Kind3::FaceFace), f.kind_share(Kind3::EdgeFace), f.kind_share(Kind3::VertexFace),
             f.kind_share(Kind3::EdgeEdge));
  for (const Kind3 k : {Kind3::Sphere, Kind3::SphereEdge, Kind3::SphereVertex})  // mixtures only
    if (f.by_kind[static_cast<std::size_t>(k)] > 0) fmt::print("  {} {:.4f}", kind3_name(static_cast<int>(k)), f.kind_share(k));
  fmt::print(" of the force-bearing contacts\n");
  fmt::print("face-face  carry q/p {:.4f} of the {:.4f}\n", f.q_over_p_face_face(), f.stress.q_over_p());
  for (const auto& [name, a] : {std::pair{"face-face", &f.aniso_face_face}, std::pair{"others", &f.aniso_other}}) {
    if (*a)
      fmt::print("{:<10} a_c {:.4f}  a_n {:.4f}  a_t {:.4f}\n", name, (*a)->a_c(), (*a)->a_n(), (*a)->a_t());
    else
      fmt::print("{:<10} no harmonics (too few contacts, or the forms do not fit them)\n", name);
  }
}

void fabric3(const Opt& o) {
  if (!o.out.empty())
    throw AnalysisError(fmt::format("fabric --out (polar plots of the angular profiles) is 2D only: '{}' is "
                                    "a 3D run (dimension = 3 in its scene.toml)", o.run));
  const auto f = run_fabric3(o.run, o.snapshot, o.volume, 0, 1e-4, o.force_rel);
  const auto pr = principal(f.stress.s);
  fmt::print("snapshot   {}\ncontacts   {} ({} {})\n", f.file, f.contacts, f.physical_contacts, bearing_label(o));
  fmt::print("stress     p {:.6g}  q {:.6g}  q/p {:.4f}  (q = (s1 - s3)/3)  q_vm/p {:.4f}  mu {:.4f}  "
             "skew {:.3g}{}\n",
             f.stress.p(), f.stress.q(), f.stress.q_over_p(), f.stress.q_vm() / f.stress.p(), f.stress.mu(),
             f.stress.skew(), f.has_volume ? "" : "  (times V: no --volume)");
  fmt::print("principal  s1 {:.6g} ({:.3f} {:.3f} {:.3f})  s2 {:.6g}  s3 {:.6g} ({:.3f} {:.3f} {:.3f})\n",
             pr.value[0], pr.dir[0][0], pr.dir[0][1], pr.dir[0][2], pr.value[1], pr.value[2], pr.dir[2][0],
             pr.dir[2][1], pr.dir[2][2]);
  fmt::print("fabric     <nn> xx {:.4f}  yy {:.4f}  zz {:.4f}  xy {:.4f}  xz {:.4f}  yz {:.4f}\n", f.fabric[0][0],
             f.fabric[1][1], f.fabric[2][2], f.fabric[0][1], f.fabric[0][2], f.fabric[1][2]);
  if (f.aniso) {
    const auto& a = *f.aniso;
    fmt::print("harmonics  a_c {:.4f}  a_n {:.4f}  a_t {:.4f}  <f> {:.6g}  ({} iterations)\n", a.a_c(), a.a_n(),
               a.a_t(), a.mean_f, a.iterations);
    fmt::print("check      q/p {:.4f} vs (2/5)(a_c + a_n + a_t) {:.4f}, with directions {:.4f}, on the stress "
               "axes {:.4f}\n",
               f.stress.q_over_p(), a.sum_2_5(), a.sum_2_5_tensor(), a.sum_2_5_on(f.stress));
    const auto& b = *f.branch;
    fmt::print("branch     a_ln {:.4f}  a_lt {:.4f}  <l> {:.6g}  (2/5)(a_c + a_n + a_t + a_ln + a_lt) {:.4f}  "
               "a_c of the branch directions {:.4f}\n",
               b.a_ln(), b.a_lt(), b.mean_l, a.sum_2_5() + 0.4 * (b.a_ln() + b.a_lt()), b.a_c_branch());
  } else {
    fmt::print("harmonics  none: {}\n", f.aniso_problem);
  }
  fmt::print("sliding    {:.4f} of force-bearing contacts (status flag)\n", f.sliding);
  if (f.polyhedra) print_kinds3(f);
  print_connectivity(f.connectivity, "spheres");
}

void fabric2(const Opt& o) {
  const auto f = run_fabric(o.run, o.snapshot, o.bins, o.volume, 0, 1e-4, o.force_rel);
  fmt::print("snapshot   {}\ncontacts   {} ({} physical, {})\n", f.file, f.contacts, f.physical_contacts,
             bearing_label(o));
  print_harmonics("fft", f.fft);
  print_harmonics("tensor", f.tensor);
  fmt::print("stress     p {:.6g}  q {:.6g}  q/p {:.4f}  theta_s {:.1f} deg  skew {:.3g}{}\n",
             f.stress.p(), f.stress.q(), f.stress.q_over_p(), f.stress.theta() * 180 / M_PI,
             f.stress.skew(), f.has_volume ? "" : "  (times V: no --volume)");
  fmt::print("check      q/p {:.4f} vs (sum a)/2 {:.4f} (fft), {:.4f} (tensor, with directions)\n",
             f.stress.q_over_p(), f.fft.sum_half(), f.tensor.sum_half_vector());
  fmt::print("sliding    {:.4f} of force-bearing contacts\n", f.sliding);
  fmt::print("fabric     <nn> xx {:.4f}  xy {:.4f}  yy {:.4f}\n", f.fabric[0][0], f.fabric[0][1],
             f.fabric[1][1]);
  if (f.sv) print_harmonics("sv", *f.sv);
  if (f.ss) print_harmonics("ss", *f.ss);
  if (f.sv_stress) fmt::print("sv stress  p {:.6g} q {:.6g}\n", f.sv_stress->p(), f.sv_stress->q());
  if (f.ss_stress) fmt::print("ss stress  p {:.6g} q {:.6g}\n", f.ss_stress->p(), f.ss_stress->q());
  print_connectivity(f.connectivity, "particles");
  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    if (!plot_polar(o.out, "polar", f)) fmt::print(stderr, "warning: gnuplot failed; scripts in {}\n", o.out);
  }
}

}  // namespace

Handler fabric(CLI::App& sub) {
  auto o = std::make_shared<Opt>();
  sub.add_option("run", o->run, "run folder (holding contacts_NNNNN.vtp)")->required();
  sub.add_option("--snapshot", o->snapshot, "snapshot index (negative: from the end)")->capture_default_str();
  sub.add_option("--bins", o->bins, "angular bins over [0, pi) (2D; 3D runs use the tensors)")
      ->check(CLI::Range(4, 36000))
      ->capture_default_str();
  sub.add_option("--volume", o->volume, "volume (area) V for the stress, > 0; default: stress times V")
      ->check(positive_number());
  sub.add_option("--out", o->out, "folder for the angular profiles and polar plots");
  sub.add_option("--force-threshold", o->force_rel,
                 "a contact bears force (counts in z, the fabric and the anisotropies) when |f_n| + |f_t| "
                 "exceeds this times the snapshot's mean |f_n|; the default is the series' z. A larger "
                 "value leaves the weak contacts out (docs/analysis.md)")
      ->check(positive_number())
      ->capture_default_str();
  return [o] {
    if (run_dimension(o->run) == 3) fabric3(*o);
    else fabric2(*o);
    return 0;
  };
}

}  // namespace cda::cli
