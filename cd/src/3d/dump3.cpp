#include "dump3.hpp"

#include <algorithm>
#include <sstream>
#include <utility>
#include <variant>

#include <fmt/format.h>

#include "files.hpp"
#include "problem3.hpp"

namespace cd {

ProblemDump3::ProblemDump3(World3& w, std::filesystem::path dir, std::vector<std::int64_t> steps)
    : w_(w), dir_(std::move(dir)), steps_(std::move(steps)) {
  if (steps_.empty()) return;
  // The hook sees the problem of the step being taken (w.steps + 1) just
  // before its solve, its warm start already in its velocities.
  w_.set_problem_hook([this](const ContactProblem3& p, const SolverParams& prm) {
    const std::int64_t k = w_.steps + 1;
    if (!dumped(k)) return;
    std::ostringstream text;
    write_contact_problem(p, prm, text);
    write_file_atomic((dir_ / fmt::format("problem_{}.cdp3", k)).string(), text.str());
    matrix_.reset();
    // No FCLib file for what its format cannot say: adhesion, the
    // orthotropic cone, compliant contacts (the .cdp3 holds them).
    const bool fclib = p.compliance == 0.0 && std::visit(
        [](auto l) { return !decltype(l)::cohesive && !decltype(l)::orthotropic; }, p.law);
    if (!fclib) return;
    matrix_ = std::make_unique<Problem3>(to_matrix(p));
    guess_.resize(3 * p.rows.size());
    for (std::size_t i = 0; i < p.rows.size(); ++i)
      for (int j = 0; j < 3; ++j) guess_[3 * i + j] = p.rows[i].r[j];
  });
}

ProblemDump3::~ProblemDump3() {
  if (!steps_.empty()) w_.set_problem_hook({});
}

bool ProblemDump3::dumped(std::int64_t k) const { return std::find(steps_.begin(), steps_.end(), k) != steps_.end(); }

void ProblemDump3::after_step(std::int64_t k) {
  if (!dumped(k)) return;
  const auto& rows = w_.rows();
  std::string text;
  for (const SphereRow& r : rows) text += fmt::format("{:a} {:a} {:a}\n", r.r[0], r.r[1], r.r[2]);
  write_file_atomic((dir_ / fmt::format("problem_{}.impulses", k)).string(), text);
  if (!matrix_) return;
  Eigen::VectorXd r(3 * rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) r.segment<3>(3 * i) = rows[i].r;
  const Eigen::VectorXd guess = Eigen::Map<const Eigen::VectorXd>(guess_.data(), guess_.size());
  const std::string path = (dir_ / fmt::format("problem_{}.hdf5", k)).string(), tmp = tmp_name(path);
  try {
    write_fclib(*matrix_, tmp, fmt::format("cdlab step {}", k),
                fmt::format("cdsim --dump-problem {}: a 3D step's contact problem, u = W r + q, W = H^T M^-1 H; "
                            "solution: the step's impulses; guess: its warm start",
                            k),
                &r, &guess);
  } catch (const std::runtime_error& e) {  // FCLib (HDF5) could not write it: a write failure
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw WriteError(fmt::format("could not write '{}': {}", path, e.what()));
  }
  rename_into_place(tmp, path);
  matrix_.reset();
}

}  // namespace cd
