// Coulomb friction in three dimensions at an impact (issue 27): the
// polyhedral cone of Stewart and Trinkle (an inscribed pyramid of 2d edges)
// as one LCP with Moreau's LCP (3.69)-(3.70) on the normals and Newton's
// restitution on the approaching normals, as the planar law (friction.cpp,
// thesis §2.5.3); see impact.hpp, moreau_friction_cone.
#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/redundant.hpp>
#include <limits>
#include <optional>

#include "impact/detail.hpp"

namespace lcsim::impact {

std::pair<double, double> cone_edge(int i, int d) {
  // Angle pi i/d = (2i/d) pi/2: exact at the quarter turns.
  if ((2 * i) % d == 0) {
    switch (((2 * i) / d) % 4) {
      case 0:
        return {1.0, 0.0};
      case 1:
        return {0.0, 1.0};
      case 2:
        return {-1.0, 0.0};
      default:
        return {0.0, -1.0};
    }
  }
  const double a = std::acos(-1.0) * i / d;
  return {std::cos(a), std::sin(a)};
}

ConeFacet cone_facet(double u1, double u2, int d) {
  const int n = 2 * d;
  const auto along = [&](int i) {
    const auto [c, s] = cone_edge(((i % n) + n) % n, d);
    return c * u1 + s * u2;
  };
  int best = 0;
  for (int i = 1; i < n; ++i)
    if (along(i) < along(best)) best = i;
  const double speed = std::hypot(u1, u2);
  const int prev = (best + n - 1) % n, next = (best + 1) % n;
  ConeFacet f{best, false};
  // Ties to rounding of a velocity on the face's bisector (cone_facet's comment).
  if (along(next) - along(best) <= 1e-9 * speed)
    f.face = true;
  else if (along(prev) - along(best) <= 1e-9 * speed)
    f = ConeFacet{prev, true};
  // d = 1: the polygon is a segment with two sides, faces 0 and 1 (outward
  // normals +t2 and -t2); the one opposing u.
  if (f.face && d == 1) f.edge = u2 > 0 ? 1 : 0;
  return f;
}

std::string cone_mode_text(ContactOutcome o, ConeFacet facet) {
  switch (o) {
    case ContactOutcome::kStick:
      return "stick";
    case ContactOutcome::kSlip:
      return (facet.face ? "slip-face-" : "slip-edge-") + std::to_string(facet.edge);
    case ContactOutcome::kSlipPositive:
    case ContactOutcome::kSlipNegative:
      return to_string(o);
    default:
      return "open";
  }
}

// Stewart and Trinkle's LCP (impact.hpp, friction_cone_lcp).
FrictionLcp friction_cone_lcp(const MatrixXd& Wb, const VectorXd& rate_N, const VectorXd& rate_D,
                              const std::vector<int>& normal_of, const std::vector<int>& first,
                              const std::vector<int>& d, const VectorXd& mu) {
  const Eigen::Index nn = rate_N.size(), ne = rate_D.size(), nf = mu.size();
  const Eigen::Index n = nn + ne + nf;
  FrictionLcp out;
  out.M = MatrixXd::Zero(n, n);
  out.q = VectorXd::Zero(n);
  out.M.topLeftCorner(nn + ne, nn + ne) = Wb;
  for (Eigen::Index f = 0; f < nf; ++f) {
    const size_t fs = static_cast<size_t>(f);
    out.M(nn + ne + f, normal_of[fs]) = mu(f);
    for (int i = 0; i < 2 * d[fs]; ++i) {
      out.M(nn + first[fs] + i, nn + ne + f) = 1.0;
      out.M(nn + ne + f, nn + first[fs] + i) = -1.0;
    }
  }
  out.q.head(nn) = rate_N;
  out.q.segment(nn, ne) = rate_D;
  return out;
}

// Solves the cone's LCP: impact::solve_friction_lcp, then Lemke's own z,
// each accepted only when detail::check_cone_lcp finds it a solution on the
// impulses and rates. Lemke's z is tried because the row-scaled test
// measures a row against its own terms, and the row of an edge orthogonal
// to the velocity (sticking with the velocity along an edge or a bisector)
// is formed of products cos(pi/2) |D||v| ~ 1e-17: its rounding, 1e-16, is
// then 30% of its terms although it is 1e-16 of the rates' scale, which is
// what check_cone_lcp measures it against. It was accepted before on the
// natural residual relative to |z|_inf, which a diverging slack inflates:
// bullet3's cube_small.urdf gave lambda_N = 0 beside 0.28 N s of edge
// impulses with xi = 5.7e11 m/s. Neither accepted: the failure, naming
// the worst row of Lemke's z, its status the first solve's, or Lemke's own
// (a ray termination, a limit) when the first was a numerical failure.
lcp::Result solve_friction_cone_lcp(const FrictionLcp& p, const lcp::Solver& solver, int* solves,
                                    std::string* tried) {
  lcp::Result res = solve_friction_lcp(p, solver, solves, tried);  // checked there
  if (res.ok()) return res;
  lcp::Options opt;
  lcp::Result r = lcp::make_solver("lemke")->solve(p.M, p.q, opt);
  if (solves) ++*solves;
  if (tried) *tried += ", lemke (impulses and rates)";
  if (r.z.size() != p.q.size() || !r.z.allFinite()) return res;
  r.z = r.z.cwiseMax(0.0);
  const detail::ConeLcpCheck c = detail::check_cone_lcp(p, r.z);
  if (c.ok()) {
    r.status = lcp::Status::kSolved;
    r.message.clear();
    return r;
  }
  if (res.status == lcp::Status::kNumericalFailure && r.status != lcp::Status::kSolved)
    res.status = r.status;  // a ray termination says more than a refused residual
  res.worst_row = static_cast<int>(c.row);
  res.message += std::string(res.message.empty() ? "" : "; ") + "lemke (" +
                 std::string(lcp::to_string(r.status, "solved")) + "): " + c.text();
  return res;
}

namespace detail {

Eigen::Index cone_slack_count(const MatrixXd& M) {
  const Eigen::Index n = M.rows();
  if (M.cols() != n) return 0;
  Eigen::Index k = 0;
  for (; k < n; ++k) {  // grow the trailing zero block by row and column i
    const Eigen::Index i = n - k - 1;
    if (M(i, i) != 0.0 || (M.row(i).tail(k).array() != 0.0).any() ||
        (M.col(i).tail(k).array() != 0.0).any())
      break;
  }
  return k;
}

namespace {
// x / s with 0 / 0 read as 0, as lcp::scaled_residual's.
double ratio(double x, double s) { return s > 0.0 ? x / s : 0.0; }
}  // namespace

std::string ConeLcpCheck::text() const {
  return lcsim::text(what, ": ", worst, " of its scale (impulses ", impulse_scale, " N s, rates ",
                     rate_scale, " m/s) > ", kConeLcpTolerance);
}

ConeLcpCheck check_cone_lcp(const FrictionLcp& p, const VectorXd& z) {
  ConeLcpCheck c;
  const Eigen::Index n = p.q.size();
  if (z.size() != n || p.M.rows() != n || p.M.cols() != n) {
    c.worst = std::numeric_limits<double>::infinity();
    c.what = "a solution of the wrong size";
    return c;
  }
  const Eigen::Index nf = cone_slack_count(p.M), na = n - nf;
  const VectorXd w = p.M * z + p.q;
  // P: the largest impulse (N s); V: the rates' scale (m/s), the rates
  // before the impact and what the impulses change, the slack left out.
  c.impulse_scale = na ? z.head(na).cwiseAbs().maxCoeff() : 0.0;
  c.rate_scale = na ? p.q.head(na).cwiseAbs().maxCoeff() +
                          (p.M.topLeftCorner(na, na).cwiseAbs() * z.head(na).cwiseAbs()).maxCoeff()
                    : 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const bool impulse = i < na;  // an impulse beside a rate, or a slack beside a cone row
    const double zs = impulse ? c.impulse_scale : c.rate_scale;
    const double ws = impulse ? c.rate_scale : c.impulse_scale;
    double r = std::abs(std::min(ratio(z(i), zs), ratio(w(i), ws)));
    if (std::isnan(r)) r = std::numeric_limits<double>::infinity();
    if (r <= c.worst) continue;
    c.worst = r;
    c.row = i;
  }
  if (c.row < 0) return c;
  const Eigen::Index i = c.row;
  if (i >= na) {
    c.cone = i - na;
    c.what = text("friction cone ", c.cone, ": mu lambda_N - sum beta = ", w(i),
                  " N s beside the sliding speed xi = ", z(i), " m/s");
    return c;
  }
  for (Eigen::Index f = 0; f < nf; ++f)
    if (p.M(i, na + f) != 0.0) c.cone = f;  // an edge row of cone f
  for (Eigen::Index f = 0; c.cone < 0 && f < nf; ++f)
    if (p.M(na + f, i) > 0.0) c.cone = f;  // the normal row of cone f
  c.what = text(c.cone >= 0 && p.M(i, na + c.cone) != 0.0 ? "edge" : "normal", " impulse ", z(i),
                " N s beside the rate ", w(i), " m/s");
  if (c.cone >= 0) c.what += text(" (friction cone ", c.cone, ")");
  return c;
}

}  // namespace detail

namespace {

// The closed frictional contacts: normal row in J, index in model.friction,
// d, first edge row, the edge rows D (n_E x N), mu, the surfaces' velocity
// along each edge (cos(pi i/d) times a planar contact's belt velocity).
struct ClosedCone {
  std::vector<int> normal_of, index, d, first;
  MatrixXd D;
  VectorXd mu, edge_velocity;
  Eigen::Index edges() const { return D.rows(); }
};

ClosedCone closed_cone(const mech::MechanicalModel& m, const IndexSet& closed) {
  ClosedCone c;
  int ne = 0;
  for (size_t f = 0; f < m.friction.size(); ++f) {
    const auto it = std::lower_bound(closed.begin(), closed.end(), m.friction[f].contact);
    if (it == closed.end() || *it != m.friction[f].contact) continue;
    c.normal_of.push_back(static_cast<int>(it - closed.begin()));
    c.index.push_back(static_cast<int>(f));
    c.d.push_back(m.edges_of(m.friction[f]));
    c.first.push_back(ne);
    ne += 2 * c.d.back();
  }
  const Eigen::Index nf = static_cast<Eigen::Index>(c.index.size());
  c.D.resize(ne, m.dofs());
  c.mu.resize(nf);
  c.edge_velocity.resize(ne);
  for (Eigen::Index f = 0; f < nf; ++f) {
    const size_t fs = static_cast<size_t>(f);
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(c.index[fs])];
    const VectorXd t1 = VectorXd(fc.tangent);
    const VectorXd t2 = fc.is_3d() ? VectorXd(fc.tangent2) : VectorXd::Zero(m.dofs());
    for (int i = 0; i < 2 * c.d[fs]; ++i) {
      const auto [cs, sn] = cone_edge(i, c.d[fs]);
      c.D.row(c.first[fs] + i) = (cs * t1 + sn * t2).transpose();
      c.edge_velocity(c.first[fs] + i) = cs * fc.velocity;
    }
    c.mu(f) = fc.mu;
  }
  return c;
}

FrictionLcp cone_lcp(const MatrixXd& Wb, const VectorXd& rate_N, const VectorXd& rate_D,
                     const ClosedCone& c) {
  return friction_cone_lcp(Wb, rate_N, rate_D, c.normal_of, c.first, c.d, c.mu);
}

// The friction impulse along t and t2 of contact f from its edge impulses.
std::pair<double, double> tangential(const ClosedCone& c, size_t f, const VectorXd& beta) {
  double p1 = 0.0, p2 = 0.0;
  for (int i = 0; i < 2 * c.d[f]; ++i) {
    const auto [cs, sn] = cone_edge(i, c.d[f]);
    p1 += cs * beta(c.first[f] + i);
    p2 += sn * beta(c.first[f] + i);
  }
  return {p1, p2};
}

constexpr const char* kPainleveTail =
    "; the friction impact LCP may have no solution or several (not resolved)";

// The single-contact Painlevé test, before the LCP is solved: a contact
// alone with W_NN - mu max_i |W_N D_i| <= 0 (friction on that edge presses
// it shut whatever the others do). "" when there is none.
std::string cone_painleve_alone(const mech::MechanicalModel& m, const IndexSet& closed,
                                const ClosedCone& c, const MatrixXd& W, const MatrixXd& WND) {
  for (size_t f = 0; f < c.index.size(); ++f) {
    const int j = c.normal_of[f], n = 2 * c.d[f];
    Eigen::Index worst = 0;
    const double w = WND.row(j).segment(c.first[f], n).cwiseAbs().maxCoeff(&worst);
    const double mu = c.mu(static_cast<Eigen::Index>(f)), coef = W(j, j) - mu * w;
    // Relative to the terms that form it: below that it is zero to rounding.
    if (coef > 1e-12 * (W(j, j) + mu * w)) continue;
    const int row = closed[static_cast<size_t>(j)];
    return text("Painlevé-type case at contact ", row, " ('", m.constraints[row],
                "'): W_NN - mu max_i |W_N D_i| = ", W(j, j), " - ", mu, " * ", w, " = ", coef,
                " <= 0, so friction on the edge ", static_cast<int>(worst),
                " or its opposite presses the contact shut");
  }
  return "";
}

// The facet of maximal dissipation for contact f sliding at v (the one
// friction takes against that sliding: cone_facet), or none when the
// sliding is zero to the rounding of the terms of t'v, t2'v (scale: |v|
// summed with the other velocity of the impact, as set_cone_outcomes).
std::optional<ConeFacet> sliding_facet(const mech::MechanicalModel& m, const ClosedCone& c,
                                       size_t f, const VectorXd& v, const VectorXd& vv) {
  const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(c.index[f])];
  const double u1 = fc.tangent.dot(v) - fc.velocity;
  // d = 1 has no friction along t2: only the sliding along t counts.
  const bool two = fc.is_3d() && c.d[f] > 1;
  const double u2 = two ? fc.tangent2.dot(v) : 0.0;
  double scale = fc.tangent.cwiseAbs().dot(vv) + std::abs(fc.velocity);
  if (two) scale += fc.tangent2.cwiseAbs().dot(vv);
  if (std::hypot(u1, u2) <= mech::zero_tolerance(scale)) return std::nullopt;
  return cone_facet(u1, u2, c.d[f]);
}

// The Painlevé test on the solved LCP (issue 27: by solving, not by
// enumerating every edge choice in advance). Each closed contact takes the
// mode the solution gives it: sliding after the impact, its friction frozen
// on the facet of maximal dissipation (sliding_facet: an edge D_i, or a
// face's midpoint (D_i + D_(i+1))/2, at mu times the normal impulse),
// whether or not it has a normal impulse (if pressed, that is the friction
// it takes); else sticking, its rows t (and for d >= 2 the next edge, which
// with t spans the tangent plane) held. detail::no_painleve_after_solve
// judges the normal matrix of these modes (a P-matrix on contacts of
// independent normal rows, the sticking rows eliminated); when it is not,
// the impact is Painlevé-type in these modes (that LCP may have several
// solutions or none) and is refused, naming the contacts and their modes.
// Modes this impact does not take are not judged (before, every choice of
// one edge per contact was, up to 256 choices, and none above: the
// quadruped's landing at d = 1 was refused for a yaw it does not take).
std::string cone_painleve_solved(const mech::MechanicalModel& m, const ImpactInput& in,
                                 const ClosedCone& c, const MatrixXd& Wb, const VectorXd& v_after) {
  const Eigen::Index nj = static_cast<Eigen::Index>(in.closed.size());
  if (c.index.empty() || (c.index.size() == 1 && nj == 1)) return "";
  MatrixXd slip = MatrixXd::Zero(Wb.rows(), nj);
  std::vector<Eigen::Index> stick;
  std::string which;
  const VectorXd vv = in.v.cwiseAbs() + v_after.cwiseAbs();
  for (size_t f = 0; f < c.index.size(); ++f) {
    const int j = c.normal_of[f], n = 2 * c.d[f], first = c.first[f];
    const int row = in.closed[static_cast<size_t>(j)];
    which += text(" ", row, " ('", m.constraints[static_cast<size_t>(row)], "')");
    const std::optional<ConeFacet> facet = sliding_facet(m, c, f, v_after, vv);
    if (!facet) {
      stick.push_back(nj + first);
      if (c.d[f] > 1) stick.push_back(nj + first + 1);
      which += " (stick)";
      continue;
    }
    const double mu = c.mu(static_cast<Eigen::Index>(f));
    const int i = facet->edge;
    if (facet->face)
      slip.col(j) += 0.5 * mu * (Wb.col(nj + first + i) + Wb.col(nj + first + (i + 1) % n));
    else
      slip.col(j) += mu * Wb.col(nj + first + i);
    which += text(facet->face ? " (face " : " (edge ", i, ")");
  }
  if (detail::no_painleve_after_solve(Wb, nj, stick, slip)) return "";
  return "Painlevé-type case at contacts" + which +
         ": with friction in the modes of the impact LCP's solution the normal matrix "
         "W_NN + W_ND diag(mu), the sticking rows eliminated, has a principal minor <= 0 on "
         "contacts of independent normal rows";
}

// Issue 27 with d >= 2 (painleve_cone.cpp): the impact problem in each
// contact's tangent coordinates (t1 = the edge 0, t2 = (D_k - cos D_0)/sin
// of the edge k at a quarter turn, or the edge 1 for odd d), the LCP's
// solution there (tangential), decided by the modes open, stick, 2d edges,
// 2d faces per contact.
detail::PainleveVerdict cone_decided_by_modes(const ImpactInput& in, const ClosedCone& c,
                                              const MatrixXd& Wb, const VectorXd& rate_N,
                                              const VectorXd& rate_D, const VectorXd& z) {
  const Eigen::Index nj = rate_N.size(), nb = Wb.rows();
  detail::ConeModesProblem p;
  p.nj = nj;
  p.normal_of = c.normal_of;
  p.d = c.d;
  p.mu = c.mu;
  Eigen::Index n = nj;
  for (const int d : c.d) {
    p.first_t.push_back(n);
    n += d >= 2 ? 2 : 1;
  }
  MatrixXd S = MatrixXd::Zero(n, nb);  // [u_N; u_t] = S [u_N; u_D]
  VectorXd lambda = VectorXd::Zero(n);
  S.topLeftCorner(nj, nj).setIdentity();
  lambda.head(nj) = z.head(nj);
  const VectorXd beta = z.segment(nj, nb - nj);
  for (size_t f = 0; f < c.d.size(); ++f) {
    const Eigen::Index t = p.first_t[f], e0 = nj + c.first[f];
    const auto [f1, f2] = tangential(c, f, beta);
    S(t, e0) = 1.0;
    lambda(t) = f1;
    if (c.d[f] < 2) continue;
    const int k = c.d[f] % 2 == 0 ? c.d[f] / 2 : 1;
    const auto [ck, sk] = cone_edge(k, c.d[f]);
    S(t + 1, e0 + k) = 1.0 / sk;
    S(t + 1, e0) = -ck / sk;
    lambda(t + 1) = f2;
  }
  VectorXd rates(nb);
  rates << rate_N, rate_D;
  p.Wg = S * Wb * S.transpose();
  p.b = S * rates;
  return detail::decide_cone_painleve_by_modes(p, lambda, detail::closed_labels(in));
}

// Issue 27: cone_painleve_solved is a sufficient condition; when it fails
// (or a contact alone is Painlevé-type, `alone`, found before the solve),
// the impact is decided by the contacts' modes: with every closed
// frictional contact at d = 1 (friction along t only, its edges +t and -t)
// as the planar law's (detail::decide_painleve_by_modes on the rows of +t),
// so d = 1 keeps the planar law's diagnoses; with any d >= 2 by
// cone_decided_by_modes.
std::string cone_painleve_decided(const mech::MechanicalModel& m, const ImpactInput& in,
                                  const ClosedCone& c, const MatrixXd& Wb, const std::string& alone,
                                  const VectorXd& rate_N, const VectorXd& rate_D, const VectorXd& z,
                                  const VectorXd& v_after) {
  std::string p = alone.empty() ? cone_painleve_solved(m, in, c, Wb, v_after) : alone;
  if (p.empty()) return p;
  if (std::any_of(c.d.begin(), c.d.end(), [](int d) { return d != 1; })) {
    const detail::PainleveVerdict d = cone_decided_by_modes(in, c, Wb, rate_N, rate_D, z);
    if (d.unique) return "";
    return p + "; " + d.message + (d.enumerated ? "" : kPainleveTail);
  }
  const Eigen::Index nj = rate_N.size(), nf = c.mu.size();
  std::vector<Eigen::Index> idx;  // the normals, then each contact's +t row
  for (Eigen::Index j = 0; j < nj; ++j) idx.push_back(j);
  for (const int first : c.first) idx.push_back(nj + first);
  const Eigen::Index n = nj + nf;
  MatrixXd Wg(n, n);
  VectorXd b(n), lambda(n);
  for (Eigen::Index a = 0; a < n; ++a) {
    const Eigen::Index ra = idx[static_cast<size_t>(a)];
    for (Eigen::Index e = 0; e < n; ++e) Wg(a, e) = Wb(ra, idx[static_cast<size_t>(e)]);
    b(a) = a < nj ? rate_N(a) : rate_D(ra - nj);
    // lambda_T = beta_+t - beta_-t (cone_edge(1, 1) = (-1, 0)).
    lambda(a) = a < nj ? z(a) : z(ra) - z(ra + 1);
  }
  const detail::PainleveVerdict d = detail::decide_painleve_by_modes(
      Wg, b, nj, c.normal_of, c.mu, lambda, detail::closed_labels(in));
  if (d.unique) return "";
  return p + "; " + d.message + (d.enumerated ? "" : kPainleveTail);
}

// Impulses, outcomes and facets per constraint; planar contacts as
// friction.cpp's set_outcomes (stick, slip+, slip-), 3-D ones stick or slip
// with cone_facet of the post-impact sliding velocity.
void set_cone_outcomes(const mech::MechanicalModel& m, const ImpactInput& in, const ClosedCone& c,
                       const VectorXd& lambda_N, const VectorXd& beta, double tiny,
                       ImpactResult& out) {
  for (size_t f = 0; f < c.index.size(); ++f) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(c.index[f])];
    const auto row = static_cast<size_t>(fc.contact);
    std::tie(out.friction_impulse(fc.contact), out.friction_impulse2(fc.contact)) =
        tangential(c, f, beta);
    if (!(lambda_N(c.normal_of[f]) > tiny)) {
      out.outcome[row] = ContactOutcome::kNoImpulse;
      continue;
    }
    const VectorXd vv = in.v.cwiseAbs() + out.v_after.cwiseAbs();
    const double u1 = fc.tangent.dot(out.v_after) - fc.velocity;
    const double u2 = fc.is_3d() ? fc.tangent2.dot(out.v_after) : 0.0;
    // Zero to rounding: the terms of t'v+ and t'v-, as friction.cpp's.
    double scale = fc.tangent.cwiseAbs().dot(vv) + std::abs(fc.velocity);
    if (fc.is_3d()) scale += fc.tangent2.cwiseAbs().dot(vv);
    if (std::hypot(u1, u2) <= mech::zero_tolerance(scale))
      out.outcome[row] = ContactOutcome::kStick;
    else if (!fc.is_3d())
      out.outcome[row] = u1 > 0 ? ContactOutcome::kSlipPositive : ContactOutcome::kSlipNegative;
    else {
      out.outcome[row] = ContactOutcome::kSlip;
      out.facet[row] = cone_facet(u1, u2, c.d[f]);
    }
  }
}

// The constraint (row of E) of row i of the cone's LCP (the normals, each
// contact's edges, each contact's cone row), or -1 when i is none.
int lcp_row_constraint(const mech::MechanicalModel& m, const IndexSet& closed, const ClosedCone& c,
                       int i) {
  const int nj = static_cast<int>(closed.size()), ne = static_cast<int>(c.edges());
  if (i < 0) return -1;
  if (i < nj) return closed[static_cast<size_t>(i)];
  for (size_t f = 0; f < c.index.size(); ++f) {
    const int e = i - nj - c.first[f];
    if ((e >= 0 && e < 2 * c.d[f]) || i - nj - ne == static_cast<int>(f))
      return m.friction[static_cast<size_t>(c.index[f])].contact;
  }
  return -1;
}

// The work of moving surfaces on the body (J): planar contacts' belts.
double surface_work(const mech::MechanicalModel& m, const ClosedCone& c, const ImpactResult& out) {
  double w = 0.0;
  for (size_t f = 0; f < c.index.size(); ++f) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(c.index[f])];
    w += fc.velocity * out.friction_impulse(fc.contact);
  }
  return w;
}

}  // namespace

ImpactResult moreau_friction_cone(const ImpactInput& in, const lcp::Solver& solver) {
  ImpactResult out;
  const auto s = detail::prepare(in, out, /*handles_friction=*/true);
  if (in.model != nullptr && out.v_after.size() == in.model->dofs()) {
    const int k = in.model->num_constraints();
    out.friction_impulse = out.friction_impulse2 = VectorXd::Zero(k);
    out.outcome.assign(static_cast<size_t>(k), ContactOutcome::kNone);
    out.facet.assign(static_cast<size_t>(k), ConeFacet{});
  }
  if (!s) return out;
  const mech::MechanicalModel& m = *in.model;
  const ClosedCone c = closed_cone(m, in.closed);
  const Eigen::Index nj = s->W.rows(), ne = c.edges();
  MatrixXd MinvDt = c.D.transpose();
  s->L.triangularView<Eigen::Lower>().solveInPlace(MinvDt);
  s->L.transpose().triangularView<Eigen::Upper>().solveInPlace(MinvDt);
  MatrixXd Wb(nj + ne, nj + ne);
  Wb.topLeftCorner(nj, nj) = s->W;
  Wb.topRightCorner(nj, ne) = s->EJ * MinvDt;
  Wb.bottomLeftCorner(ne, nj) = Wb.topRightCorner(nj, ne).transpose();
  Wb.bottomRightCorner(ne, ne) = c.D * MinvDt;
  // A contact alone Painlevé-type is decided after the solve by the modes
  // (issue 27), as the planar law's; refused when no solver solves the LCP.
  const std::string alone = cone_painleve_alone(m, in.closed, c, s->W, Wb.topRightCorner(nj, ne));
  const VectorXd rate_N = s->a + s->e_J.cwiseProduct(s->a.cwiseMin(0.0));
  const FrictionLcp lcp = cone_lcp(Wb, rate_N, c.D * in.v - c.edge_velocity, c);
  std::string tried;
  const lcp::Result res = solve_friction_cone_lcp(lcp, solver, &out.lcp_solves, &tried);
  out.lcp_status = res.status;
  if (!res.ok()) {
    out.painleve = !alone.empty();
    out.message = out.painleve ? alone + kPainleveTail : detail::friction_lcp_failure(tried, res);
    if (const int row = lcp_row_constraint(m, in.closed, c, res.worst_row);
        !out.painleve && row >= 0)
      out.message +=
          text(" at contact ", row, " ('", m.constraints[static_cast<size_t>(row)], "')");
    return out;
  }
  const VectorXd lambda_N = res.z.head(nj), beta = res.z.segment(nj, ne);
  const double tiny = detail::friction_mode_threshold(*s);
  const VectorXd v_after = in.v + s->MinvEt * lambda_N + MinvDt * beta;
  if (std::string p =
          cone_painleve_decided(m, in, c, Wb, alone, rate_N, lcp.q.segment(nj, ne), res.z, v_after);
      !p.empty()) {
    out.painleve = true;
    out.message = p;
    return out;
  }
  detail::finish(in, *s, lambda_N, v_after, tiny, out);
  set_cone_outcomes(m, in, c, lambda_N, beta, tiny, out);
  out.status = Status::kOk;
  detail::flag_friction_energy_gain(surface_work(m, c, out), out);
  return out;
}

}  // namespace lcsim::impact
