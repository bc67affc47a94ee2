// Divergence (issue 24, item 1): a run whose numbers have left the model's
// scales is never "completed". Every method's states pass through one
// DivergenceGuard (sim.hpp): the time-stepping loops (moreau_jean.cpp,
// euler.cpp) and Bullet's recorder check every step, and Integrator::run
// checks what any method reports at its end (the exact method included).
//
// The scales, from the model and the start only (never from the run):
// - energy scale E_s = T0 + |V0| + E_f + E_b: the start's kinetic and
//   potential energy, the kinetic energy the constant forces f give the free
//   coordinates over the horizon T (sum_j (f_j T)^2 / (2 M_jj)), and what a
//   moving belt can feed in (sum_c 1/2 M_max w_c^2 + mu_c |w_c| F T, F = |f|_1
//   + |K q0|_1 bounding the normal force). Without input (a belt) the model's
//   total energy never rises: dampers and inelastic impacts dissipate, springs
//   and f are in the potential; so E - E0 > kAmplitude^2 E_s is growth "by
//   orders of magnitude without input": six in energy, three in amplitude.
//   A correct run's E - E0 is rounding and truncation of the size of its
//   terms, far below that (even an unstable linearisation that falls
//   exponentially keeps E constant); Bullet's nonlinear multibody, measured
//   with lcsim's linear energy, differs by O(1) of E_s for swings, by
//   (q / q0)^2 for a joint that spins — a thousand times its start before this
//   fires.
// - length scale L = max_i |g_i| + |E_i|_1 R, R = |q0|_inf + T sqrt(2 E_s /
//   m_min): the largest gap any constraint can show if every coordinate moved
//   at the speed the energy scale allows for the whole horizon. A violation
//   beyond kAmplitude L is far past any stop: a time-stepping penetration is
//   O(h |v|) <= L.
// - every number finite.
#include <algorithm>
#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <string>

namespace lcsim::sim {

namespace {

std::string coordinate_name(const mech::Model& model, Eigen::Index i) {
  if (!model.is_mechanical()) return "x" + std::to_string(i + 1);
  const auto& c = model.mechanical->coordinates;
  const auto N = static_cast<Eigen::Index>(c.size());
  if (i < N) return "q '" + c[static_cast<std::size_t>(i)] + "'";
  if (i < 2 * N) return "v '" + c[static_cast<std::size_t>(i - N)] + "'";
  return "x" + std::to_string(i + 1);
}

}  // namespace

DivergenceGuard::DivergenceGuard(const mech::Model& model, const VectorXd& x0, double t_end)
    : model_(&model) {
  if (!model.is_mechanical()) return;
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs();
  if (x0.size() < 2 * N) return;
  const VectorXd q0 = x0.head(N), v0 = x0.segment(N, N);
  const double T = t_end;
  double m_min = std::numeric_limits<double>::infinity(), m_max = 0.0, e_f = 0.0;
  // With force inputs (docs/inputs.md) the largest force per coordinate on
  // 257 times over [0, T] (a scale for the guard's 1e6 margin, not a bound).
  VectorXd f_size = m.f.cwiseAbs();
  if (m.has_inputs())
    for (int s = 0; s <= 256; ++s)
      f_size = f_size.cwiseMax(mech::force_at(m, T * s / 256.0).cwiseAbs());
  for (int j = 0; j < N; ++j) {
    const double mj = m.M.coeff(j, j);
    m_min = std::min(m_min, mj);
    m_max = std::max(m_max, mj);
    if (mj > 0.0) e_f += 0.5 * (f_size(j) * T) * (f_size(j) * T) / mj;
  }
  const double F = m.f.lpNorm<1>() + (m.K * q0).lpNorm<1>();
  double e_b = 0.0;
  for (const auto& fc : m.friction)
    e_b += 0.5 * m_max * fc.velocity * fc.velocity + fc.mu * std::abs(fc.velocity) * F * T;
  e0_ = mech::total_energy(m, q0, v0);
  energy_scale_ = mech::kinetic_energy(m, v0) + std::abs(mech::potential_energy(m, q0)) + e_f + e_b;
  const double reach =
      q0.cwiseAbs().maxCoeff() + (m_min > 0.0 ? T * std::sqrt(2.0 * energy_scale_ / m_min) : 0.0);
  // Each row's sum of |E_ij| from its stored entries, in the order of j as
  // the sum over every column was (the zeros it skips add nothing to a sum
  // of non-negative terms, so the figure is the same to the bit): one pass
  // over E's columns, O(nnz) where E.coeff(i, j) for every (i, j) cost
  // O(k N) (3 s at N = 10^4).
  VectorXd row = VectorXd::Zero(m.num_constraints());
  for (int j = 0; j < m.E.outerSize(); ++j)
    for (mech::SparseMatrix::InnerIterator it(m.E, j); it; ++it)
      row(it.row()) += std::abs(it.value());
  for (int i = 0; i < m.num_constraints(); ++i)
    length_scale_ = std::max(length_scale_, std::abs(m.g(i)) + row(i) * reach);
  mechanical_ = true;
}

std::string DivergenceGuard::check(double t, const VectorXd& x, bool full) {
  if (!mechanical_) return non_finite(t, x, 0);
  const int N = model_->mechanical->dofs();
  if (std::string why = non_finite(t, x.tail(x.size() - 2 * N), 2 * N); !why.empty()) return why;
  return check(t, x.head(N), x.segment(N, N), full);
}

std::string DivergenceGuard::check(double t, Eigen::Ref<const VectorXd> q,
                                   Eigen::Ref<const VectorXd> v, bool full) {
  if (std::string why = non_finite(t, q, 0); !why.empty()) return why;
  if (std::string why = non_finite(t, v, q.size()); !why.empty()) return why;
  if (!mechanical_ || (++calls_ % kStride != 0 && !full)) return "";
  const mech::MechanicalModel& m = *model_->mechanical;
  const double e = mech::total_energy(m, q, v);
  if (!std::isfinite(e) || e - e0_ > kAmplitude * kAmplitude * energy_scale_) {
    Eigen::Index i = 0, j = 0;
    q.cwiseAbs().maxCoeff(&i);
    v.cwiseAbs().maxCoeff(&j);
    return "diverged at t = " + short_number(t) + ": energy " + short_number(e) + " J from " +
           short_number(e0_) + " J at the start, a rise of more than " +
           short_number(kAmplitude * kAmplitude) + " times the model's energy scale " +
           short_number(energy_scale_) +
           " J without input (largest: " + coordinate_name(*model_, i) + " = " +
           short_number(q(i)) + ", " + coordinate_name(*model_, q.size() + j) + " = " +
           short_number(v(j)) + ")";
  }
  if (m.num_constraints() == 0) return "";
  Eigen::Index i = 0;
  const double gap = mech::gaps(m, q).minCoeff(&i);
  return violation_message("at t = " + short_number(t) + ": constraint '" +
                               m.constraints[static_cast<std::size_t>(i)] + "'",
                           gap);
}

std::string DivergenceGuard::non_finite(double t, Eigen::Ref<const VectorXd> x,
                                        Eigen::Index offset) const {
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!std::isfinite(x(i)))
      return "diverged at t = " + short_number(t) + ": " + coordinate_name(*model_, offset + i) +
             " = " + short_number(x(i)) + " (not finite)";
  return "";
}

std::string DivergenceGuard::check_worst_gap(double worst_gap) const {
  if (!mechanical_) return "";
  return violation_message("over the run: some constraint", worst_gap);
}

std::string DivergenceGuard::violation_message(const std::string& where, double gap) const {
  if (!(gap < -kAmplitude * length_scale_)) return "";
  return "diverged " + where + " violated by " + short_number(-gap) + ", more than " +
         short_number(kAmplitude) + " times the model's length scale " +
         short_number(length_scale_) + " (far past any stop)";
}

}  // namespace lcsim::sim
