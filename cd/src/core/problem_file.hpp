// The parts of cdlab's frozen-step files (.cdp for 2D, .cdp3 for 3D;
// 2d/contact_problem.hpp, 3d/contact_problem3.hpp) that do not depend on
// the dimension: the solver's parameters, the colouring and the boundary
// dofs, written and read the same way by both, every number a C hexadecimal
// float (read back to the same bits) and every malformed value reported by
// TextReader with the file and the line; and the opening of a problem file
// (these and Siconos' .dat) with an error that names it.
#pragma once
#include <climits>
#include <cstdint>
#include <fstream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "solver.hpp"
#include "text_reader.hpp"

namespace cd::problem_file {

// %a: hexadecimal floats, read back to the same bits by strtod.
inline std::string hex(double v) { return fmt::format("{:a}", v); }

// "tol T", "max_iter N", "min_parallel N" and, when > 0, "residual_tol R"
// , "anderson M" and "subspace K", and "stop_rows loaded" when the stop
// averages over the loaded rows (so that a replay takes the step's own solve).
inline void write_solver(std::ostream& out, const SolverParams& prm) {
  out << "tol " << hex(prm.tol) << "\nmax_iter " << prm.max_iter << "\nmin_parallel " << prm.min_parallel << "\n";
  if (prm.residual_tol > 0) out << "residual_tol " << hex(prm.residual_tol) << "\n";
  if (prm.anderson > 0) out << "anderson " << prm.anderson << "\n";
  if (prm.subspace > 0) out << "subspace " << prm.subspace << "\n";
  if (prm.stop_rows == StopRows::Loaded) out << "stop_rows loaded\n";
}

inline void read_solver(TextReader& rd, SolverParams& prm, const std::string& after) {
  rd.expect("tol", after);
  prm.tol = rd.non_negative("the tolerance", true);
  if (prm.tol > 1) rd.fail(fmt::format("the tolerance is {}, expected in (0, 1]", prm.tol));
  rd.expect("max_iter", "after tol");
  prm.max_iter = static_cast<int>(rd.integer("the sweep cap", 1, INT_MAX));
  rd.expect("min_parallel", "after max_iter");
  prm.min_parallel = static_cast<int>(rd.integer("the parallel threshold", 0, INT_MAX));
  if (rd.peek() == "residual_tol") {  // optional: written when > 0
    rd.token();
    prm.residual_tol = rd.non_negative("the residual tolerance", true);
  }
  if (rd.peek() == "anderson") {  // optional: written when > 0
    rd.token();
    prm.anderson = static_cast<int>(rd.integer("the Anderson memory", 1, kAndersonMaxMemory));
  }
  if (rd.peek() == "subspace") {  // optional: written when > 0
    rd.token();
    prm.subspace = static_cast<int>(rd.integer("the subspace correction's iterations", 1, 1000));
  }
  if (rd.peek() == "stop_rows") {  // optional: written when not every row
    rd.token();
    const std::string v(rd.token());
    if (v != "loaded") rd.fail(fmt::format("stop_rows is '{}', expected 'loaded'", v));
    prm.stop_rows = StopRows::Loaded;
  }
}

// "colours C overflow 0|1", "start ..." (C + 1 values), "split ..." (C).
inline void write_colouring(std::ostream& out, const Colouring& c) {
  out << "colours " << c.split.size() << " overflow " << (c.overflow ? 1 : 0) << "\nstart";
  for (const auto v : c.start) out << ' ' << v;
  out << "\nsplit";
  for (const auto v : c.split) out << ' ' << v;
  out << "\n";
}

// Reads what write_colouring wrote; `max_colours` bounds the count.
inline Colouring read_colouring(TextReader& rd, long long max_colours, const std::string& after) {
  Colouring col;
  rd.expect("colours", after);
  const long long nc = rd.integer("the number of colours", 0, max_colours);
  rd.expect("overflow", "after the number of colours");
  col.overflow = rd.integer("overflow (0 or 1)", 0, 1) == 1;
  rd.expect("start", "after the colour count");
  col.start.resize(nc + 1);
  std::int32_t prev = 0;  // starts never decrease
  for (auto& v : col.start) prev = v = static_cast<std::int32_t>(rd.integer("a colour start", prev, INT_MAX));
  rd.expect("split", "after the colour starts");
  col.split.resize(nc);
  for (long long c = 0; c < nc; ++c)
    col.split[c] = static_cast<std::int32_t>(rd.integer("a colour split", col.start[c], col.start[c + 1]));
  return col;
}

// "rows R" after the colouring, which must cover the rows [0, R) in order;
// a row takes at least `tokens_each` numbers (R is bounded by the file).
inline long long read_row_count(TextReader& rd, const Colouring& c, long long tokens_each) {
  rd.expect("rows", "after the colouring");
  const long long nr = rd.count("the number of rows", INT_MAX, tokens_each);
  if (c.start.front() != 0 || c.start.back() != nr)
    rd.fail(fmt::format("the colours cover rows {} to {}, the problem has {}", c.start.front(), c.start.back(), nr));
  return nr;
}

// A row's two bodies, each in [0, nb), and not the same one.
template <class Row>
void read_row_bodies(TextReader& rd, Row& r, long long nb, const std::string& w) {
  r.b1 = static_cast<std::int32_t>(rd.integer("body 1" + w, 0, nb - 1));
  r.b2 = static_cast<std::int32_t>(rd.integer("body 2" + w, 0, nb - 1));
  if (r.b1 == r.b2) rd.fail(fmt::format("the contact{} joins body {} to itself (body 1 = body 2)", w, r.b1));
}

// "law NAME": the alternative of the law variant V whose name(law) is NAME.
template <class V, class Name>
V read_law(TextReader& rd, Name&& name) {
  rd.expect("law", "after the header");
  const std::string law(rd.need("the law's name"));
  V out;
  bool found = false;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((!found && name(V{std::variant_alternative_t<I, V>{}}) == law
          ? (out = std::variant_alternative_t<I, V>{}, found = true)
          : false),
     ...);
  }(std::make_index_sequence<std::variant_size_v<V>>{});
  if (!found) rd.fail(fmt::format("unknown law '{}'", law));
  return out;
}

// The boundary dofs (2D BoundaryDof, 3D CellDof3): "dofs D", then per dof
// "v0 v inv_mass scale", the dimension's own fields head(dof), the row
// count M, and M lines "row" followed by the dof's coefficients on that row,
// coefficients(dof, m) (2D: a_n a_t; 3D: the three frame components).
template <class Dof, class Head, class Coefficients>
void write_dofs(std::ostream& out, const std::vector<Dof>& dofs, Head&& head, Coefficients&& coefficients) {
  out << "dofs " << dofs.size() << "\n";
  for (const Dof& d : dofs) {
    out << hex(d.v0) << ' ' << hex(d.v) << ' ' << hex(d.inv_mass) << ' ' << hex(d.scale) << head(d) << ' '
        << d.rows.size() << '\n';
    for (std::size_t m = 0; m < d.rows.size(); ++m) out << d.rows[m] << ' ' << coefficients(d, m) << '\n';
  }
}

// Reads what write_dofs wrote, after `after`: at most max_dofs dofs, rows
// in [0, nr), each row line `tokens_each` tokens (the row and its
// coefficients). head(dof, w) reads (and checks) the dimension's own fields,
// coefficients(dof, w) appends one row's; `w` names the dof in messages.
template <class Dof, class Head, class Coefficients>
std::vector<Dof> read_dofs(TextReader& rd, const std::string& after, long long max_dofs, long long nr,
                           long long tokens_each, Head&& head, Coefficients&& coefficients) {
  rd.expect("dofs", after);
  const long long nd = rd.count("the number of dofs", max_dofs, 5);
  std::vector<Dof> dofs(nd);
  for (long long d = 0; d < nd; ++d) {
    Dof& D = dofs[d];
    const std::string w = fmt::format(" of dof {}", d);
    D.v0 = rd.number("v0" + w);
    D.v = rd.number("v" + w);
    D.inv_mass = rd.non_negative("inv_mass" + w);
    D.scale = rd.number("scale" + w);
    head(D, w);
    const long long m = rd.count("the number of rows" + w, nr, tokens_each);
    D.rows.resize(m);
    for (long long j = 0; j < m; ++j) {
      D.rows[j] = static_cast<std::int32_t>(rd.integer("a row" + w, 0, nr - 1));
      coefficients(D, w);
    }
  }
  return dofs;
}

// The file at `path` read by read(stream), or std::runtime_error naming it.
template <class Read>
auto read_path(const std::string& path, Read&& read) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open for reading", path));
  return read(in);
}

// The file at `path` written by write(stream), or std::runtime_error naming it.
template <class Write>
void write_path(const std::string& path, Write&& write) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot open for writing", path));
  write(out);
  if (!out.flush()) throw std::runtime_error(fmt::format("{}: write failed", path));
}

}  // namespace cd::problem_file
