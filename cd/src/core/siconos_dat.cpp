#include "siconos_dat.hpp"

#include <climits>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "problem_file.hpp"
#include "text_reader.hpp"

namespace cd {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Storage 0: "rows<TAB>cols" again, then the column-major array (Siconos
// writes matrix0 in its own order, size1 values a line: a text line is a
// column of W).
void read_dense(TextReader& rd, long long n, Triplets& t) {
  const long long r2 = rd.integer("the dense row count", 0, LLONG_MAX);
  const long long c2 = rd.integer("the dense column count", 0, LLONG_MAX);
  if (r2 != n || c2 != n)
    rd.fail(fmt::format("dense W says {}x{}, header said {}x{}", r2, c2, n, n));
  for (long long j = 0; j < n; ++j)
    for (long long i = 0; i < n; ++i) {
      const double v = rd.number(fmt::format("W({},{})", i, j));
      if (v != 0.0) t.emplace_back(static_cast<int>(i), static_cast<int>(j), v);
    }
}

// Storage 2: NumericsSparseMatrix origin, then CSparse's own listing: a
// version line, "M-by-N, nzmax: K nnz: K, 1-norm: X", then per column
// "col j : locations a to b" and b - a + 1 lines "row : value"; or, for a
// triplet matrix, "triplet: M-by-N, nzmax: K nnz: K" and K lines
// "row col : value".
void read_sparse(TextReader& rd, long long n, Triplets& t) {
  rd.integer("the sparse origin", 0, 3);
  rd.next_line("the CSparse version line");
  const std::string& h = rd.next_line("the CSparse size line");
  long long m = 0, nn = 0, nzmax = 0, nnz = 0;
  const bool triplet = h.rfind("triplet:", 0) == 0;
  const int got = std::sscanf(h.c_str(),
                              triplet ? "triplet: %lld-by-%lld, nzmax: %lld nnz: %lld"
                                      : "%lld-by-%lld, nzmax: %lld nnz: %lld",
                              &m, &nn, &nzmax, &nnz);
  if (got != 4)
    rd.fail(
        fmt::format("expected the CSparse size line '[triplet: ]M-by-N, nzmax: K nnz: K', "
                    "got '{}'",
                    h));
  if (m != n || nn != n)
    rd.fail(fmt::format("sparse W says {}x{}, header said {}x{}", m, nn, n, n));
  if (nnz < 0 || nnz > n * n) rd.fail(fmt::format("nnz {} is impossible for {}x{}", nnz, n, n));
  // An entry is at least "i : v" (3 tokens): the file's own length bounds it.
  if (nnz > rd.remaining_tokens() / 3) rd.fail(fmt::format("nnz {}: unexpected end of file before its entries", nnz));
  t.reserve(nnz);
  if (triplet) {
    for (long long p = 0; p < nnz; ++p) {
      const std::string e = fmt::format("in entry {} of {}", p, nnz);
      const long long i = rd.integer("a row index " + e, 0, n - 1);
      const long long j = rd.integer("a column index " + e, 0, n - 1);
      rd.expect(":", e);
      t.emplace_back(static_cast<int>(i), static_cast<int>(j), rd.number("a value " + e));
    }
    return;
  }
  long long next = 0;  // CSparse locations run on across columns
  for (long long j = 0; j < n; ++j) {
    const std::string c = fmt::format("in column {} of {}", j, n);
    rd.expect("col", c);
    const long long jj = rd.integer("the column number " + c, 0, n - 1);
    if (jj != j) rd.fail(fmt::format("column {} listed where column {} was expected", jj, j));
    rd.expect(":", c);
    rd.expect("locations", c);
    const long long a = rd.integer("the first location " + c, 0, nnz);
    rd.expect("to", c);
    const long long b = rd.integer("the last location " + c, a - 1, nnz - 1);
    if (a != next) rd.fail(fmt::format("column {} starts at location {}, expected {}", j, a, next));
    for (long long p = a; p <= b; ++p) {
      const std::string e = fmt::format("at location {} in column {}", p, j);
      const long long i = rd.integer("a row index " + e, 0, n - 1);
      rd.expect(":", e);
      t.emplace_back(static_cast<int>(i), static_cast<int>(j), rd.number("a value " + e));
    }
    next = b + 1;
  }
  if (next != nnz)
    rd.fail(fmt::format("the columns hold {} entries, the header said {}", next, nnz));
}

// Storage 1, Siconos' SparseBlockStructuredMatrix as SBM_write_in_file
// writes it: the block count (0: nothing follows), the numbers of block rows
// and columns, their cumulative sizes, the counts filled1 and filled2, the
// block-row pointers (filled1 values) and the blocks' column indices
// (filled2), then each block, in
// block-row order, as its number and its values column by column.
void read_sbm(TextReader& rd, long long n, Triplets& t) {
  const long long nblocks = rd.integer("the number of blocks", 0, n * n);
  if (nblocks == 0) return;
  const long long nrow = rd.integer("the number of block rows", 1, n);
  const long long ncol = rd.integer("the number of block columns", 1, n);
  auto sizes = [&](long long count, const char* what) {
    std::vector<long long> s(count);
    for (long long i = 0; i < count; ++i)
      s[i] = rd.integer(fmt::format("the cumulative size of block {} {}", what, i), i ? s[i - 1] + 1 : 1, n);
    if (s.back() != n) rd.fail(fmt::format("the block {}s add up to {}, W is {}x{}", what, s.back(), n, n));
    return s;
  };
  const std::vector<long long> rs = sizes(nrow, "row"), cs = sizes(ncol, "column");
  const long long filled1 = rd.integer("the number of block-row pointers", 1, nrow + 1);
  const long long filled2 = rd.integer("the number of block column indices", nblocks, nblocks);
  std::vector<long long> row_ptr(filled1);
  for (long long i = 0; i < filled1; ++i)
    row_ptr[i] = rd.integer("a block-row pointer", i ? row_ptr[i - 1] : 0, i ? nblocks : 0);
  if (row_ptr.back() != nblocks)
    rd.fail(fmt::format("the block-row pointers end at {}, there are {} blocks", row_ptr.back(), nblocks));
  std::vector<long long> col(filled2);
  for (long long k = 0; k < filled2; ++k) col[k] = rd.integer("a block column index", 0, ncol - 1);
  for (long long r = 0; r + 1 < filled1; ++r)
    for (long long k = row_ptr[r]; k < row_ptr[r + 1]; ++k) {
      const std::string b = fmt::format("block {}", k);
      rd.integer("the number of " + b, k, k);
      const long long i0 = r ? rs[r - 1] : 0, j0 = col[k] ? cs[col[k] - 1] : 0;
      const long long ni = rs[r] - i0, nj = cs[col[k]] - j0;
      for (long long j = 0; j < nj; ++j)
        for (long long i = 0; i < ni; ++i) {
          const double v = rd.number(fmt::format("{}({},{})", b, i, j));
          if (v != 0.0) t.emplace_back(static_cast<int>(i0 + i), static_cast<int>(j0 + j), v);
        }
    }
}

}  // namespace

SiconosDat read_siconos_dat(std::istream& in, const std::string& name, int dim) {
  TextReader rd(in, name);
  SiconosDat p;
  p.dim = static_cast<int>(rd.integer("the dimension", 1, 3));
  if (dim == 2 && p.dim != 2)
    rd.fail(fmt::format("dimension {}: only 2D problems (dimension 2) are supported here", p.dim));
  if (dim == 3 && p.dim != 3)
    rd.fail(fmt::format("dimension {}: only 3D problems (dimension 3) are supported here", p.dim));
  if (p.dim == 1) rd.fail("dimension 1: frictional contact problems have dimension 2 or 3");
  p.nc = static_cast<int>(rd.integer("the number of contacts", 0, INT_MAX / 4));
  const long long n = static_cast<long long>(p.dim) * p.nc;
  const long long storage = rd.integer("the storage type of W", 0, 2);
  const long long rows = rd.integer("the row count of W", 0, LLONG_MAX);
  const long long cols = rd.integer("the column count of W", 0, LLONG_MAX);
  if (rows != n || cols != n)
    rd.fail(
        fmt::format("W is {}x{}, expected {}x{} for {} contacts in {}D", rows, cols, n, n, p.nc, p.dim));
  Triplets t;
  if (storage == 0) {
    read_dense(rd, n, t);
  } else if (storage == 1) {
    read_sbm(rd, n, t);
  } else {
    read_sparse(rd, n, t);
  }
  p.W.resize(n, n);
  p.W.setFromTriplets(t.begin(), t.end());  // sorts rows; a repeated entry is summed
  p.W.makeCompressed();
  p.q.resize(n);
  for (long long i = 0; i < n; ++i) p.q[i] = rd.number(fmt::format("q[{}] (of {})", i, n));
  p.mu.resize(p.nc);
  for (int k = 0; k < p.nc; ++k) {
    p.mu[k] = rd.number(fmt::format("mu[{}] (of {})", k, p.nc));
    if (p.mu[k] < 0) rd.fail(fmt::format("mu[{}] = {} is negative", k, p.mu[k]));
  }
  // Numbers after mu (some dumps append a solution) are ignored; anything
  // else means the file is not what its header says.
  for (std::string t(rd.token()); !t.empty(); t = std::string(rd.token())) {
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (*end != '\0' || !std::isfinite(v))
      rd.fail(fmt::format("unexpected text '{}' after mu (only numbers may follow)", t));
  }
  return p;
}

SiconosDat read_siconos_dat(const std::string& path, int dim) {
  return problem_file::read_path(path, [&](std::istream& in) { return read_siconos_dat(in, path, dim); });
}

}  // namespace cd
