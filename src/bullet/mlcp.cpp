// Bullet's MLCP solvers as LCP back-ends: bullet-dantzig, bullet-lemke,
// bullet-pgs.
//
// btMLCPSolverInterface::solveMLCP(A, b, x, lo, hi, limitDependency, iters)
// solves A x = b + w with lo <= x <= hi (x = lo needs w >= 0, x = hi needs
// w <= 0); the LCP w = M z + q, z >= 0 is A = M, b = -q, lo = 0, hi = inf,
// limitDependency = -1 (../shared/notes/bullet.md). Bullet's own success flag
// is not trusted: btDantzigSolver assumes a symmetric matrix and reports
// success on wrong answers for nonsymmetric ones, so every answer goes
// through lcsim's residual check with the caller's tolerance.
//
// Pinned settings: btLemkeSolver in unbounded mode (m_useLoHighBounds =
// false: the plain LCP needs no bounds, and the bounded mode inverts A by
// Gauss-Jordan without pivoting), m_maxLoops = max_pivots or 50 k + 1000,
// m_maxValue = 1e300 (Bullet's 1e5 cap would clip large impulses). PGS and
// Dantzig get opt.max_iterations as their iteration count (Dantzig ignores it).
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <BulletDynamics/MLCPSolvers/btLemkeSolver.h>
#include <BulletDynamics/MLCPSolvers/btSolveProjectedGaussSeidel.h>

#include <cmath>
#include <lcsim/bullet/bullet.hpp>

namespace lcsim::bullet {

namespace {

const char* name_of(MlcpSolver which) {
  switch (which) {
    case MlcpSolver::kDantzig:
      return "bullet-dantzig";
    case MlcpSolver::kLemke:
      return "bullet-lemke";
    case MlcpSolver::kPgs:
      return "bullet-pgs";
  }
  return "bullet-?";
}

lcp::Result invalid(std::string msg) {
  lcp::Result r;
  r.status = lcp::Status::kInvalidInput;
  r.message = std::move(msg);
  return r;
}

}  // namespace

lcp::Result solve_bullet_mlcp(MlcpSolver which, const Eigen::MatrixXd& M, const Eigen::VectorXd& q,
                              const lcp::Options& opt) {
  if (std::string bad = lcp::validate(M, q); !bad.empty()) return invalid(std::move(bad));
  if (!(opt.tolerance >= 0.0) || !std::isfinite(opt.tolerance) || opt.max_iterations < 0 ||
      opt.max_pivots < 0)
    return invalid("tolerance must be finite and >= 0, max_iterations and max_pivots >= 0");
  const int k = static_cast<int>(q.size());
  if (opt.warm_start && opt.warm_start->size() != k)
    return invalid("warm start has " + std::to_string(opt.warm_start->size()) +
                   " entries, expected " + std::to_string(k));
  btMatrixXu A(k, k);
  btVectorXu b(k), x(k), lo(k), hi(k);
  A.setZero();
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j)
      if (M(i, j) != 0.0) A.setElem(i, j, M(i, j));
    b[i] = -q(i);
    lo[i] = 0.0;
    hi[i] = BT_INFINITY;
    x[i] = (opt.warm_start ? std::max(0.0, (*opt.warm_start)(i)) : 0.0);
  }
  btAlignedObjectArray<int> dep;
  dep.resize(k, -1);
  bool claimed = false;
  switch (which) {
    case MlcpSolver::kDantzig: {
      btDantzigSolver s;
      claimed = s.solveMLCP(A, b, x, lo, hi, dep, opt.max_iterations, false);
      break;
    }
    case MlcpSolver::kLemke: {
      btLemkeSolver s;
      s.m_useLoHighBounds = false;
      s.m_maxLoops = opt.max_pivots > 0 ? opt.max_pivots : 50 * k + 1000;
      s.m_maxValue = 1e300;
      claimed = s.solveMLCP(A, b, x, lo, hi, dep, opt.max_iterations, false);
      break;
    }
    case MlcpSolver::kPgs: {
      btSolveProjectedGaussSeidel s;
      s.m_leastSquaresResidualThreshold = 0;
      claimed = s.solveMLCP(A, b, x, lo, hi, dep, opt.max_iterations, false);
      break;
    }
  }
  Eigen::VectorXd z(k);
  for (int i = 0; i < k; ++i) z(i) = x[i];
  // lcsim's own acceptance test decides, whatever Bullet claims.
  lcp::Result r = lcp::accept(M, q, std::move(z), opt);
  if (which == MlcpSolver::kPgs) r.iterations = opt.max_iterations;
  if (r.ok()) {
    if (!claimed) r.message = std::string(name_of(which)) + " reported failure, but z passes";
    return r;
  }
  r.message = std::string(name_of(which)) +
              (claimed ? " reported success but " : " reported failure; ") + r.message;
  return r;
}

namespace {

class MlcpBackend final : public lcp::Solver {
 public:
  explicit MlcpBackend(MlcpSolver which) : which_(which) {}
  std::string name() const override { return name_of(which_); }
  lcp::Result solve(const Eigen::MatrixXd& M, const Eigen::VectorXd& q,
                    const lcp::Options& opt) const override {
    return solve_bullet_mlcp(which_, M, q, opt);
  }

 private:
  MlcpSolver which_;
};

}  // namespace

void register_mlcp_backends() {
  for (MlcpSolver w : {MlcpSolver::kDantzig, MlcpSolver::kLemke, MlcpSolver::kPgs})
    lcp::solvers().add(name_of(w), [w] { return std::make_unique<MlcpBackend>(w); });
}

}  // namespace lcsim::bullet
