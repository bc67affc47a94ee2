// Issue 27: what the two enumerations of a Painlevé-type impact's modes
// share (painleve.cpp, planar friction; painleve_cone.cpp, polyhedral
// cones): one mode's square system solved and, when it is singular, judged
// by velocity uniqueness over the affine set of its impulses; the tally of
// the motions found and the verdict with its messages.
#include <functional>
#include <lcsim/core/format.hpp>

#include "impact/detail.hpp"

namespace lcsim::impact::detail {

void ModeInequalities::add(const MatrixXd& a_u, const MatrixXd& a_l, const MatrixXd& P,
                           const MatrixXd& WP, const VectorXd& b, bool rate) {
  const Eigen::Index r = F.rows();
  F.conservativeResize(r + 1, P.cols());
  h.conservativeResize(r + 1);
  // A mode with no unknowns (every contact open) has rows of no entries:
  // Eigen's row of a 0-column matrix offsets a null pointer.
  if (F.cols() > 0) F.row(r) = a_u * WP + a_l * P;
  h(r) = (a_u * b)(0);
  on_rates.push_back(rate);
}

bool same_velocity(const MatrixXd& Wg, const VectorXd& b, const VectorXd& a, const VectorXd& c) {
  return (Wg * (a - c)).cwiseAbs().maxCoeff() <=
         1e-8 * (1.0 + b.cwiseAbs().maxCoeff() +
                 (Wg.cwiseAbs() * (a.cwiseAbs() + c.cwiseAbs())).maxCoeff());
}

namespace {

VectorXd tolerances(const ModeInequalities& q, double tol_u, double tol_l) {
  VectorXd t(q.h.size());
  for (Eigen::Index r = 0; r < t.size(); ++r)
    t(r) = q.on_rates[static_cast<size_t>(r)] ? tol_u : tol_l;
  return t;
}

// The polyhedron {y : B y + c >= 0} of a small kernel (dimension k <= 3,
// B of full column rank, so the polyhedron is pointed: not empty exactly
// when it has a vertex), by enumerating its vertices (k rows active, a
// regular k x k system, the others holding to 1e-12 of their terms:
// rounding) and its extreme rays (k - 1 rows active, the line they leave,
// either sign, B d >= 0 to 1e-12 of B's terms). At most C(m, k) small
// systems (m the rows, about 40 for four contacts at d = 4: 9880 at k = 3).
struct Polyhedron {
  bool decided = false;
  std::vector<VectorXd> vertices, rays;
};
void active_subsets(Eigen::Index m, Eigen::Index r,
                    const std::function<void(const std::vector<Eigen::Index>&)>& f) {
  std::vector<Eigen::Index> idx(static_cast<size_t>(r));
  for (Eigen::Index i = 0; i < r; ++i) idx[static_cast<size_t>(i)] = i;
  if (r > m) return;
  while (true) {
    f(idx);
    Eigen::Index i = r - 1;
    while (i >= 0 && idx[static_cast<size_t>(i)] == m - r + i) --i;
    if (i < 0) return;
    ++idx[static_cast<size_t>(i)];
    for (Eigen::Index j = i + 1; j < r; ++j)
      idx[static_cast<size_t>(j)] = idx[static_cast<size_t>(j - 1)] + 1;
  }
}
Polyhedron polyhedron(const MatrixXd& B, const VectorXd& c) {
  Polyhedron out;
  const Eigen::Index k = B.cols(), m = B.rows();
  if (k > 3 || Eigen::FullPivLU<MatrixXd>(B).setThreshold(1e-12).rank() < k) return out;
  out.decided = true;
  const auto holds = [&](const VectorXd& y, const VectorXd& cc) {
    const VectorXd r = B * y + cc;
    const VectorXd scale = B.cwiseAbs() * y.cwiseAbs() + cc.cwiseAbs();
    return (r.array() >= -1e-12 * scale.array()).all();
  };
  active_subsets(m, k, [&](const std::vector<Eigen::Index>& rows) {
    MatrixXd A(k, k);
    VectorXd rhs(k);
    for (Eigen::Index i = 0; i < k; ++i) {
      A.row(i) = B.row(rows[static_cast<size_t>(i)]);
      rhs(i) = -c(rows[static_cast<size_t>(i)]);
    }
    Eigen::FullPivLU<MatrixXd> lu(A);
    lu.setThreshold(1e-12);
    if (!lu.isInvertible()) return;
    const VectorXd y = lu.solve(rhs);
    if (holds(y, c)) out.vertices.push_back(y);
  });
  if (out.vertices.empty()) return out;
  const VectorXd zero = VectorXd::Zero(m);
  active_subsets(m, k - 1, [&](const std::vector<Eigen::Index>& rows) {
    MatrixXd A(k - 1, k);
    for (Eigen::Index i = 0; i < k - 1; ++i) A.row(i) = B.row(rows[static_cast<size_t>(i)]);
    Eigen::FullPivLU<MatrixXd> lu(A);
    lu.setThreshold(1e-12);
    if (k > 1 && lu.rank() < k - 1) return;
    const VectorXd d = k == 1 ? VectorXd::Ones(1) : VectorXd(lu.kernel().col(0));
    for (const double sign : {1.0, -1.0})
      if (holds(sign * d, zero) && (B * d).cwiseAbs().maxCoeff() > 0.0)
        out.rays.push_back(sign * d);
  });
  return out;
}

}  // namespace

// A consistent singular system's impulses form an affine set x0 + ker A.
// When Wg P ker A = 0 every impulse of it gives the same velocity (velocity
// uniqueness, not impulse uniqueness, is what counts): the mode is the
// law's motion when that velocity is the law's, no motion when the
// inequalities have no point in the set (polyhedron: no vertex), else
// another motion. When the velocity moves over the set: one motion if every
// vertex gives the same velocity and no ray moves it, else a continuum
// (refused). A kernel too large for polyhedron(): not decided, refused.
ModeOutcome solve_mode_system(const MatrixXd& Wg, const VectorXd& b, const MatrixXd& P,
                              const MatrixXd& A, const VectorXd& rhs, const ModeInequalities& q,
                              const VectorXd& lambda_law) {
  const Eigen::Index nx = P.cols();
  VectorXd x = VectorXd::Zero(nx);
  MatrixXd kernel(nx, 0);
  if (nx > 0) {
    Eigen::FullPivLU<MatrixXd> lu(A);
    // Pivots below 1e-12 of the largest are rounding of dependent rows: W is
    // formed to ~1e-16 of its terms, and a system of condition above 1e12
    // would not hold its solution to the 1e-9 of the inequalities anyway.
    lu.setThreshold(1e-12);
    x = lu.solve(rhs);
    if (!lu.isInvertible()) {
      const double scale = rhs.cwiseAbs().maxCoeff() + (A.cwiseAbs() * x.cwiseAbs()).maxCoeff();
      if ((A * x - rhs).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + scale)) return {};  // inconsistent
      kernel = lu.kernel();
    }
  }
  ModeOutcome out;
  out.lambda = P * x;
  const double tol_u =
      1e-9 * (1.0 + b.cwiseAbs().maxCoeff() + (Wg.cwiseAbs() * out.lambda.cwiseAbs()).maxCoeff());
  const double tol_l = 1e-9 * (1.0 + out.lambda.cwiseAbs().maxCoeff());
  const VectorXd tol = tolerances(q, tol_u, tol_l), c = q.F * x + q.h;
  if (kernel.cols() == 0) {
    out.kind = ((c + tol).array() >= 0.0).all() ? ModeOutcome::kMotion : ModeOutcome::kNone;
    return out;
  }
  const MatrixXd WP = Wg * P, WK = WP * kernel, PK = P * kernel;
  const bool velocity_unique =
      WK.cwiseAbs().maxCoeff() <= 1e-8 * (Wg.cwiseAbs() * PK.cwiseAbs()).maxCoeff();
  if (velocity_unique && same_velocity(Wg, b, out.lambda, lambda_law)) {
    out.kind = ModeOutcome::kMotion;
    return out;
  }
  // The impulses' set is x0 + K y over the y of F K y + c + tol >= 0 (the
  // tolerance once, as a regular mode's test): polyhedron(); a larger
  // kernel or a B of lower rank would need a linear program (not done:
  // Lemke's on the program's optimality conditions, tried, ended on false
  // rays on these degenerate sets; refused as not decided).
  const Polyhedron set = polyhedron(q.F * kernel, c + tol);
  if (!set.decided) {
    out.kind = ModeOutcome::kUndecided;
    return out;
  }
  if (set.vertices.empty()) return {};
  out.lambda += PK * set.vertices[0];
  out.kind = ModeOutcome::kMotion;
  if (velocity_unique) return out;
  // The velocity is affine in y: one velocity over the set when every
  // vertex gives y0's (same_velocity: a set made by the tolerance alone is
  // one motion) and no ray moves it; else a continuum of motions.
  for (const VectorXd& y : set.vertices)
    if (!same_velocity(Wg, b, out.lambda, P * x + PK * y)) out.kind = ModeOutcome::kContinuum;
  for (const VectorXd& d : set.rays)
    if ((WK * d).cwiseAbs().maxCoeff() > 1e-8 * (Wg.cwiseAbs() * (PK * d).cwiseAbs()).maxCoeff())
      out.kind = ModeOutcome::kContinuum;
  return out;
}

bool MotionTally::add(const ModeOutcome& o, const std::function<std::string()>& modes_text,
                      PainleveVerdict& out) {
  if (o.kind == ModeOutcome::kNone) return true;
  if (o.kind == ModeOutcome::kContinuum) {
    out.message = text("the system of the modes ", modes_text(),
                       " is singular and leaves the velocity free (a continuum of motions)");
    return false;
  }
  if (o.kind == ModeOutcome::kUndecided) {
    out.message = text("the system of the modes ", modes_text(),
                       " is singular and whether its impulses hold a motion other than the "
                       "LCP's is not decided");
    return false;
  }
  for (const VectorXd& m : motions)
    if (same_velocity(Wg, b, o.lambda, m)) return true;
  motions.push_back(o.lambda);
  if (modes.size() < 2) modes.push_back(modes_text());
  return true;
}

void MotionTally::decide(const VectorXd& lambda_law, PainleveVerdict& out) const {
  if (motions.size() == 1 && same_velocity(Wg, b, motions[0], lambda_law)) {
    out.unique = true;
    return;
  }
  if (motions.empty()) {
    out.message = "the contacts' modes' enumeration finds no motion (the solution fits none)";
  } else if (motions.size() == 1) {
    out.message =
        text("the impact has two motions: the modes ", modes[0], " and the LCP's solution");
  } else {
    out.message = text("the impact has ", motions.size(), " motions: the modes ", modes[0],
                       " and the modes ", modes[1]);
  }
}

}  // namespace lcsim::impact::detail
