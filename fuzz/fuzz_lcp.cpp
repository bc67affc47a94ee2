// libFuzzer target: every LCP solver on an LCP w = M z + q, 0 <= z _|_ w >= 0
// decoded from the bytes. Solvers never throw (lcp.hpp); whatever status they
// return must agree with the data:
//   - kInvalidInput iff lcp::validate(M, q) names a problem (non-finite data);
//   - kSolved implies z, w finite, of size k, and the row-scaled acceptance
//     test of Options::tolerance, recomputed here from w = M z + q: for every
//     row i, |min(z_i / ||z||_inf, w_i / s_i)| <= tol with
//     s_i = |q_i| + sum_j |M_ij| |z_j| (0/0 read as 0), which holds z_i and
//     w_i >= -tol times their scale; a row of size 1 next to rows of size 1e12
//     is judged against its own terms (issue #14).
// Any violation, crash or sanitizer report aborts the run.
//
// Layout: byte 0 gives k = 1 + b % 12; byte 1 the decoding of the entries:
//   0: raw little-endian doubles (NaN, Inf, subnormals, 1e300 ...),
//   1: int8 / 8 (small, many ties and zeros: degenerate LCPs),
//   2: int8 * 10^e with e in [-12, 12] from the next byte (badly scaled),
//   3: symmetric positive definite A'A + I / 8 from int8 entries of A,
//   4: as 3, then row i of M and q scaled by 10^e_i, e_i in [-12, 12] from one
//      byte per row read before the entries (badly scaled rows of a P-matrix
//      LCP: every pivoting solver should solve it),
//   5: int8 / 8 entries, rows scaled as in 4 (any matrix, badly scaled rows).
// Then k*k entries of M (row-major) and k of q; missing bytes read as 0.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <lcsim/lcp/lcp.hpp>
#include <sstream>
#include <string>

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

struct Reader {
  const std::uint8_t* data;
  std::size_t size, pos = 0;
  std::uint8_t byte() { return pos < size ? data[pos++] : 0; }
  double raw() {
    std::uint8_t b[8];
    for (auto& x : b) x = byte();
    double d;
    std::memcpy(&d, b, sizeof d);
    return d;
  }
};

[[noreturn]] void fail(const std::string& solver, const char* what, const lcsim::lcp::Result& r,
                       const MatrixXd& M, const VectorXd& q) {
  std::fprintf(stderr,
               "fuzz_lcp: %s: %s (status %s, residual %g, scaled residual %g at row %d, min z %g, "
               "min w %g: %s)\n",
               solver.c_str(), what, std::string(lcsim::lcp::to_string(r.status, "solved")).c_str(),
               r.residual, r.scaled_residual, r.worst_row, r.min_z, r.min_w, r.message.c_str());
  Eigen::IOFormat fmt(Eigen::FullPrecision, 0, ", ", "\n", "[", "]");
  std::fprintf(
      stderr, "M =\n%s\nq = %s\n",
      [&] {
        std::ostringstream os;
        os << M.format(fmt);
        return os.str();
      }()
          .c_str(),
      [&] {
        std::ostringstream os;
        os << q.transpose().format(fmt);
        return os.str();
      }()
          .c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  Reader in{data, size};
  const int k = 1 + in.byte() % 12;
  const int mode = in.byte() % 6;
  MatrixXd M(k, k);
  VectorXd q(k);
  VectorXd row_scale = VectorXd::Ones(k);
  if (mode >= 4)
    for (int i = 0; i < k; ++i)
      row_scale(i) = std::pow(10.0, static_cast<int>(in.byte() % 25) - 12);
  auto entry = [&]() -> double {
    switch (mode) {
      case 0:
        return in.raw();
      case 1:
        return static_cast<std::int8_t>(in.byte()) / 8.0;
      case 2: {
        const double m = static_cast<std::int8_t>(in.byte());
        return m * std::pow(10.0, static_cast<int>(in.byte() % 25) - 12);
      }
      default:
        return static_cast<std::int8_t>(in.byte()) / 8.0;
    }
  };
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) M(i, j) = entry();
  for (int i = 0; i < k; ++i) q(i) = entry();
  if (mode == 3 || mode == 4) M = M.transpose() * M + MatrixXd::Identity(k, k) / 8.0;
  M = row_scale.asDiagonal() * M;  // same solutions: 0 <= z _|_ D w >= 0 iff 0 <= z _|_ w >= 0
  q = row_scale.cwiseProduct(q);

  const bool valid = lcsim::lcp::validate(M, q).empty();
  const lcsim::lcp::Options opt;
  const auto check = [&](const std::string& name, const lcsim::lcp::Result& r) {
    if (!valid) {
      if (r.status != lcsim::lcp::Status::kInvalidInput)
        fail(name, "non-finite data but not kInvalidInput", r, M, q);
      return;
    }
    if (r.status == lcsim::lcp::Status::kInvalidInput)
      fail(name, "kInvalidInput on a well-formed LCP", r, M, q);
    if (r.status != lcsim::lcp::Status::kSolved) return;
    if (r.z.size() != k || !r.z.allFinite())
      fail(name, "solved but z has the wrong size or is not finite", r, M, q);
    const VectorXd w = M * r.z + q;
    if (!w.allFinite()) fail(name, "solved but M z + q is not finite", r, M, q);
    const double zn = r.z.cwiseAbs().maxCoeff();
    for (int i = 0; i < k; ++i) {
      double s = std::abs(q(i));
      for (int j = 0; j < k; ++j) s += std::abs(M(i, j) * r.z(j));
      const double zi = zn > 0.0 ? r.z(i) / zn : 0.0, wi = s > 0.0 ? w(i) / s : 0.0;
      if (!(zi >= -opt.tolerance)) fail(name, "solved but z_i < -tol ||z||_inf", r, M, q);
      if (!(wi >= -opt.tolerance)) fail(name, "solved but w_i < -tol s_i", r, M, q);
      if (!(std::min(zi, wi) <= opt.tolerance))
        fail(name, "solved but row-scaled complementarity above tolerance", r, M, q);
    }
  };
  for (const std::string& name : lcsim::lcp::solver_names())
    check(name, lcsim::lcp::make_solver(name)->solve(M, q, opt));
  check("murty", lcsim::lcp::solve_murty(M, q, opt));
  const auto pivot = lcsim::lcp::make_solver("pivot");
  check("fallbacks", lcsim::lcp::solve_with_fallbacks(*pivot, M, q, opt));
  check("scaled", lcsim::lcp::solve_scaled(*pivot, M, q, opt));
  return 0;
}
