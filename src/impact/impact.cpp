// Impact rules: shared set-up, Moreau's LCP with Newton restitution
// ("newton", "inelastic") and the registry of rules by name.
#include <algorithm>
#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "impact/detail.hpp"

namespace lcsim::impact {

namespace detail {

namespace {

// Why `in` cannot be applied by a law (that handles friction or not); ""
// when it can.
std::string refusal(const ImpactInput& in, bool handles_friction) {
  if (in.model == nullptr) return "impact input has no model";
  const mech::MechanicalModel& m = *in.model;
  if (m.has_friction() && !handles_friction)
    return "this impact law does not handle friction (the model has " +
           std::to_string(m.friction.size()) +
           " frictional contacts); the laws 'newton', 'inelastic' and "
           "'moreau-restitution' do";
  const int N = m.dofs(), k = m.num_constraints();
  if (in.v.size() != N)
    return "pre-impact velocity has " + std::to_string(in.v.size()) + " entries, the model has " +
           std::to_string(N) + " coordinates";
  for (size_t i = 0; i < in.closed.size(); ++i)
    if (in.closed[i] < 0 || in.closed[i] >= k || (i > 0 && in.closed[i] <= in.closed[i - 1]))
      return "closed set must be sorted distinct indices in [0, " + std::to_string(k) + ")";
  if (in.restitution.size() != k && in.restitution.size() != 0)
    return "restitution has " + std::to_string(in.restitution.size()) + " entries, the model has " +
           std::to_string(k) + " constraints";
  return "";
}

// The coefficients: the input's, else the model's, else 0.
VectorXd restitution_of(const ImpactInput& in) {
  const mech::MechanicalModel& m = *in.model;
  const int k = m.num_constraints();
  if (in.restitution.size() == k) return in.restitution;
  if (m.restitution.size() == k) return m.restitution;
  return VectorXd::Zero(k);
}

// The closed rows' E_J, e_J, M^-1 E_J', W = E_J M^-1 E_J', a = E_J v, and
// the Cholesky factor L of M.
void set_up_closed(const ImpactInput& in, Setup& s) {
  const mech::MechanicalModel& m = *in.model;
  const int nj = static_cast<int>(in.closed.size());
  s.EJ.resize(nj, m.dofs());
  s.e_J.resize(nj);
  for (int i = 0; i < nj; ++i) {
    s.EJ.row(i) = m.E.row(in.closed[i]);
    s.e_J(i) = s.e(in.closed[i]);
  }
  const Eigen::LLT<MatrixXd> llt(m.M);
  s.MinvEt = llt.solve(s.EJ.transpose());
  s.W = s.EJ * s.MinvEt;
  s.a = s.EJ * in.v;
  s.L = llt.matrixL();
}

}  // namespace

std::optional<Setup> prepare(const ImpactInput& in, ImpactResult& out, bool handles_friction) {
  out = ImpactResult{};
  out.message = refusal(in, handles_friction);
  if (!out.message.empty()) {
    out.status = Status::kInvalidInput;
    return std::nullopt;
  }
  Setup s;
  s.k = in.model->num_constraints();
  s.e = restitution_of(in);
  out.v_after = in.v;
  out.impulse = VectorXd::Zero(s.k);
  out.energy_before = mech::kinetic_energy(*in.model, in.v);
  out.energy_after = out.energy_before;
  if (in.closed.empty()) {
    out.status = Status::kOk;
    return std::nullopt;
  }
  set_up_closed(in, s);
  return s;
}

std::optional<Refined> refine_on_active_set(const Setup& s, const VectorXd& v,
                                            const VectorXd& e_target, const VectorXd& z) {
  const Eigen::Index nj = z.size();
  const VectorXd c = e_target.cwiseProduct(s.a);
  const VectorXd v_lcp = v + s.MinvEt * z;
  const VectorXd rate = s.EJ * v_lcp + c;
  // Rate scale as in finish; the active-set threshold is the LCP's looser
  // acceptance (1e-10 relative): a constraint taken into A wrongly moves v+
  // by at most that, one left out makes the check below reject the result.
  const VectorXd scale = s.EJ.cwiseAbs() * (v.cwiseAbs() + v_lcp.cwiseAbs()) + c.cwiseAbs();
  std::vector<Eigen::Index> act;
  // Not mech::zero_tolerance (mech/tolerances.hpp): 1e-10 relative, the LCP's acceptance.
  for (Eigen::Index i = 0; i < nj; ++i)
    if (z(i) > 0.0 || rate(i) <= 1e-10 * scale(i) + kAbsTol) act.push_back(i);
  if (act.empty()) return std::nullopt;
  const Eigen::Index na = static_cast<Eigen::Index>(act.size()), N = v.size();
  MatrixXd Bt(N, na);  // L^{-1} E_A'
  // c_A = e_A∘(E_A v) split as ebar E_A v + c'_A with ebar the mean
  // restitution on A: the ebar part is a multiple of the projection of v
  // (exact for equal restitution), only c' needs the solve with R below.
  double ebar = 0.0;
  for (const Eigen::Index i : act) ebar += e_target(i);
  ebar /= static_cast<double>(act.size());
  VectorXd cA(na);  // c'_A
  for (Eigen::Index j = 0; j < na; ++j) {
    Bt.col(j) = s.EJ.row(act[j]).transpose();
    cA(j) = (e_target(act[j]) - ebar) * s.a(act[j]);
  }
  s.L.triangularView<Eigen::Lower>().solveInPlace(Bt);
  // y = L' v+, y0 = L' v: minimise |y - y0| subject to B_A y = -c_A =
  // -ebar B_A y0 - c'_A. With B_A' P = Q R (rank r: dependent rows of E_A are
  // dropped, their rates follow from the kept ones), y = y0 + Q_r t,
  // t = -((1 + ebar) Q_r' y0 + R_11^{-T} c'_P): the projection of y0 needs
  // no solve with R. Impulse: R_11 mu = t on the kept rows.
  Eigen::ColPivHouseholderQR<MatrixXd> qr(Bt);
  qr.setThreshold(64 * std::numeric_limits<double>::epsilon());
  const Eigen::Index r = qr.rank();
  if (r == 0) return std::nullopt;
  const auto& perm = qr.colsPermutation().indices();
  const VectorXd y0 = s.L.transpose() * v;
  VectorXd cP(r);
  for (Eigen::Index j = 0; j < r; ++j) cP(j) = cA(perm(j));
  const auto R11 = qr.matrixR().topLeftCorner(r, r).triangularView<Eigen::Upper>();
  // Q applied as its Householder reflectors (O(N r)), never formed.
  const VectorXd Qty0 = (qr.householderQ().transpose() * y0).head(r);
  const VectorXd t = -((1.0 + ebar) * Qty0 + R11.transpose().solve(cP));
  VectorXd Qt = VectorXd::Zero(N);
  Qt.head(r) = t;
  Qt = qr.householderQ() * Qt;
  const VectorXd mu = R11.solve(t);
  Refined out;
  out.v_after = s.L.transpose().triangularView<Eigen::Upper>().solve(y0 + Qt);
  // Where the LCP's velocity is the refined one to rounding, keep the LCP's
  // result: its impulse is the better one when W is well conditioned.
  const double vscale = v.cwiseAbs().maxCoeff() + out.v_after.cwiseAbs().maxCoeff();
  if ((v_lcp - out.v_after).cwiseAbs().maxCoeff() <= kRelTol * vscale + kAbsTol)
    return std::nullopt;
  out.impulse_J = VectorXd::Zero(nj);
  for (Eigen::Index j = 0; j < r; ++j) out.impulse_J(act[perm(j)]) = mu(j);
  // Impulses within rounding of zero are zero (the mode is the support).
  const double lambda_scale =
      std::max(out.impulse_J.cwiseAbs().maxCoeff(), z.cwiseAbs().maxCoeff());
  // Not mech::zero_tolerance (mech/tolerances.hpp): relative to the largest impulse, no floor.
  for (Eigen::Index i = 0; i < nj; ++i)
    if (std::abs(out.impulse_J(i)) <= kRelTol * lambda_scale) out.impulse_J(i) = 0.0;
  // Still a solution? Impulse >= 0 and every closed rate >= 0, to the
  // tolerances of finish.
  if (out.impulse_J.minCoeff() < -1e-9 * lambda_scale) return std::nullopt;
  const VectorXd rate_new = s.EJ * out.v_after + c;
  for (Eigen::Index i = 0; i < nj; ++i)
    if (rate_new(i) < -mech::zero_tolerance(scale(i))) return std::nullopt;
  return out;
}

void finish(const ImpactInput& in, const Setup& s, const VectorXd& impulse_J,
            const VectorXd& v_after, double mode_threshold, ImpactResult& out) {
  const mech::MechanicalModel& m = *in.model;
  out.v_after = v_after;
  out.impulse = VectorXd::Zero(s.k);
  out.mode.clear();
  const double lambda_scale = impulse_J.size() ? impulse_J.cwiseAbs().maxCoeff() : 0.0;
  bool admissible = true;
  for (size_t i = 0; i < in.closed.size(); ++i) {
    out.impulse(in.closed[i]) = impulse_J(i);
    if (impulse_J(i) > mode_threshold) out.mode.push_back(in.closed[i]);
    // Not mech::zero_tolerance (mech/tolerances.hpp): relative to the largest impulse, no floor.
    if (impulse_J(i) < -1e-9 * lambda_scale) admissible = false;
  }
  out.energy_after = mech::kinetic_energy(m, v_after);
  const VectorXd rates = s.EJ * v_after;
  const VectorXd scale = s.EJ.cwiseAbs() * (in.v.cwiseAbs() + v_after.cwiseAbs());
  out.worst_rate = std::min(0.0, rates.size() ? rates.minCoeff() : 0.0);
  for (Eigen::Index i = 0; i < rates.size(); ++i)
    if (rates(i) < -mech::zero_tolerance(scale(i))) admissible = false;
  out.admissible = admissible;
}

std::optional<VectorXd> solve_impact_lcp(const MatrixXd& W, const VectorXd& q,
                                         const lcp::Solver& solver, ImpactResult& out) {
  // Solved scaled to a unit diagonal and |q|_inf = 1 (lcp::solve_scaled).
  // The LCP solvers accept a residual of 1e-12 (1 + |q|_inf), an absolute
  // test; masses over four decades give W entries from 1e-4 to 1e4, where
  // the rounding of the unscaled problem alone exceeds that.
  // The given solver, then Lemke (dependent constraints make W singular, PSD
  // but not P; Lemke still solves it since q is in the range of W, Lemma
  // 4.6.1), then projected Gauss–Seidel (converges on PSD W).
  // Two passes: the solvers' own acceptance (1e-12 (1 + |q|) on the scaled
  // problem), then 1e-10: singular W (dependent rows) costs the pivoting
  // solvers a few digits, and 1e-10 relative is still far below any physical
  // meaning of a rate.
  lcp::Options opt;
  lcp::Result res;
  std::string tried;
  for (const double tol : {1e-12, 1e-10}) {
    opt.tolerance = tol;
    int attempts = 0;
    res = lcp::solve_scaled(solver, W, q, opt, &attempts, &tried);
    out.lcp_solves += attempts;
    if (res.ok()) break;
  }
  out.lcp_status = res.status;
  if (!res.ok()) {
    out.message = "impact LCP failed (" + tried +
                  "): " + std::string(lcp::to_string(res.status, "solved")) +
                  (res.message.empty() ? "" : " (" + res.message + ")");
    return std::nullopt;
  }
  return res.z;
}

}  // namespace detail

ImpactResult moreau_newton(const ImpactInput& in, const lcp::Solver& solver) {
  ImpactResult out;
  const auto s = detail::prepare(in, out);
  if (!s) return out;
  // (3.69)-(3.70): E_J v+ = E_J v + E_J M^{-1} E_J' lambda, 0 <= E_J v+ ⟂ lambda >= 0.
  const auto z = detail::solve_impact_lcp(s->W, s->a, solver, out);
  if (!z) return out;
  // Newton restitution on the inelastic impulse (§8.2.2). The mode is the
  // support of the inelastic impulse: pivoting solvers give exact zeros.
  // v+ = w + M^{-1} E_J' (e∘z) with w the inelastic velocity, refined on E
  // (detail::refine_on_active_set) where that still solves the LCP.
  VectorXd zi = *z, w = in.v + s->MinvEt * zi;
  if (const auto ref = detail::refine_on_active_set(*s, in.v, VectorXd::Zero(zi.size()), zi)) {
    zi = ref->impulse_J;
    w = ref->v_after;
  }
  // M^{-1} E_J' (e∘z) = ebar (w - v) + M^{-1} E_J' ((e - ebar)∘z), ebar the
  // mean restitution on the support: exact in w when the restitution is equal.
  // The support counts impulses that change some rate by more than rounding
  // (kRelTol of the largest approach rate, through the diagonal of W): a
  // solver may leave a degenerate contact (rate 0, impulse 0) basic at 1e-17.
  double tiny = 0.0;
  for (Eigen::Index i = 0; i < zi.size(); ++i)
    if (s->W(i, i) > 0.0) tiny = std::max(tiny, std::abs(s->a(i)) / s->W(i, i));
  tiny *= kRelTol;
  double ebar = 0.0;
  int support = 0;
  for (Eigen::Index i = 0; i < zi.size(); ++i)
    if (zi(i) > tiny) ebar += s->e_J(i), ++support;
  if (support > 0) ebar /= support;
  const VectorXd de = (s->e_J.array() - ebar).matrix().cwiseProduct(zi);
  detail::finish(in, *s, zi + s->e_J.cwiseProduct(zi), w + ebar * (w - in.v) + s->MinvEt * de, tiny,
                 out);
  out.status = Status::kOk;
  return out;
}

namespace {

using RuleFn = ImpactResult (*)(const ImpactInput&, const lcp::Solver&);

struct Rule {
  const char* name;
  RuleFn fn;
  bool friction = false;  // handles mechanical.friction
};

// "newton" is §8.2.2 with the given restitution; "inelastic" the same
// formula with e = 0 whatever the restitution (Moreau's inelastic rule,
// (3.69)-(3.70)). "moreau" is an alias of "newton" (its old name).
// On a model with friction the three LCP laws are the one friction LCP
// (moreau_friction: Newton's restitution inside it); the others refuse
// friction (detail::prepare).
ImpactResult lcp_law(const ImpactInput& in, const lcp::Solver& solver, RuleFn frictionless) {
  if (in.model != nullptr && in.model->has_friction()) return moreau_friction(in, solver);
  return frictionless(in, solver);
}

ImpactResult inelastic(const ImpactInput& in, const lcp::Solver& solver) {
  if (in.model == nullptr) return moreau_newton(in, solver);  // its message
  ImpactInput e0 = in;
  e0.restitution = VectorXd::Zero(in.model->num_constraints());
  return lcp_law(e0, solver, &moreau_newton);
}

constexpr const char* kMoreauAliasNote =
    "'moreau' is an alias of 'newton': Newton's restitution per contact on Moreau's "
    "inelastic impulse, with the model's restitution (inelastic only where it is 0); the law "
    "'inelastic' applies e = 0 whatever the restitution";

const Rule kRules[] = {
    {"newton",
     +[](const ImpactInput& in, const lcp::Solver& s) { return lcp_law(in, s, &moreau_newton); },
     true},
    {"inelastic", &inelastic, true},
    {"moreau-restitution",
     +[](const ImpactInput& in, const lcp::Solver& s) {
       return lcp_law(in, s, &moreau_restitution);
     },
     true},
    {"sequential", +[](const ImpactInput& in, const lcp::Solver&) { return sequential(in); }},
    {"flip", +[](const ImpactInput& in, const lcp::Solver&) { return flip_rule(in); }},
};

class NamedLaw : public ImpactLaw {
 public:
  explicit NamedLaw(const Rule& r) : rule_(r) {}
  std::string name() const override { return rule_.name; }
  bool handles_friction() const override { return rule_.friction; }
  ImpactResult apply(const ImpactInput& in, const lcp::Solver& solver) const override {
    ImpactResult r = rule_.fn(in, solver);
    if (!r.ok() && in.model != nullptr && in.model->has_friction() &&
        r.message.rfind("this impact law", 0) == 0)
      r.message = "impact law '" + std::string(rule_.name) + "'" + r.message.substr(15);
    return r;
  }

 private:
  Rule rule_;
};

}  // namespace

Registry<ImpactLaw>& laws() {
  return Registry<ImpactLaw>::instance("impact law", [](Registry<ImpactLaw>& reg) {
    for (const Rule& rule : kRules)
      reg.add(rule.name, [rule] { return std::make_unique<NamedLaw>(rule); });
    reg.add_alias("moreau", "newton", kMoreauAliasNote);
  });
}

std::vector<std::string> impact_law_names() { return laws().names(); }

std::unique_ptr<ImpactLaw> make_impact_law(std::string_view name) {
  return laws().make_or_throw(
      name, name == "moreau-qp" ? "moreau-qp is in the component lcsim::ipopt; link it" : "");
}

}  // namespace lcsim::impact
