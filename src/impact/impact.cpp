// Impact rules: shared set-up, Moreau's LCP with Newton restitution
// ("moreau", "newton") and the registry of rules by name.
#include "impact/impact.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "impact/detail.hpp"

namespace lcsim::impact {

namespace detail {

std::optional<Setup> prepare(const ImpactInput& in, ImpactResult& out) {
  out = ImpactResult{};
  if (in.model == nullptr) {
    out.message = "impact input has no model";
    return std::nullopt;
  }
  const mech::MechanicalModel& m = *in.model;
  const int N = m.dofs(), k = m.num_constraints();
  if (in.v.size() != N) {
    out.message = "pre-impact velocity has " + std::to_string(in.v.size()) +
                  " entries, the model has " + std::to_string(N) + " coordinates";
    return std::nullopt;
  }
  for (size_t i = 0; i < in.closed.size(); ++i) {
    if (in.closed[i] < 0 || in.closed[i] >= k || (i > 0 && in.closed[i] <= in.closed[i - 1])) {
      out.message = "closed set must be sorted distinct indices in [0, " + std::to_string(k) + ")";
      return std::nullopt;
    }
  }
  Setup s;
  s.k = k;
  if (in.restitution.size() == k)
    s.e = in.restitution;
  else if (in.restitution.size() == 0 && m.restitution.size() == k)
    s.e = m.restitution;
  else if (in.restitution.size() == 0)
    s.e = VectorXd::Zero(k);
  else {
    out.message = "restitution has " + std::to_string(in.restitution.size()) +
                  " entries, the model has " + std::to_string(k) + " constraints";
    return std::nullopt;
  }
  out.v_after = in.v;
  out.impulse = VectorXd::Zero(k);
  out.energy_before = mech::kinetic_energy(m, in.v);
  out.energy_after = out.energy_before;
  if (in.closed.empty()) {
    out.ok = true;
    return std::nullopt;
  }
  const int nj = static_cast<int>(in.closed.size());
  s.EJ.resize(nj, N);
  s.e_J.resize(nj);
  for (int i = 0; i < nj; ++i) {
    s.EJ.row(i) = m.E.row(in.closed[i]);
    s.e_J(i) = s.e(in.closed[i]);
  }
  const Eigen::LLT<MatrixXd> llt(m.M);
  s.MinvEt = llt.solve(s.EJ.transpose());
  s.W = s.EJ * s.MinvEt;
  s.a = s.EJ * in.v;
  return s;
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
    if (impulse_J(i) < -1e-9 * lambda_scale) admissible = false;
  }
  out.energy_after = mech::kinetic_energy(m, v_after);
  const VectorXd rates = s.EJ * v_after;
  const VectorXd scale = s.EJ.cwiseAbs() * (in.v.cwiseAbs() + v_after.cwiseAbs());
  out.worst_rate = std::min(0.0, rates.size() ? rates.minCoeff() : 0.0);
  for (Eigen::Index i = 0; i < rates.size(); ++i)
    if (rates(i) < -(1e-9 * scale(i) + kAbsTol)) admissible = false;
  out.admissible = admissible;
}

std::optional<VectorXd> solve_impact_lcp(const MatrixXd& W, const VectorXd& q,
                                         const lcp::Solver& solver, ImpactResult& out) {
  // Scale to a unit diagonal and |q|_inf = 1: z = s D z~ with D = diag(W)^{-1/2}.
  // The LCP solvers accept a residual of 1e-12 (1 + |q|_inf), an absolute
  // test; masses over four decades give W entries from 1e-4 to 1e4, where
  // the rounding of the unscaled problem alone exceeds that.
  const Eigen::Index n = q.size();
  VectorXd d(n);
  for (Eigen::Index i = 0; i < n; ++i) d(i) = W(i, i) > 0.0 ? 1.0 / std::sqrt(W(i, i)) : 1.0;
  const VectorXd qd = d.cwiseProduct(q);
  const double s = qd.cwiseAbs().maxCoeff() > 0.0 ? qd.cwiseAbs().maxCoeff() : 1.0;
  const MatrixXd Ws = d.asDiagonal() * W * d.asDiagonal();
  const VectorXd qs = qd / s;
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
    res = lcp::solve_with_fallbacks(solver, Ws, qs, opt, &attempts, &tried);
    out.lcp_solves += attempts;
    if (res.ok()) break;
  }
  out.lcp_status = res.status;
  if (!res.ok()) {
    out.message = "impact LCP failed (" + tried + "): " + std::string(lcp::to_string(res.status)) +
                  (res.message.empty() ? "" : " (" + res.message + ")");
    return std::nullopt;
  }
  return VectorXd(s * d.cwiseProduct(res.z));
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
  const VectorXd scaled = z->cwiseProduct((1.0 + s->e_J.array()).matrix());
  detail::finish(in, *s, scaled, in.v + s->MinvEt * scaled, 0.0, out);
  out.ok = true;
  return out;
}

namespace {

using RuleFn = ImpactResult (*)(const ImpactInput&, const lcp::Solver&);

struct Rule {
  const char* name;
  RuleFn fn;
};

// "moreau" and "newton" are one formula (§8.2.2 with the given restitution;
// e = 0 is Moreau's inelastic rule): two names, one implementation.
const Rule kRules[] = {
    {"moreau", &moreau_newton},
    {"moreau-qp", +[](const ImpactInput& in, const lcp::Solver&) { return moreau_qp(in); }},
    {"newton", &moreau_newton},
    {"moreau-restitution", &moreau_restitution},
    {"sequential", +[](const ImpactInput& in, const lcp::Solver&) { return sequential(in); }},
    {"flip", +[](const ImpactInput& in, const lcp::Solver&) { return flip_rule(in); }},
};

class NamedLaw : public ImpactLaw {
 public:
  explicit NamedLaw(const Rule& r) : rule_(r) {}
  std::string name() const override { return rule_.name; }
  ImpactResult apply(const ImpactInput& in, const lcp::Solver& solver) const override {
    return rule_.fn(in, solver);
  }

 private:
  Rule rule_;
};

}  // namespace

std::vector<std::string> impact_law_names() {
  std::vector<std::string> names;
  for (const Rule& r : kRules) names.emplace_back(r.name);
  return names;
}

std::unique_ptr<ImpactLaw> make_impact_law(std::string_view name) {
  for (const Rule& r : kRules)
    if (name == r.name) return std::make_unique<NamedLaw>(r);
  std::ostringstream msg;
  msg << "unknown impact rule '" << name << "' (known:";
  for (const auto& n : impact_law_names()) msg << " " << n;
  msg << ")";
  throw std::invalid_argument(msg.str());
}

}  // namespace lcsim::impact
