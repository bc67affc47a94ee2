// The planar Coulomb impact as one LCP (issue 17): thesis §2.5.3 (Lemma 2.5.1,
// the relay characteristic as complementarity) applied to the tangential
// impulse of each frictional contact, Moreau's LCP (3.69)-(3.70) on the
// normals, Newton's restitution on the approaching normals.
#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/redundant.hpp>
#include <limits>

#include "impact/detail.hpp"

namespace lcsim::impact {

const char* to_string(ContactOutcome o) {
  switch (o) {
    case ContactOutcome::kNone:
      return "none";
    case ContactOutcome::kNoImpulse:
      return "no-impulse";
    case ContactOutcome::kStick:
      return "stick";
    case ContactOutcome::kSlipPositive:
      return "slip+";
    case ContactOutcome::kSlipNegative:
      return "slip-";
    case ContactOutcome::kSlip:
      return "slip";
  }
  return "?";
}

FrictionLcp friction_lcp(const MatrixXd& Wg, const VectorXd& rate_N, const VectorXd& rate_T,
                         const std::vector<int>& normal_of, const VectorXd& mu) {
  const Eigen::Index nn = rate_N.size(), nf = rate_T.size(), n = nn + 2 * nf;
  // (lambda_N, lambda_T) = P z with lambda_T = lambda_R - mu∘lambda_N[F].
  MatrixXd P = MatrixXd::Zero(nn + nf, n);
  P.topLeftCorner(nn, nn).setIdentity();
  P.block(nn, nn, nf, nf).setIdentity();
  for (Eigen::Index f = 0; f < nf; ++f) P(nn + f, normal_of[static_cast<size_t>(f)]) = -mu(f);
  FrictionLcp out;
  out.M = MatrixXd::Zero(n, n);
  out.q = VectorXd::Zero(n);
  // Rows 0..nn: u_N+ (with restitution); nn..nn+nf: u_T+ + xi;
  // nn+nf..n: 2 mu lambda_N - lambda_R (the friction cone's two edges,
  // mu lambda_N + lambda_T >= 0 and mu lambda_N - lambda_T >= 0, as
  // lambda_R >= 0 and this row).
  out.M.topRows(nn + nf) = Wg * P;
  out.M.block(nn, nn + nf, nf, nf).setIdentity();
  for (Eigen::Index f = 0; f < nf; ++f) {
    out.M(nn + nf + f, normal_of[static_cast<size_t>(f)]) = 2.0 * mu(f);
    out.M(nn + nf + f, nn + f) = -1.0;
  }
  out.q.head(nn) = rate_N;
  out.q.segment(nn, nf) = rate_T;
  return out;
}

void friction_impulses(const VectorXd& z, int n_normal, const std::vector<int>& normal_of,
                       const VectorXd& mu, VectorXd& lambda_N, VectorXd& lambda_T) {
  const Eigen::Index nf = mu.size();
  lambda_N = z.head(n_normal);
  lambda_T.resize(nf);
  for (Eigen::Index f = 0; f < nf; ++f)
    lambda_T(f) = z(n_normal + f) - mu(f) * lambda_N(normal_of[static_cast<size_t>(f)]);
}

lcp::Result solve_friction_lcp(const FrictionLcp& p, const lcp::Solver& solver, int* solves,
                               std::string* tried) {
  lcp::Options opt;
  lcp::Result res;
  // A row-scaled pass is kept only when the impulses and rates obey the
  // law (detail::check_cone_lcp: the row-scaled test judges complementarity
  // against |z|_inf, which a diverging slack inflates).
  const auto physical = [&](lcp::Result& r) {
    const detail::ConeLcpCheck c = detail::check_cone_lcp(p, r.z);
    if (c.ok()) return true;
    r.status = lcp::Status::kNumericalFailure;
    r.worst_row = static_cast<int>(c.row);
    r.message = "its solution refused: " + c.text();
    return false;
  };
  for (const double tol : {1e-12, 1e-10}) {
    opt.tolerance = tol;
    res = lcp::solve_scaled(solver, p.M, p.q, opt, solves, tried);
    if (res.ok() && physical(res)) return res;
  }
  for (const char* name : {"lemke", "enum"}) {
    if (std::string(name) == "enum" && p.q.size() > 12) continue;
    lcp::Result r = lcp::make_solver(name)->solve(p.M, p.q, opt);
    if (solves) ++*solves;
    if (tried) *tried += std::string(", ") + name + " (zeros below rounding)";
    if (r.z.size() != p.q.size() || !r.z.allFinite()) continue;
    const double zmax = r.z.cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < r.z.size(); ++i)
      if (std::abs(r.z(i)) <= 64 * std::numeric_limits<double>::epsilon() * zmax) r.z(i) = 0.0;
    lcp::Result chk = lcp::evaluate(p.M, p.q, r.z);
    chk.scaled_residual = lcp::scaled_residual(p.M, p.q, r.z, &chk.worst_row);
    if (chk.scaled_residual <= opt.tolerance && detail::check_cone_lcp(p, r.z).ok()) {
      chk.status = lcp::Status::kSolved;
      chk.pivots = r.pivots;
      return chk;
    }
  }
  return res;
}

namespace {

// The closed frictional contacts: their normal row in J, index in
// model.friction, tangent rows and mu.
struct ClosedFriction {
  std::vector<int> normal_of;  // position in J
  std::vector<int> index;      // into model.friction
  MatrixXd T;                  // tangent rows (n_F x N)
  VectorXd mu;
  VectorXd velocity;  // the surfaces' velocities (sliding = T v - velocity)
};

ClosedFriction closed_friction(const mech::MechanicalModel& m, const IndexSet& closed) {
  ClosedFriction c;
  for (size_t f = 0; f < m.friction.size(); ++f) {
    const auto it = std::lower_bound(closed.begin(), closed.end(), m.friction[f].contact);
    if (it == closed.end() || *it != m.friction[f].contact) continue;
    c.normal_of.push_back(static_cast<int>(it - closed.begin()));
    c.index.push_back(static_cast<int>(f));
  }
  const Eigen::Index nf = static_cast<Eigen::Index>(c.index.size());
  c.T.resize(nf, m.dofs());
  c.mu.resize(nf);
  c.velocity.resize(nf);
  for (Eigen::Index f = 0; f < nf; ++f) {
    const mech::FrictionalContact& fc = m.friction[static_cast<size_t>(c.index[f])];
    c.T.row(f) = VectorXd(fc.tangent).transpose();
    c.mu(f) = fc.mu;
    c.velocity(f) = fc.velocity;
  }
  return c;
}

// Painlevé-type cases. With the frictional contacts sliding in directions
// sigma (lambda_T = -sigma mu lambda_N), the normal impulses solve the LCP
// with matrix W_NN - W_NT diag(sigma mu) S (S picks the frictional rows);
// when it is not a P-matrix that LCP may have no solution or several.
// Before the solve, one contact alone: its coefficient W_NN - mu |W_NT| <= 0
// (painleve_alone). After it, the modes the solution gives (issue 27:
// painleve_solved; each contact slipping with the sign of its sliding after
// the impact, or sticking, its row held), judged by
// detail::no_painleve_after_solve; the sign patterns this impact does not
// take are not judged (before, every pattern was, up to 8 frictional
// contacts, and none above). The message, or "" when there is none. Both
// are sufficient conditions: painleve_decided then enumerates the modes.
constexpr const char* kPainleveTail =
    "; the friction impact LCP may have no solution or several (not resolved)";

std::string painleve_alone(const mech::MechanicalModel& m, const IndexSet& closed,
                           const ClosedFriction& c, const MatrixXd& W, const MatrixXd& WNT) {
  for (size_t f = 0; f < c.index.size(); ++f) {
    const int j = c.normal_of[f];
    const double wnn = W(j, j), wnt = WNT(j, static_cast<Eigen::Index>(f));
    const double mu = c.mu(static_cast<Eigen::Index>(f));
    const double coef = wnn - mu * std::abs(wnt);
    // Relative to the terms that form it: below that it is zero to rounding.
    if (coef > 1e-12 * (wnn + mu * std::abs(wnt))) continue;
    const int row = closed[static_cast<size_t>(j)];
    return text("Painlevé-type case at contact ", row, " ('", m.constraints[row],
                "'): W_NN - mu |W_NT| = ", wnn, " - ", mu, " * ", std::abs(wnt), " = ", coef,
                " <= 0, so sliding ", (wnt > 0 ? "along +t" : "along -t"),
                " presses the contact shut");
  }
  return "";
}

std::string painleve_solved(const ImpactInput& in, const ClosedFriction& c, const MatrixXd& Wg,
                            const VectorXd& v_after) {
  const Eigen::Index nf = c.mu.size(), nj = Wg.rows() - nf;
  if (nf < 1 || (nf == 1 && nj == 1)) return "";
  MatrixXd slip = MatrixXd::Zero(Wg.rows(), nj);
  std::vector<Eigen::Index> stick;
  std::string msg = "Painlevé-type case at contacts";
  const VectorXd vv = in.v.cwiseAbs() + v_after.cwiseAbs();
  for (Eigen::Index f = 0; f < nf; ++f) {
    const int j = c.normal_of[static_cast<size_t>(f)];
    const int row = in.closed[static_cast<size_t>(j)];
    msg += text(" ", row, " ('", in.model->constraints[static_cast<size_t>(row)], "')");
    // Sliding after the impact (zero to the rounding of the terms of t'v,
    // as set_outcomes): sigma its sign, lambda_T = -sigma mu lambda_N, the
    // column -sigma mu W_g t; else it sticks (its row held).
    const double ut = c.T.row(f).dot(v_after) - c.velocity(f);
    const double scale = c.T.row(f).cwiseAbs().dot(vv) + std::abs(c.velocity(f));
    if (std::abs(ut) <= mech::zero_tolerance(scale)) {
      stick.push_back(nj + f);
      msg += " (stick)";
      continue;
    }
    const double sigma = ut > 0 ? 1.0 : -1.0;
    slip.col(j) -= sigma * c.mu(f) * Wg.col(nj + f);
    msg += sigma > 0 ? " (slip+)" : " (slip-)";
  }
  if (detail::no_painleve_after_solve(Wg, nj, stick, slip)) return "";
  return msg +
         ": with these modes of the impact LCP's solution the normal matrix W_NN - W_NT "
         "diag(sigma mu), the sticking rows eliminated, is not a P-matrix on contacts of "
         "independent normal rows";
}

// Issue 27: painleve_solved is a sufficient condition; when it fails, the
// impact is decided by the contacts' modes (detail::decide_painleve_by_modes):
// accepted ("") when they give one motion, the LCP's; else the refusal,
// saying what the enumeration found (or that it was above its bound).
// `alone`: painleve_alone's finding before the solve, judged the same way.
std::string painleve_decided(const ImpactInput& in, const ClosedFriction& c, const MatrixXd& Wg,
                             const std::string& alone, const VectorXd& rate_N,
                             const VectorXd& lambda_N, const VectorXd& lambda_T,
                             const VectorXd& v_after) {
  std::string p = alone.empty() ? painleve_solved(in, c, Wg, v_after) : alone;
  if (p.empty()) return p;
  const Eigen::Index nj = lambda_N.size(), nf = lambda_T.size();
  const VectorXd b = (VectorXd(nj + nf) << rate_N, c.T * in.v - c.velocity).finished();
  const VectorXd lambda = (VectorXd(nj + nf) << lambda_N, lambda_T).finished();
  const detail::PainleveVerdict d = detail::decide_painleve_by_modes(
      Wg, b, nj, c.normal_of, c.mu, lambda, detail::closed_labels(in));
  if (d.unique) return "";
  return p + "; " + d.message + (d.enumerated ? "" : kPainleveTail);
}

void set_outcomes(const mech::MechanicalModel& m, const ImpactInput& in, const ClosedFriction& c,
                  const VectorXd& lambda_N, const VectorXd& lambda_T, double tiny,
                  ImpactResult& out) {
  for (size_t f = 0; f < c.index.size(); ++f) {
    const Eigen::Index fi = static_cast<Eigen::Index>(f);
    const int row = m.friction[static_cast<size_t>(c.index[f])].contact;
    out.friction_impulse(row) = lambda_T(fi);
    if (!(lambda_N(c.normal_of[f]) > tiny)) {
      out.outcome[static_cast<size_t>(row)] = ContactOutcome::kNoImpulse;
      continue;
    }
    const double ut = c.T.row(fi).dot(out.v_after) - c.velocity(fi);
    // Zero to rounding: the terms of t'v+ and t'v-, as the rates in finish.
    const double scale = c.T.row(fi).cwiseAbs().dot(in.v.cwiseAbs() + out.v_after.cwiseAbs()) +
                         std::abs(c.velocity(fi));
    out.outcome[static_cast<size_t>(row)] =
        std::abs(ut) <= mech::zero_tolerance(scale)
            ? ContactOutcome::kStick
            : (ut > 0 ? ContactOutcome::kSlipPositive : ContactOutcome::kSlipNegative);
  }
}

// The Delassus matrix of normal and tangential rows, [W, E_J M^-1 T'; T
// M^-1 E_J', T M^-1 T'], from MinvTt = M^-1 T'.
MatrixXd delassus(const detail::Setup& s, const ClosedFriction& c, const MatrixXd& MinvTt) {
  const Eigen::Index nj = s.W.rows(), nf = c.mu.size();
  MatrixXd Wg(nj + nf, nj + nf);
  Wg.topLeftCorner(nj, nj) = s.W;
  Wg.topRightCorner(nj, nf) = s.EJ * MinvTt;
  Wg.bottomLeftCorner(nf, nj) = Wg.topRightCorner(nj, nf).transpose();
  Wg.bottomRightCorner(nf, nf) = c.T * MinvTt;
  return Wg;
}

// Flags, and says in out.message, an impact that raised the kinetic energy
// beyond the work of moving surfaces.
void flag_energy_gain(const ClosedFriction& c, const VectorXd& lambda_T, ImpactResult& out) {
  // T+ - T- = lambda' u+ - ½ dv' M dv (dv = v+ - v-), with u_T+ = T v+ the
  // tangential rates; lambda_T (u_T+ - velocity) <= 0 and lambda_N u_N+ = 0
  // for e = 0, so beyond the work of moving surfaces on the body
  // (lambda_T' velocity, a belt) only restitution can make it positive.
  detail::flag_friction_energy_gain(c.velocity.dot(lambda_T), out);
}

}  // namespace

ImpactResult moreau_friction(const ImpactInput& in, const lcp::Solver& solver) {
  // Two tangents somewhere: the general cone (planar contacts as d = 1);
  // planar models keep this path and its numbers.
  if (in.model != nullptr && in.model->has_friction_3d()) return moreau_friction_cone(in, solver);
  ImpactResult out;
  const auto s = detail::prepare(in, out, /*handles_friction=*/true);
  if (in.model != nullptr && out.v_after.size() == in.model->dofs()) {
    out.friction_impulse = VectorXd::Zero(in.model->num_constraints());
    out.outcome.assign(static_cast<size_t>(in.model->num_constraints()), ContactOutcome::kNone);
  }
  if (!s) return out;
  const mech::MechanicalModel& m = *in.model;
  const ClosedFriction c = closed_friction(m, in.closed);
  const Eigen::Index nj = s->W.rows(), nf = c.mu.size();
  MatrixXd MinvTt = c.T.transpose();
  s->L.triangularView<Eigen::Lower>().solveInPlace(MinvTt);
  s->L.transpose().triangularView<Eigen::Upper>().solveInPlace(MinvTt);
  const MatrixXd Wg = delassus(*s, c, MinvTt);
  // A contact alone Painlevé-type is decided after the solve, as the modes.
  const std::string alone = painleve_alone(m, in.closed, c, s->W, Wg.topRightCorner(nj, nf));
  // Newton's restitution on approaching contacts: u_N+ >= -e u_N- there; a
  // closed contact already separating (u_N- >= 0) only needs u_N+ >= 0.
  const VectorXd rate_N = s->a + s->e_J.cwiseProduct(s->a.cwiseMin(0.0));
  const FrictionLcp lcp = friction_lcp(Wg, rate_N, c.T * in.v - c.velocity, c.normal_of, c.mu);
  std::string tried;
  const lcp::Result res = solve_friction_lcp(lcp, solver, &out.lcp_solves, &tried);
  out.lcp_status = res.status;
  if (!res.ok()) {
    out.painleve = !alone.empty();
    out.message = out.painleve ? alone + kPainleveTail : detail::friction_lcp_failure(tried, res);
    return out;
  }
  const VectorXd* z = &res.z;
  VectorXd lambda_N, lambda_T;
  friction_impulses(*z, static_cast<int>(nj), c.normal_of, c.mu, lambda_N, lambda_T);
  const double tiny = detail::friction_mode_threshold(*s);
  const VectorXd v_after = in.v + s->MinvEt * lambda_N + MinvTt * lambda_T;
  if (std::string p = painleve_decided(in, c, Wg, alone, rate_N, lambda_N, lambda_T, v_after);
      !p.empty()) {
    out.painleve = true;
    out.message = p;
    return out;
  }
  detail::finish(in, *s, lambda_N, v_after, tiny, out);
  set_outcomes(m, in, c, lambda_N, lambda_T, tiny, out);
  out.status = Status::kOk;
  flag_energy_gain(c, lambda_T, out);
  return out;
}

namespace detail {

// Rounding of the largest approach rate through the diagonal of W (as
// moreau_newton's).
double friction_mode_threshold(const Setup& s) {
  double tiny = 0.0;
  for (Eigen::Index i = 0; i < s.W.rows(); ++i)
    if (s.W(i, i) > 0.0) tiny = std::max(tiny, std::abs(s.a(i)) / s.W(i, i));
  return tiny * kRelTol;
}

void flag_friction_energy_gain(double surface_work, ImpactResult& out) {
  // Beyond rounding: 1e-12 relative (a few hundred eps of the kinetic energy).
  if (out.energy_after - surface_work > out.energy_before * (1.0 + 1e-12) + 1e-300) {
    out.energy_gain = true;
    out.message = text("kinetic energy rose through the impact, ", out.energy_before, " -> ",
                       out.energy_after,
                       " J: Newton restitution with coupled normal and tangential "
                       "directions (W_NT != 0) can create energy (Kane's paradox)");
  }
}

bool no_painleve_after_solve(const MatrixXd& Wf, Eigen::Index nj,
                             const std::vector<Eigen::Index>& stick_rows,
                             const MatrixXd& slip_cols) {
  if (nj > 12 || slip_cols.cwiseAbs().maxCoeff() == 0.0) return true;
  std::vector<Eigen::Index> idx(static_cast<size_t>(nj));
  for (Eigen::Index i = 0; i < nj; ++i) idx[static_cast<size_t>(i)] = i;
  // An independent subset of the sticking rows (their Gram matrix's
  // nonsingular principal part: dependent rows hold with the others).
  std::vector<Eigen::Index> held;
  if (!stick_rows.empty()) {
    const Eigen::Index ns = static_cast<Eigen::Index>(stick_rows.size());
    MatrixXd G(ns, ns);
    for (Eigen::Index a = 0; a < ns; ++a)
      for (Eigen::Index b = 0; b < ns; ++b)
        G(a, b) = Wf(stick_rows[static_cast<size_t>(a)], stick_rows[static_cast<size_t>(b)]);
    Eigen::FullPivLU<MatrixXd> lu(G);
    lu.setThreshold(1e-10);  // relative to the largest pivot: dependence to rounding
    for (Eigen::Index r = 0; r < lu.rank(); ++r)
      held.push_back(stick_rows[static_cast<size_t>(lu.permutationQ().indices()(r))]);
  }
  const Eigen::Index nh = static_cast<Eigen::Index>(held.size());
  for (const Eigen::Index h : held) idx.push_back(h);
  const Eigen::Index n = nj + nh;
  MatrixXd A(n, n);
  for (Eigen::Index a = 0; a < n; ++a)
    for (Eigen::Index b = 0; b < n; ++b) {
      const Eigen::Index ra = idx[static_cast<size_t>(a)], cb = idx[static_cast<size_t>(b)];
      A(a, b) = Wf(ra, cb) + (b < nj ? slip_cols(ra, b) : 0.0);
    }
  MatrixXd Ns = A.topLeftCorner(nj, nj);
  if (nh > 0) {
    const Eigen::FullPivLU<MatrixXd> lu(A.bottomRightCorner(nh, nh));
    if (!lu.isInvertible()) return true;  // not judged: the held rows' system is singular
    Ns -= A.topRightCorner(nj, nh) * lu.solve(A.bottomLeftCorner(nh, nj));
  }
  return lcp::is_p_matrix(Ns) || lcp::is_p_matrix_on_independent_rows(Ns, Wf.topLeftCorner(nj, nj));
}

std::string friction_lcp_failure(const std::string& tried, const lcp::Result& res) {
  return "friction impact LCP failed (" + tried +
         "): " + std::string(lcp::to_string(res.status, "solved")) +
         (res.message.empty() ? "" : " (" + res.message + ")");
}

}  // namespace detail

}  // namespace lcsim::impact
