// Issue 27 for cones with d >= 2: deciding a Painlevé-type impact of the
// polyhedral cone law (friction_cone.cpp) by enumerating the closed
// contacts' modes, as painleve.cpp does for planar friction. The friction
// impulse of a contact lies in mu lambda_N conv{e_i} (e_i = cone_edge(i, d),
// the polygon of the 2d edges) and takes there the point of maximal
// dissipation against the sliding u_T after the impact. Per contact the
// modes are: open (no impulse, u_N >= 0); stick (u_N = 0, u_T = 0, friction
// anywhere in the polygon); slip on edge i (friction at the vertex
// mu lambda_N e_i, e_i minimising u_T . e over the vertices); slip on face k
// (friction on the side from e_k to e_(k+1), u_T orthogonal to that side,
// e_k minimising u_T . e). Each mode is a square linear system.
#include <cmath>
#include <functional>
#include <lcsim/core/format.hpp>

#include "impact/detail.hpp"

namespace lcsim::impact::detail {

namespace {

struct ConeContact {
  Eigen::Index t = -1;  // first tangent row in Wg, -1 frictionless
  int d = 0;            // 0 frictionless, 1 planar (t1 only), >= 2 (t1, t2)
  double mu = 0.0;
  int modes() const { return t < 0 ? 2 : (d == 1 ? 4 : 2 + 4 * d); }
  std::pair<double, double> edge(int i) const {
    return d == 1 ? std::pair<double, double>{i == 0 ? 1.0 : -1.0, 0.0} : cone_edge(i % (2 * d), d);
  }
};

std::string cone_mode_name(const ConeContact& c, int mode) {
  if (mode == 0) return "open";
  if (mode == 1) return c.t < 0 ? "closed" : "stick";
  if (mode < 2 + 2 * c.d) return text("slip-edge-", mode - 2);
  return text("slip-face-", mode - 2 - 2 * c.d);
}

struct ConeProblemView {
  const ConeModesProblem& p;
  std::vector<ConeContact> contacts;  // per normal
};

struct ModeSystem {
  MatrixXd P;                        // lambda = P x
  MatrixXd R;                        // the equations R u = 0
  std::vector<Eigen::Index> face_x;  // per normal: the face's second unknown, or -1
};

// The columns of P and rows of R of the modes (see the file's comment).
ModeSystem mode_system(const ConeProblemView& v, const std::vector<int>& modes) {
  const Eigen::Index n = v.p.Wg.rows();
  ModeSystem s{MatrixXd::Zero(n, n), MatrixXd::Zero(n, n),
               std::vector<Eigen::Index>(v.contacts.size(), -1)};
  Eigen::Index x = 0;
  const auto unit = [&](Eigen::Index row) {
    s.P(row, x) = 1.0;
    s.R(x++, row) = 1.0;
  };
  for (size_t j = 0; j < v.contacts.size(); ++j) {
    const ConeContact& c = v.contacts[j];
    const int m = modes[j];
    const auto J = static_cast<Eigen::Index>(j);
    if (m == 0) continue;
    if (m == 1) {
      unit(J);
      if (c.t >= 0) unit(c.t);
      if (c.d >= 2) unit(c.t + 1);
      continue;
    }
    const bool face = m >= 2 + 2 * c.d;
    const int i = face ? m - 2 - 2 * c.d : m - 2;
    const auto [ci, si] = c.edge(i);
    s.P(J, x) = 1.0;
    s.P(c.t, x) = c.mu * ci;
    if (c.d >= 2) s.P(c.t + 1, x) = c.mu * si;
    s.R(x++, J) = 1.0;
    if (!face) continue;
    const auto [cn, sn] = c.edge(i + 1);
    s.P(c.t, x) = s.R(x, c.t) = cn - ci;
    s.P(c.t + 1, x) = s.R(x, c.t + 1) = sn - si;
    s.face_x[j] = x++;
  }
  s.P.conservativeResize(n, x);
  s.R.conservativeResize(x, n);
  return s;
}

// The mode's inequalities as rows F x + h >= 0 over its unknowns x (lambda
// = P x, u = Wg P x + b), each with its tolerance: 1e-9 of the terms of u
// (rate rows) or of lambda (impulse rows), as painleve.cpp's solve_modes.
struct Inequalities {
  MatrixXd F;
  VectorXd h;
  std::vector<bool> on_rates;
  void add(const MatrixXd& a_u, const MatrixXd& a_l, const ModeSystem& s, const MatrixXd& WP,
           const VectorXd& b, bool rate) {
    const Eigen::Index r = F.rows();
    F.conservativeResize(r + 1, s.P.cols());
    h.conservativeResize(r + 1);
    // A mode with no unknowns (every contact open) has rows of no entries:
    // Eigen's row of a 0-column matrix offsets a null pointer.
    if (F.cols() > 0) F.row(r) = a_u * WP + a_l * s.P;
    h(r) = (a_u * b)(0);
    on_rates.push_back(rate);
  }
};

Inequalities inequalities(const ConeProblemView& v, const std::vector<int>& modes,
                          const ModeSystem& s, const MatrixXd& WP) {
  const Eigen::Index n = v.p.Wg.rows();
  Inequalities q{MatrixXd(0, s.P.cols()), VectorXd(0), {}};
  const MatrixXd zero = MatrixXd::Zero(1, n);
  for (size_t j = 0; j < v.contacts.size(); ++j) {
    const ConeContact& c = v.contacts[j];
    const int m = modes[j];
    const auto J = static_cast<Eigen::Index>(j);
    MatrixXd a = zero;
    a(0, J) = 1.0;
    if (m == 0) {  // u_N >= 0
      q.add(a, zero, s, WP, v.p.b, true);
      continue;
    }
    q.add(zero, a, s, WP, v.p.b, false);  // lambda_N >= 0
    const int edges = c.d == 1 ? 2 : 2 * c.d;
    if (m == 1 && c.t >= 0) {
      // Inside the polygon: f . (e_k + e_(k+1)) <= mu lambda_N (1 + e_k . e_(k+1))
      // (d = 1: |f| <= mu lambda_N, the same rows with e_1 = -e_0 doubled).
      for (int k = 0; k < edges; ++k) {
        const auto [ck, sk] = c.edge(k);
        const auto [cn, sn] = c.d == 1 ? c.edge(k) : c.edge(k + 1);
        MatrixXd r = zero;
        r(0, J) = c.mu * (1.0 + ck * cn + sk * sn);
        r(0, c.t) = -(ck + cn);
        if (c.d >= 2) r(0, c.t + 1) = -(sk + sn);
        q.add(zero, r, s, WP, v.p.b, false);
      }
    }
    if (m < 2) continue;
    const int i = m < 2 + 2 * c.d ? m - 2 : m - 2 - 2 * c.d;
    const auto [ci, si] = c.edge(i);
    for (int k = 0; k < edges; ++k) {  // u_T . e_k - u_T . e_i >= 0
      if (k == i) continue;
      const auto [ck, sk] = c.edge(k);
      MatrixXd r = zero;
      r(0, c.t) = ck - ci;
      if (c.d >= 2) r(0, c.t + 1) = sk - si;
      q.add(r, zero, s, WP, v.p.b, true);
    }
    if (s.face_x[j] < 0) continue;
    // 0 <= g <= mu lambda_N, g the face's second unknown.
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Index r = q.F.rows();
      q.F.conservativeResize(r + 1, s.P.cols());
      q.h.conservativeResize(r + 1);
      q.F.row(r).setZero();
      q.F(r, s.face_x[j]) = sign;
      q.h(r) = 0.0;
      if (sign < 0) q.F.row(r) += c.mu * s.P.row(J);
      q.on_rates.push_back(false);
    }
  }
  return q;
}

VectorXd tolerances(const Inequalities& q, double tol_u, double tol_l) {
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

bool same_velocity(const ConeModesProblem& p, const VectorXd& a, const VectorXd& c) {
  // Wg = G M^-1 G' is positive semidefinite: Wg (a - c) = 0 is G'(a - c) = 0.
  return (p.Wg * (a - c)).cwiseAbs().maxCoeff() <=
         1e-8 * (1.0 + p.b.cwiseAbs().maxCoeff() +
                 (p.Wg.cwiseAbs() * (a.cwiseAbs() + c.cwiseAbs())).maxCoeff());
}

struct ModeOutcome {
  enum Kind { kNone, kMotion, kContinuum, kUndecided } kind = kNone;
  VectorXd lambda;
};

// One mode's motion. A regular system: its solution when the inequalities
// hold. A singular one (dependent rows: the box's four coplanar corners
// leave the normal block of rank 3): a consistent system's impulses form an
// affine set x0 + ker A. When Wg P ker A = 0 every impulse of it gives the
// same velocity (velocity uniqueness, not impulse uniqueness, is what
// counts): the mode is the law's motion when that velocity is the law's, no
// motion when the inequalities have no point in the set (polyhedron: no
// vertex), else another motion. When the velocity moves over the set: one
// motion if every vertex gives the same velocity and no ray moves it, else
// a continuum (refused). A kernel too large for polyhedron(): not decided,
// refused.
ModeOutcome solve_cone_mode(const ConeProblemView& v, const std::vector<int>& modes,
                            const VectorXd& lambda_law) {
  const ConeModesProblem& p = v.p;
  const ModeSystem s = mode_system(v, modes);
  const Eigen::Index nx = s.P.cols();
  const MatrixXd WP = p.Wg * s.P;
  const MatrixXd A = s.R * WP;
  const VectorXd rhs = -(s.R * p.b);
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
  out.lambda = s.P * x;
  const Inequalities q = inequalities(v, modes, s, WP);
  const double tol_u = 1e-9 * (1.0 + p.b.cwiseAbs().maxCoeff() +
                               (p.Wg.cwiseAbs() * out.lambda.cwiseAbs()).maxCoeff());
  const double tol_l = 1e-9 * (1.0 + out.lambda.cwiseAbs().maxCoeff());
  const VectorXd tol = tolerances(q, tol_u, tol_l), c = q.F * x + q.h;
  if (kernel.cols() == 0) {
    out.kind = ((c + tol).array() >= 0.0).all() ? ModeOutcome::kMotion : ModeOutcome::kNone;
    return out;
  }
  const MatrixXd WK = WP * kernel;
  const bool velocity_unique =
      WK.cwiseAbs().maxCoeff() <= 1e-8 * (p.Wg.cwiseAbs() * (s.P * kernel).cwiseAbs()).maxCoeff();
  if (velocity_unique && same_velocity(p, out.lambda, lambda_law)) {
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
  const MatrixXd PK = s.P * kernel;
  out.lambda += PK * set.vertices[0];
  out.kind = ModeOutcome::kMotion;
  if (velocity_unique) return out;
  // The velocity is affine in y: one velocity over the set when every
  // vertex gives y0's (same_velocity: a set made by the tolerance alone is
  // one motion) and no ray moves it; else a continuum of motions.
  for (const VectorXd& y : set.vertices)
    if (!same_velocity(p, out.lambda, s.P * x + PK * y)) out.kind = ModeOutcome::kContinuum;
  for (const VectorXd& d : set.rays)
    if ((WK * d).cwiseAbs().maxCoeff() > 1e-8 * (p.Wg.cwiseAbs() * (PK * d).cwiseAbs()).maxCoeff())
      out.kind = ModeOutcome::kContinuum;
  return out;
}

std::string cone_modes_text(const ConeProblemView& v, const std::vector<int>& modes,
                            const std::vector<std::string>& labels) {
  std::string s;
  for (size_t j = 0; j < v.contacts.size(); ++j)
    s += text(j > 0 ? " " : "", labels[j], " (", cone_mode_name(v.contacts[j], modes[j]), ")");
  return s;
}

}  // namespace

PainleveVerdict decide_cone_painleve_by_modes(const ConeModesProblem& p, const VectorXd& lambda_law,
                                              const std::vector<std::string>& labels) {
  ConeProblemView v{p, std::vector<ConeContact>(static_cast<size_t>(p.nj))};
  for (size_t f = 0; f < p.normal_of.size(); ++f)
    v.contacts[static_cast<size_t>(p.normal_of[f])] =
        ConeContact{p.first_t[f], p.d[f], p.mu(static_cast<Eigen::Index>(f))};
  long total = 1;
  for (const ConeContact& c : v.contacts)
    if (total <= kConePainleveModeBound) total *= c.modes();
  PainleveVerdict out;
  if (total > kConePainleveModeBound) {
    out.message = text("the contacts' modes (", p.nj, " closed contacts, more than ",
                       kConePainleveModeBound, " combinations) are above the enumeration's bound ",
                       kConePainleveModeBound, ": not enumerated");
    return out;
  }
  out.enumerated = true;
  std::vector<VectorXd> motions;
  std::vector<std::vector<int>> modes_of;
  std::vector<int> modes(v.contacts.size());
  for (long code = 0; code < total; ++code) {
    long c = code;
    for (size_t j = 0; j < v.contacts.size(); ++j) {
      modes[j] = static_cast<int>(c % v.contacts[j].modes());
      c /= v.contacts[j].modes();
    }
    const ModeOutcome o = solve_cone_mode(v, modes, lambda_law);
    if (o.kind == ModeOutcome::kNone) continue;
    if (o.kind == ModeOutcome::kContinuum) {
      out.message = text("the system of the modes ", cone_modes_text(v, modes, labels),
                         " is singular and leaves the velocity free (a continuum of motions)");
      return out;
    }
    if (o.kind == ModeOutcome::kUndecided) {
      out.message = text("the system of the modes ", cone_modes_text(v, modes, labels),
                         " is singular and whether its impulses hold a motion other than the "
                         "LCP's is not decided");
      return out;
    }
    bool seen = false;
    for (const VectorXd& m : motions) seen = seen || same_velocity(p, o.lambda, m);
    if (seen) continue;
    motions.push_back(o.lambda);
    modes_of.push_back(modes);
  }
  if (motions.size() == 1 && same_velocity(p, motions[0], lambda_law)) {
    out.unique = true;
    return out;
  }
  if (motions.empty()) {
    out.message = "the contacts' modes' enumeration finds no motion (the solution fits none)";
  } else if (motions.size() == 1) {
    out.message = text("the impact has two motions: the modes ",
                       cone_modes_text(v, modes_of[0], labels), " and the LCP's solution");
  } else {
    out.message = text("the impact has ", motions.size(), " motions: the modes ",
                       cone_modes_text(v, modes_of[0], labels), " and the modes ",
                       cone_modes_text(v, modes_of[1], labels));
  }
  return out;
}

}  // namespace lcsim::impact::detail
