// Siconos' text form of a frictional contact problem (".dat", the files of
// Siconos' fc2d/fc3d test data; tests/data/contact-problems/README.md):
// the dimension, the number of contacts, W as a Siconos NumericsMatrix
// (storage type, rows, columns, then the storage's layout), q, mu. The same
// for 2D and 3D, so read here once; 2d/problem.hpp and 3d/problem3.hpp make
// their problems from it. Storage 0 (dense, column-major: a text line of the
// file is a column), 1 (sparse block, SBM: Siconos' block-row compressed
// layout, each block column-major) and 2 (CSparse compressed-column listing,
// or triplet). Numbers after mu (some dumps append a solution) are ignored.
// Malformed input throws std::runtime_error naming the file, the line and
// what was expected.
#pragma once
#include <iosfwd>
#include <string>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace cd {

struct SiconosDat {
  int dim = 0;                    // 2 or 3
  int nc = 0;                     // contacts
  Eigen::SparseMatrix<double> W;  // dim nc x dim nc, column-major, compressed
  Eigen::VectorXd q;              // dim nc
  Eigen::VectorXd mu;             // nc, >= 0
};

// `dim`: the dimension the caller takes (2 or 3), 0: either.
SiconosDat read_siconos_dat(std::istream& in, const std::string& name, int dim = 0);
SiconosDat read_siconos_dat(const std::string& path, int dim = 0);

}  // namespace cd
