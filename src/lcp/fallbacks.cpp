#include <cmath>
#include <lcsim/lcp/lcp.hpp>

namespace lcsim::lcp {

Result solve_with_fallbacks(const Solver& first, const MatrixXd& M, const VectorXd& q,
                            const Options& opt, int* attempts, std::string* tried) {
  const auto accept = [&](Result r) {
    if (r.ok() || r.z.size() != q.size() || !r.z.allFinite()) return r;
    Result chk = evaluate(M, q, r.z);
    const double t = opt.tolerance * (1.0 + (q.size() ? q.cwiseAbs().maxCoeff() : 0.0));
    if (chk.residual <= t && chk.min_z >= -t && chk.min_w >= -t) {
      chk.status = Status::kSolved;
      return chk;
    }
    return r;
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
  const Eigen::Index n = q.size();
  VectorXd d(n);
  for (Eigen::Index i = 0; i < n; ++i) d(i) = M(i, i) > 0.0 ? 1.0 / std::sqrt(M(i, i)) : 1.0;
  const VectorXd qd = d.cwiseProduct(q);
  const double s = n && qd.cwiseAbs().maxCoeff() > 0.0 ? qd.cwiseAbs().maxCoeff() : 1.0;
  const MatrixXd Ms = d.asDiagonal() * M * d.asDiagonal();
  const Result r = solve_with_fallbacks(first, Ms, qd / s, opt, attempts, tried);
  if (r.z.size() != n) return r;
  Result out = evaluate(M, q, s * d.cwiseProduct(r.z));
  out.status = r.status;
  out.pivots = r.pivots;
  out.iterations = r.iterations;
  out.message = r.message;
  return out;
}

}  // namespace lcsim::lcp
