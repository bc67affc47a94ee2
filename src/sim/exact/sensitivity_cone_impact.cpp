// Forward sensitivities through an impact with 3-D friction (impact::
// moreau_friction_cone, Stewart–Trinkle's LCP): at a fixed outcome -- the
// contacts A with a positive normal impulse and, per frictional contact on
// A, stick, planar slip sigma, or a slide whose post-impact velocity lies in
// edge i's region or along face j's bisector -- the law is linear in v, as
// the planar map (sensitivity_friction.cpp). Unknowns: the normal impulses,
// a stuck contact's tangential impulses (t, and t2 for a cone), a face
// slide's cross impulse w; rows: E_r v+ = -e_r E_r v (r in A, e_r where
// approaching), t v+ = velocity (t2 v+ = 0) for a stuck contact, n_j^perp
// v+ = 0 for a face slide; a slide's impulse rides on its normal's column
// (planar -sigma mu t, edge i -mu D_i, face j -mu c n_j). So v+ = v + G B
// lambda, (X G B) lambda = c - R v, J's velocity block I - G B (X G B)^-1 R.
// The law reports "slip" for a cone contact; its facet is found here as the
// one whose linear map reproduces the law's normal impulses with the
// post-impact velocity in that facet's region (at most 4096 combinations).
// Not differentiable (every column lost, naming the contact) where the
// outcome is not locally constant, to sqrt(eps) of its scale: a stuck
// contact's impulse on the polygon's boundary, a slide's velocity on a
// region's boundary or at zero, a face's cross impulse at an end of the
// face, and the planar map's cases.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

namespace {

RowVectorXd trow(const Eigen::SparseVector<double>& v) { return RowVectorXd(VectorXd(v)); }

// One frictional contact on A at the impact's outcome.
struct ImpactEntry {
  int f = -1;             // entry of mechanical.friction
  Eigen::Index a = -1;    // its normal's index in A
  FrictionMode mode{};    // kStick, planar slip, cone_edge(i) or cone_face(j)
  Eigen::Index row = -1;  // its first unknown beyond the normals (-1 if none)
};

// The rows of the round's linear system at the outcome `es`.
struct ConeImpactRows {
  MatrixXd X, R, B;
  VectorXd c;
};

ConeImpactRows cone_impact_rows(const mech::MechanicalModel& m, const std::vector<int>& d,
                                const MatrixXd& E, const std::vector<int>& A, const VectorXd& R1,
                                std::vector<ImpactEntry>& es) {
  const Eigen::Index a = static_cast<Eigen::Index>(A.size()), N = E.cols();
  std::vector<RowVectorXd> held;
  std::vector<double> target;
  for (ImpactEntry& e : es) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(e.f)];
    e.row = -1;
    const double step = std::numbers::pi / d[static_cast<size_t>(e.f)];
    if (e.mode == FrictionMode::kStick) {
      e.row = a + static_cast<Eigen::Index>(held.size());
      held.push_back(trow(fc.tangent));
      target.push_back(fc.velocity);
      if (d[static_cast<size_t>(e.f)] >= 2) held.push_back(trow(fc.tangent2)), target.push_back(0);
    } else if (cone_slip(e.mode) && cone_on_face(e.mode)) {
      const double th = (cone_index(e.mode) + 0.5) * step + std::numbers::pi / 2;
      e.row = a + static_cast<Eigen::Index>(held.size());
      held.push_back(std::cos(th) * trow(fc.tangent) + std::sin(th) * trow(fc.tangent2));
      target.push_back(0.0);
    }
  }
  const Eigen::Index na = a + static_cast<Eigen::Index>(held.size());
  ConeImpactRows s{MatrixXd::Zero(na, N), MatrixXd::Zero(na, N), MatrixXd::Zero(N, na),
                   VectorXd::Zero(na)};
  for (Eigen::Index i = 0; i < a; ++i) {
    s.X.row(i) = E.row(A[static_cast<size_t>(i)]);
    s.R.row(i) = R1(i) * s.X.row(i);
    s.B.col(i) = s.X.row(i).transpose();
  }
  for (size_t h = 0; h < held.size(); ++h) {
    const Eigen::Index r = a + static_cast<Eigen::Index>(h);
    s.X.row(r) = s.R.row(r) = held[h];
    s.B.col(r) = held[h].transpose();
    s.c(r) = target[h];
  }
  for (const ImpactEntry& e : es) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(e.f)];
    const double step = std::numbers::pi / d[static_cast<size_t>(e.f)];
    if (e.mode == FrictionMode::kSlipPositive || e.mode == FrictionMode::kSlipNegative)
      s.B.col(e.a) -=
          (e.mode == FrictionMode::kSlipPositive ? 1.0 : -1.0) * fc.mu * VectorXd(fc.tangent);
    if (!cone_slip(e.mode)) continue;
    const bool face = cone_on_face(e.mode);
    const double ang = (cone_index(e.mode) + (face ? 0.5 : 0.0)) * step;
    s.B.col(e.a) -= fc.mu * (face ? std::cos(step / 2) : 1.0) *
                    (std::cos(ang) * VectorXd(fc.tangent) + std::sin(ang) * VectorXd(fc.tangent2));
  }
  return s;
}

// The margin (> 0 inside) of entry e's outcome at the solution, relative
// to its scale: stick, the polygon's faces; edge i, the velocity's bisector
// cross products; face j, the speed along n_j and the cross impulse's ends;
// planar slip, the sliding velocity's sign.
double outcome_margin(const mech::FrictionalContact& fc, int d, const ImpactEntry& e,
                      const VectorXd& lambda, const VectorXd& vplus, double vscale) {
  const double step = std::numbers::pi / std::max(d, 1), ln = lambda(e.a);
  const double s1 = fc.tangent.dot(vplus) - fc.velocity;
  const double s2 = d >= 2 ? fc.tangent2.dot(vplus) : 0.0, sp = std::hypot(s1, s2);
  if (e.mode == FrictionMode::kStick) {
    if (d < 2) return (fc.mu * ln - std::abs(lambda(e.row))) / (fc.mu * ln);
    double worst = 1.0;
    for (int j = 0; j < 2 * d; ++j) {
      const double th = (j + 0.5) * step;
      const double out = std::cos(th) * lambda(e.row) + std::sin(th) * lambda(e.row + 1);
      worst = std::min(worst, (fc.mu * std::cos(step / 2) * ln - out) / (fc.mu * ln));
    }
    return worst;
  }
  if (sp <= kSqrtEps * vscale) return 0.0;  // a slide at zero velocity: stick and slip meet
  if (!cone_slip(e.mode)) return (e.mode == FrictionMode::kSlipPositive ? s1 : -s1) / sp;
  if (!cone_on_face(e.mode)) {
    const double lo = (cone_index(e.mode) - 0.5) * step, hi = (cone_index(e.mode) + 0.5) * step;
    return std::min(std::cos(lo) * s2 - std::sin(lo) * s1, std::sin(hi) * s1 - std::cos(hi) * s2) /
           sp;
  }
  const double th = (cone_index(e.mode) + 0.5) * step;
  const double speed = std::cos(th) * s1 + std::sin(th) * s2;
  const double bound = fc.mu * std::sin(step / 2) * ln;
  return std::min(speed / sp, (bound - std::abs(lambda(e.row))) / (fc.mu * ln));
}

// The entries of mechanical.friction on A and each one's possible modes
// (a cone slide: every edge and face); -1, or the row whose outcome is not
// derived (a d = 1 slide reported as a cone's).
int impact_entries(const mech::MechanicalModel& m, const std::vector<int>& d,
                   const std::vector<int>& A, const std::vector<impact::ContactOutcome>& outcome,
                   std::vector<ImpactEntry>& es, std::vector<std::vector<FrictionMode>>& choices) {
  for (size_t f = 0; f < m.friction.size(); ++f) {
    const int row = m.friction[f].contact;
    const auto it = std::find(A.begin(), A.end(), row);
    if (it == A.end()) continue;
    const impact::ContactOutcome o = outcome[static_cast<size_t>(row)];
    ImpactEntry en;
    en.f = static_cast<int>(f);
    en.a = it - A.begin();
    std::vector<FrictionMode> ch;
    if (o == impact::ContactOutcome::kStick) ch = {FrictionMode::kStick};
    if (o == impact::ContactOutcome::kSlipPositive) ch = {FrictionMode::kSlipPositive};
    if (o == impact::ContactOutcome::kSlipNegative) ch = {FrictionMode::kSlipNegative};
    if (o == impact::ContactOutcome::kSlip && d[f] >= 2)
      for (int i = 0; i < 2 * d[f]; ++i) ch.push_back(cone_edge(i)), ch.push_back(cone_face(i));
    if (ch.empty()) return row;
    es.push_back(en);
    choices.push_back(std::move(ch));
  }
  return -1;
}

// The outcome's linear map: the first combination of modes whose map
// reproduces the law's normal impulses (1e-8 of the largest) with every
// entry's margin >= -sqrt(eps) (outcome_margin); false if none.
struct ConeImpactSolution {
  ConeImpactRows s;
  MatrixXd GB;
  Eigen::FullPivLU<MatrixXd> W;
  VectorXd lambda, vplus;
  double worst = 1.0;
};

bool solve_outcome(const mech::MechanicalModel& m, const std::vector<int>& d, const MatrixXd& E,
                   const MatrixXd& G, const std::vector<int>& A, const VectorXd& R1,
                   const VectorXd& v, const VectorXd& impulse, double pmax,
                   std::vector<ImpactEntry>& es, const std::vector<std::vector<FrictionMode>>& ch,
                   ConeImpactSolution& out) {
  double total = 1.0;
  for (const auto& c : ch) total *= static_cast<double>(c.size());
  for (size_t code = 0; code < static_cast<size_t>(total); ++code) {
    size_t cc = code;
    for (size_t k = 0; k < es.size(); ++k) {
      es[k].mode = ch[k][cc % ch[k].size()];
      cc /= ch[k].size();
    }
    out.s = cone_impact_rows(m, d, E, A, R1, es);
    out.GB = G * out.s.B;
    const Eigen::Index na = out.s.X.rows();
    if (na > 0) out.W.compute(out.s.X * out.GB);
    if (na > 0 && !out.W.isInvertible()) continue;
    out.lambda = na > 0 ? VectorXd(out.W.solve(out.s.c - out.s.R * v)) : VectorXd();
    out.vplus = v + out.GB * out.lambda;
    bool same = true;
    for (size_t i = 0; i < A.size() && same; ++i)
      same = std::abs(out.lambda(static_cast<Eigen::Index>(i)) - impulse(A[i])) <= 1e-8 * pmax;
    out.worst = 1.0;
    const double vscale = v.cwiseAbs().maxCoeff() + out.vplus.cwiseAbs().maxCoeff();
    for (const ImpactEntry& en : es)
      out.worst = std::min(out.worst, outcome_margin(m.friction[static_cast<size_t>(en.f)],
                                                     d[static_cast<size_t>(en.f)], en, out.lambda,
                                                     out.vplus, vscale));
    if (same && out.worst >= -kSqrtEps) return true;
  }
  return false;
}

// mu[c] of a contact sliding after the impact: its normal's column moves by
// the slide's column / mu (dB), so dlambda = -(X G B)^-1 X G dB lambda and
// dv+ = G (dB lambda + B dlambda), into dR's velocity rows.
void cone_impact_mu(const mech::MechanicalModel& m, const std::vector<int>& d,
                    const std::vector<SensParam>& params, int nx0, const MatrixXd& G,
                    const std::vector<ImpactEntry>& es, const ConeImpactSolution& sol,
                    MatrixXd& dR) {
  const Eigen::Index N = G.rows();
  for (size_t p = 0; p < params.size(); ++p) {
    if (params[p].kind != 'u') continue;
    const auto en = std::find_if(es.begin(), es.end(),
                                 [&](const ImpactEntry& x) { return x.f == params[p].j; });
    if (en == es.end() || en->mode == FrictionMode::kStick) continue;
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(en->f)];
    MatrixXd dB = MatrixXd::Zero(N, sol.s.B.cols());
    const double step = std::numbers::pi / std::max(d[static_cast<size_t>(en->f)], 1);
    if (cone_slip(en->mode)) {
      const bool face = cone_on_face(en->mode);
      const double ang = (cone_index(en->mode) + (face ? 0.5 : 0.0)) * step;
      dB.col(en->a) = -(face ? std::cos(step / 2) : 1.0) * (std::cos(ang) * VectorXd(fc.tangent) +
                                                            std::sin(ang) * VectorXd(fc.tangent2));
    } else {
      dB.col(en->a) =
          -(en->mode == FrictionMode::kSlipPositive ? 1.0 : -1.0) * VectorXd(fc.tangent);
    }
    const VectorXd dlambda = -sol.W.solve(sol.s.X * G * dB * sol.lambda);
    dR.block(N, nx0 + static_cast<Eigen::Index>(p), N, 1) =
        G * (dB * sol.lambda) + sol.GB * dlambda;
  }
}

}  // namespace

bool Sensitivity::cone_impact_map(double t, const EventResult::ImpactRound& rd, MatrixXd& J,
                                  MatrixXd& dR) {
  const mech::MechanicalModel& m = *model_.mechanical;
  int first3d = -1;
  for (const mech::FrictionalContact& fc : m.friction)
    if (first3d < 0 && fc.is_3d() &&
        std::find(rd.closed.begin(), rd.closed.end(), fc.contact) != rd.closed.end())
      first3d = fc.contact;
  if (first3d < 0) return friction_impact_map(t, rd, J, dR);
  if (!m.gap_inputs.empty() || rd.outcome.size() != static_cast<size_t>(m.num_constraints())) {
    lose_all(t, first3d,
             "an impact with 3-D friction on a moving stop: its derivative is not computed");
    return false;
  }
  const MatrixXd E = MatrixXd(m.E);
  const VectorXd& v = rd.v_before;
  const VectorXd e = law_ == 'i' ? VectorXd::Zero(rd.restitution.size()) : rd.restitution;
  const ImpactActive act = impact_active(rd, E);
  const std::vector<int>& A = act.A;
  const double pmax = act.pmax, amax = act.amax;
  VectorXd R1(static_cast<Eigen::Index>(A.size()));
  VectorXd erate = VectorXd::Zero(static_cast<Eigen::Index>(A.size()));  // e[c]'s a_c
  for (size_t i = 0; i < A.size(); ++i) {
    const double ar = E.row(A[i]).dot(v);
    if (e(A[i]) != 0.0 && std::abs(ar) <= kSqrtEps * amax) {
      lose_all(t, A[i],
               "an impact with 3-D friction at a zero approach rate with restitution: not "
               "differentiable");
      return false;
    }
    R1(static_cast<Eigen::Index>(i)) = 1.0 + (ar < 0.0 ? e(A[i]) : 0.0);
    if (ar < 0.0 && law_ != 'i') erate(static_cast<Eigen::Index>(i)) = ar;
  }
  std::vector<ImpactEntry> es;
  std::vector<std::vector<FrictionMode>> choices;
  if (const int bad = impact_entries(m, cone_d_, A, rd.outcome, es, choices); bad >= 0) {
    lose_all(t, bad, "an impact with friction whose outcome at this contact is not derived");
    return false;
  }
  double total = 1.0;
  for (const auto& c : choices) total *= static_cast<double>(c.size());
  ConeImpactSolution sol;
  if (total > 4096.0 ||
      !solve_outcome(m, cone_d_, E, G_, A, R1, v, rd.impulse, pmax, es, choices, sol)) {
    lose_all(t, first3d,
             "an impact with 3-D friction whose outcome no linear map at a facet reproduces "
             "(not derived)");
    return false;
  }
  if (sol.worst <= kSqrtEps) {
    lose_all(t, first3d,
             "an impact with 3-D friction at the boundary of its outcome (the impulse on the "
             "polygon's boundary, or the post-impact sliding velocity on a region's boundary or "
             "at zero): stick and slip meet there, no derivative");
    return false;
  }
  const double vmax = v.cwiseAbs().maxCoeff() + sol.vplus.cwiseAbs().maxCoeff();
  for (int r : rd.closed)
    if (std::find(A.begin(), A.end(), r) == A.end() &&
        std::abs(E.row(r).dot(sol.vplus)) <= kSqrtEps * std::max(amax, vmax)) {
      lose_all(t, r,
               "degenerate impact: a zero impulse and a zero separation rate (the impact LCP's "
               "active set is not locally constant)");
      return false;
    }
  J = MatrixXd::Identity(n_, n_);
  if (sol.s.X.rows() > 0) {
    J.block(N_, N_, N_, N_) -= sol.GB * sol.W.solve(sol.s.R);
    J.block(N_, 2 * N_, N_, 1) = sol.GB * sol.W.solve(sol.s.c);
  }
  cone_impact_mu(m, cone_d_, cols_.params, nx0_, G_, es, sol, dR);
  // M[i][j] and e[c]: the planar map's terms (X, R, B and c do not depend
  // on M; e moves R's row of an approaching contact).
  mass_restitution_impact_columns(cols_.params, nx0_, G_, sol.GB, sol.s.X, sol.W, sol.lambda, A,
                                  erate, dR);
  return true;
}

}  // namespace lcsim::sim::detail
