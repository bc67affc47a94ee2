#include <cmath>
#include <lcsim/lcp/lcp.hpp>

#include "lcp/detail.hpp"

namespace lcsim::lcp {

Result solve_with_fallbacks(const Solver& first, const MatrixXd& M, const VectorXd& q,
                            const Options& opt, int* attempts, std::string* tried) {
  // A z that passes the acceptance test is a solution, whatever its solver
  // claimed; one that does not stays the solver's result.
  const auto accept = [&](Result r) {
    if (r.ok() || r.z.size() != q.size() || !r.z.allFinite()) return r;
    Result chk = detail::finish(M, q, r.z, Status::kSolved, opt, "");
    if (!chk.ok()) return r;
    chk.pivots = r.pivots;
    chk.iterations = r.iterations;
    return chk;
  };
  const auto note = [&](const std::string& name) {
    if (attempts) ++*attempts;
    if (tried) *tried += (tried->empty() ? "" : ", ") + name;
  };
  Result res = accept(first.solve(M, q, opt));
  note(first.name());
  // Enumeration last (k <= 12): near-dependent rows can leave a matrix of low
  // rank with entries 0.9999...; Lemke and PGS can then stall, enumeration of
  // the complementary bases cannot.
  for (const char* fallback : {"lemke", "pgs", "enum"}) {
    if (res.ok() || first.name() == fallback) continue;
    if (std::string(fallback) == "enum" && q.size() > 12) continue;
    res = accept(make_solver(fallback)->solve(M, q, opt));
    note(fallback);
  }
  return res;
}

Result solve_scaled(const Solver& first, const MatrixXd& M, const VectorXd& q, const Options& opt,
                    int* attempts, std::string* tried) {
  const std::string bad = detail::validate_all(M, q, opt);
  if (!bad.empty()) return detail::invalid(bad);
  const detail::Scaling sc = detail::symmetric_scaling(M, q);
  // A subnormal diagonal (1 / sqrt(M_ii) ~ 1e155) can overflow the scaled
  // problem: solve the original one then.
  if (!sc.M.allFinite() || !sc.q.allFinite())
    return solve_with_fallbacks(first, M, q, opt, attempts, tried);
  const Result r = solve_with_fallbacks(first, sc.M, sc.q, opt, attempts, tried);
  if (r.z.size() != q.size()) return r;
  Result out = detail::finish(M, q, sc.unscale(r.z), r.status, opt, r.message);
  out.pivots = r.pivots;
  out.iterations = r.iterations;
  return out;
}

}  // namespace lcsim::lcp
