// Enumeration of all 2^k complementary bases (k <= 16): the test oracle.
// For each index set a, solve M_aa z_a = -q_a (skipping singular M_aa) and
// keep z when it passes the acceptance test (scaled_residual <= tolerance).
// Runs on the row-equilibrated LCP (lcp.hpp): the rank decision on M_aa is
// then relative to rows of one size, and the test is invariant under it.
// Only solutions at nonsingular complementary bases are found; when M is
// singular the solution set may be a polyhedron whose vertices these are.
#include <algorithm>
#include <exception>
#include <lcsim/lcp/lcp.hpp>
#include <string>
#include <vector>

#include "lcp/detail.hpp"

namespace lcsim::lcp {
namespace {

constexpr int kMaxEnumeration = 16;

EnumerationResult enumerate(const MatrixXd& M0, const VectorXd& q0, const Options& opt) {
  EnumerationResult out;
  const int k = static_cast<int>(q0.size());
  const detail::Scaling eq = detail::equilibrate_rows(M0, q0);
  const MatrixXd& M = eq.M;
  const VectorXd& q = eq.q;
  std::vector<int> alpha;
  VectorXd z(k), w(k);
  for (unsigned mask = 0; mask < (1u << k); ++mask) {
    alpha.clear();
    for (int i = 0; i < k; ++i)
      if (mask & (1u << i)) alpha.push_back(i);
    z.setZero();
    if (!alpha.empty()) {
      Eigen::FullPivLU<MatrixXd> lu(M(alpha, alpha));
      lu.setThreshold(1e-13);
      if (!lu.isInvertible()) continue;
      z(alpha) = -lu.solve(q(alpha));
    }
    if (z.minCoeff() < -opt.tolerance * z.cwiseAbs().maxCoeff()) continue;
    z = z.cwiseMax(0.0);
    if (!(scaled_residual(M, q, z) <= opt.tolerance)) continue;
    const double tol = 1e-9 * (1.0 + z.cwiseAbs().maxCoeff());
    const bool seen =
        std::any_of(out.solutions.begin(), out.solutions.end(),
                    [&](const VectorXd& s) { return (s - z).cwiseAbs().maxCoeff() <= tol; });
    if (!seen) out.solutions.push_back(z);
  }
  out.status = out.solutions.empty() ? Status::kNumericalFailure : Status::kSolved;
  if (out.solutions.empty()) out.message = "no complementary basis gives a solution";
  return out;
}

}  // namespace

EnumerationResult enumerate_solutions(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  EnumerationResult out;
  std::string bad = detail::validate_all(M, q, opt);
  if (bad.empty() && q.size() > kMaxEnumeration)
    bad = "enumeration is limited to k <= " + std::to_string(kMaxEnumeration) +
          ", got k = " + std::to_string(q.size());
  if (!bad.empty()) {
    out.message = bad;
    return out;
  }
  try {
    return enumerate(M, q, opt);
  } catch (const std::exception& e) {
    out.status = Status::kNumericalFailure;
    out.message = std::string("exception in enumeration: ") + e.what();
    return out;
  }
}

Result solve_enumeration(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  EnumerationResult e = enumerate_solutions(M, q, opt);
  if (e.status == Status::kInvalidInput) return detail::invalid(e.message);
  if (e.solutions.empty())
    return detail::finish(M, q, VectorXd::Zero(q.size()), Status::kNumericalFailure, opt,
                          e.message);
  Result r = detail::finish(M, q, e.solutions.front(), Status::kSolved, opt, "");
  r.iterations = 1 << q.size();
  return r;
}

}  // namespace lcsim::lcp
