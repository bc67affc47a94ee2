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
// (rate rows) or of lambda (impulse rows), as painleve.cpp's.
ModeInequalities inequalities(const ConeProblemView& v, const std::vector<int>& modes,
                              const ModeSystem& s, const MatrixXd& WP) {
  const Eigen::Index n = v.p.Wg.rows();
  ModeInequalities q{MatrixXd(0, s.P.cols()), VectorXd(0), {}};
  const MatrixXd zero = MatrixXd::Zero(1, n);
  for (size_t j = 0; j < v.contacts.size(); ++j) {
    const ConeContact& c = v.contacts[j];
    const int m = modes[j];
    const auto J = static_cast<Eigen::Index>(j);
    MatrixXd a = zero;
    a(0, J) = 1.0;
    if (m == 0) {  // u_N >= 0
      q.add(a, zero, s.P, WP, v.p.b, true);
      continue;
    }
    q.add(zero, a, s.P, WP, v.p.b, false);  // lambda_N >= 0
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
        q.add(zero, r, s.P, WP, v.p.b, false);
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
      q.add(r, zero, s.P, WP, v.p.b, true);
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

// One mode's motion (solve_mode_system, painleve_modes.cpp: a singular
// system, as the box's four coplanar corners give, judged by velocity
// uniqueness).
ModeOutcome solve_cone_mode(const ConeProblemView& v, const std::vector<int>& modes,
                            const VectorXd& lambda_law) {
  const ConeModesProblem& p = v.p;
  const ModeSystem s = mode_system(v, modes);
  const MatrixXd WP = p.Wg * s.P;
  return solve_mode_system(p.Wg, p.b, s.P, s.R * WP, -(s.R * p.b), inequalities(v, modes, s, WP),
                           lambda_law);
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
  MotionTally tally{p.Wg, p.b, {}, {}};
  std::vector<int> modes(v.contacts.size());
  for (long code = 0; code < total; ++code) {
    long c = code;
    for (size_t j = 0; j < v.contacts.size(); ++j) {
      modes[j] = static_cast<int>(c % v.contacts[j].modes());
      c /= v.contacts[j].modes();
    }
    const auto modes_text = [&] { return cone_modes_text(v, modes, labels); };
    if (!tally.add(solve_cone_mode(v, modes, lambda_law), modes_text, out)) return out;
  }
  tally.decide(lambda_law, out);
  return out;
}

}  // namespace lcsim::impact::detail
