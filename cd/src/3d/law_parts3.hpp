// The 3D contact law from named parts: what the sweep's row update solves
// (coupling3.hpp), chosen once per scene from a LawSpec3, never by a test
// inside the sweep.
//
// A law is Law3<Friction, Adhesion, Offsets>, one part of each kind:
//   friction  Frictionless, RoundCone (|s_t| <= mu s_n), OrthotropicCone
//             (|(s_t1/mu, s_t2/mu_b)| <= s_n; mu_b in the row's RowExtra3);
//   adhesion  NoAdhesion, Adhesion (s_n = r_n + a, a the row's adh);
//   offsets   NoOffsets, TangentialOffsets (constant terms b_t in the
//             tangential velocity the law sees: tangential restitution or
//             moving periodic images; in the row's RowExtra3).
// The normal part, rigid (Signorini) or compliant (a backward-Euler spring:
// the law on u + rho (r - r0)), acts on the velocity the law sees, not on
// the projection, so it is the coupling's (coupling3.hpp's BodyCouplingT3
// over RigidNormal / CompliantNormal, the same list below).
//
// LocalLaw3, the variant a ContactProblem3 carries, is generated from the
// lists of parts (every valid combination, once); choose_law3 picks its
// alternative from a LawSpec3. A new part is one struct here, one entry in
// its list, one value in LawSpec3 and law_name3's suffix; the sweep, the
// coupling and the .cdp3 files take it from there.
#pragma once
#include <algorithm>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <variant>

#include "contact3.hpp"
#include "law3.hpp"

namespace cd {

namespace law3 {

// ---- Friction --------------------------------------------------------------
// project: the local solve of the sphere block diag(W_nn, W_tt, W_tt) from
// the stick trial g (law3.hpp), a the adhesion shift (0 without).
struct Frictionless {
  static constexpr bool tangential = false;
  static constexpr bool orthotropic = false;
  static constexpr const char* name = "frictionless";
  static void project(const SweepRow3&, const RowExtra3*, const Vec3& g, double a, Vec3& out) {
    out = Vec3(std::max(-a, g[0]), 0.0, 0.0);
  }
};
struct RoundCone {
  static constexpr bool tangential = true;
  static constexpr bool orthotropic = false;
  static constexpr const char* name = "coulomb";
  static void project(const SweepRow3& r, const RowExtra3*, const Vec3& g, double a, Vec3& out) {
    project_sphere3(g, r.mu, a, out);
  }
};
struct OrthotropicCone {
  static constexpr bool tangential = true;
  static constexpr bool orthotropic = true;
  static constexpr const char* name = "coulomb";  // "+orthotropic" follows (law_name3)
  static void project(const SweepRow3& r, const RowExtra3* e, const Vec3& g, double a, Vec3& out) {
    project_sphere3_ortho(g, r.mu, e->mu_b, a, out);
  }
};

// ---- Adhesion --------------------------------------------------------------
struct NoAdhesion {
  static constexpr bool cohesive = false;
  static double shift(const SweepRow3&) { return 0.0; }
};
struct Adhesion {
  static constexpr bool cohesive = true;
  static double shift(const SweepRow3& r) { return r.adh; }
};

// ---- Tangential offsets ----------------------------------------------------
struct NoOffsets {
  static constexpr bool offsets = false;
};
struct TangentialOffsets {
  static constexpr bool offsets = true;
};

// ---- Normal (the coupling's part) -----------------------------------------
// Compliant: rho = 1/(k dt^2), rho_t = 1/(k_t dt^2) and r0, the impulses at
// the solve's start (the warm start), same index as the rows.
struct RigidNormal {
  static constexpr bool compliant = false;
};
struct CompliantNormal {
  static constexpr bool compliant = true;
  const Vec3* r0 = nullptr;
  double rho = 0.0, rho_t = 0.0;
};

}  // namespace law3

// A law of one part of each kind. Valid: the offsets act on the tangential
// velocity, so a frictionless law takes none (it reads no RowExtra3).
template <class Friction, class Adhesion, class Offsets>
struct Law3 {
  using friction_part = Friction;
  using adhesion_part = Adhesion;
  using offsets_part = Offsets;
  static constexpr bool valid = Friction::tangential || !Offsets::offsets;
  static constexpr bool tangential = Friction::tangential;
  static constexpr bool orthotropic = Friction::orthotropic;
  static constexpr bool offsets = Offsets::offsets;
  static constexpr bool cohesive = Adhesion::cohesive;
  static constexpr bool extra = offsets || orthotropic;  // reads RowExtra3
  static void solve(const SweepRow3& r, [[maybe_unused]] const RowExtra3* e, const Vec3& g, Vec3& out) {
    Friction::project(r, e, g, Adhesion::shift(r), out);
  }
};

namespace law3 {

// The lists of parts, in the order the variant lists them.
using Frictions = std::tuple<Frictionless, RoundCone, OrthotropicCone>;
using Adhesions = std::tuple<NoAdhesion, Adhesion>;
using OffsetsParts = std::tuple<NoOffsets, TangentialOffsets>;

// Every combination of one part of each kind, the valid ones kept, as a
// variant (declarations only: the types are all that is used).
template <class F, class A, class... O>
std::tuple<Law3<F, A, O>...> over_offsets(std::tuple<O...>);
template <class F, class... A>
auto over_adhesion(std::tuple<A...>) -> decltype(std::tuple_cat(over_offsets<F, A>(OffsetsParts{})...));
template <class... F>
auto over_friction(std::tuple<F...>) -> decltype(std::tuple_cat(over_adhesion<F>(Adhesions{})...));
template <class... L>
auto valid_only(std::tuple<L...>)
    -> decltype(std::tuple_cat(std::conditional_t<L::valid, std::tuple<L>, std::tuple<>>{}...));
template <class... L>
std::variant<L...> as_variant(std::tuple<L...>);

}  // namespace law3

// The laws a scene can need, one type each: the variant a ContactProblem3
// carries, resolved once per solve into a template instance of the sweep.
using LocalLaw3 = decltype(law3::as_variant(law3::valid_only(law3::over_friction(law3::Frictions{}))));
static_assert(std::variant_size_v<LocalLaw3> == 10, "2 frictionless laws (adhesion or not) and 2 x 2 x 2 with a cone");

// What a scene's law is made of (World3 fills it once; the overlap
// projection asks for the plain frictionless law).
enum class Friction3 { None, Round, Orthotropic };
struct LawSpec3 {
  Friction3 friction = Friction3::None;
  bool adhesion = false;
  bool offsets = false;  // only with friction
};

// The alternative of LocalLaw3 a spec names. A spec no law has (offsets
// without friction) is a programming error, refused by name.
inline LocalLaw3 choose_law3(const LawSpec3& s) {
  if (s.offsets && s.friction == Friction3::None)
    throw std::logic_error("choose_law3: tangential offsets need friction (a frictionless law reads none)");
  LocalLaw3 out;
  bool found = false;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (([&] {
       using L = std::variant_alternative_t<I, LocalLaw3>;
       const Friction3 f = !L::tangential ? Friction3::None : L::orthotropic ? Friction3::Orthotropic : Friction3::Round;
       if (!found && f == s.friction && L::cohesive == s.adhesion && L::offsets == s.offsets) {
         out = L{};
         found = true;
       }
     }()),
     ...);
  }(std::make_index_sequence<std::variant_size_v<LocalLaw3>>{});
  return out;
}

// The friction part's name, then "+adhesion", "+offsets", "+orthotropic"
// as the law has them (the .cdp3 files' law line).
inline std::string law_name3(const LocalLaw3& l) {
  return std::visit(
      [](auto x) {
        using L = decltype(x);
        std::string s = L::friction_part::name;
        if (L::cohesive) s += "+adhesion";
        if (L::offsets) s += "+offsets";
        if (L::orthotropic) s += "+orthotropic";
        return s;
      },
      l);
}

}  // namespace cd
