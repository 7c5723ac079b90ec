// `cdsim --dump-problem STEP` on 3D scenes: step STEP's contact problem
// (counted from 1), written into the run folder as
//   problem_STEP.cdp3      the whole ContactProblem3 as cdlab text, hex
//                          floats (contact_problem3.hpp): `cdproblem solve`
//                          replays it to the step's impulses bit for bit;
//   problem_STEP.hdf5      the same problem in FCLib's local form (W = H^T
//                          M^-1 H, q, mu; problem3.hpp's to_matrix), with the
//                          step's impulses as its solution and the warm start
//                          as its guess, for Siconos or any FCLib reader; not
//                          written for cohesive or orthotropic laws, which
//                          FCLib cannot express;
//   problem_STEP.impulses  the impulses cdsim found, one row a line (r_n
//                          r_t1 r_t2 as hex floats, the .cdp3's row order).
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "world3.hpp"

namespace cd {

struct Problem3;

class ProblemDump3 {
 public:
  // Installs World3's problem hook when `steps` is not empty.
  ProblemDump3(World3& w, std::filesystem::path dir, std::vector<std::int64_t> steps);
  ~ProblemDump3();
  // After step k: its impulses and FCLib file, if k is dumped.
  void after_step(std::int64_t k);

 private:
  bool dumped(std::int64_t k) const;
  World3& w_;
  std::filesystem::path dir_;
  std::vector<std::int64_t> steps_;
  std::unique_ptr<Problem3> matrix_;  // the dumped step's matrix form (null: none)
  std::vector<double> guess_;         // its warm start
};

}  // namespace cd
