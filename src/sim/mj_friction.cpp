// Moreau–Jean's step with friction (see mj_friction.hpp).
#include "sim/mj_friction.hpp"

namespace lcsim::sim::detail {

MjFriction::MjFriction(const mech::MechanicalModel& m)
    : m_(m), of_contact_(static_cast<size_t>(m.num_constraints()), -1), Er_(m.E) {
  for (size_t f = 0; f < m.friction.size(); ++f)
    of_contact_[static_cast<size_t>(m.friction[f].contact)] = static_cast<int>(f);
  Er_.makeCompressed();
}

bool MjFriction::any_in(const IndexSet& A) const {
  if (m_.friction.empty()) return false;
  for (int i : A)
    if (of_contact_[static_cast<size_t>(i)] >= 0) return true;
  return false;
}

const std::vector<VectorXd>& MjFriction::tangent_columns(const MjIteration& f) {
  for (const auto& [it, cols] : tcols_)
    if (it == &f) return cols;
  std::vector<VectorXd> cols;
  for (const mech::FrictionalContact& c : m_.friction) cols.push_back(f.solve(c.tangent));
  tcols_.emplace_back(&f, std::move(cols));
  return tcols_.back().second;
}

bool MjFriction::step(MjIteration& f, const IndexSet& A, const std::vector<const SparseCol*>& cols,
                      const VectorXd& Ev, const VectorXd& e, const lcp::Solver& solver,
                      VectorXd& v_next, VectorXd& lambda_N, VectorXd& lambda_T, long& solves,
                      lcp::Result& failed) {
  const std::vector<VectorXd>& tc = tangent_columns(f);
  const Eigen::Index na = static_cast<Eigen::Index>(A.size()), N = v_next.size();
  std::vector<int> normal_of, fric;  // position in A, index into m.friction
  for (Eigen::Index a = 0; a < na; ++a)
    if (const int fi = of_contact_[static_cast<size_t>(A[a])]; fi >= 0) {
      normal_of.push_back(static_cast<int>(a));
      fric.push_back(fi);
    }
  const Eigen::Index nf = static_cast<Eigen::Index>(fric.size()), ng = na + nf;
  // G = [E_A; T_F] and W^{-1} G' dense (N x ng).
  MatrixXd G(ng, N), WGt(N, ng);
  VectorXd mu(nf), belt(nf);
  for (Eigen::Index a = 0; a < na; ++a) {
    G.row(a) = Er_.row(A[a]);
    WGt.col(a) = *cols[a];
  }
  for (Eigen::Index j = 0; j < nf; ++j) {
    const mech::FrictionalContact& c = m_.friction[static_cast<size_t>(fric[j])];
    G.row(na + j) = c.tangent.transpose();
    WGt.col(na + j) = tc[static_cast<size_t>(fric[j])];
    mu(j) = c.mu;
    belt(j) = c.velocity;
  }
  const MatrixXd Wg = G * WGt;
  const VectorXd rates = G * v_next;  // v_next = v_free here
  VectorXd rate_N = rates.head(na);
  for (Eigen::Index a = 0; a < na; ++a) rate_N(a) += e(A[a]) * Ev(A[a]);
  const impact::FrictionLcp p =
      impact::friction_lcp(Wg, rate_N, rates.tail(nf) - belt, normal_of, mu);
  int attempts = 0;
  lcp::Result r = impact::solve_friction_lcp(p, solver, &attempts, nullptr);
  solves += attempts;
  if (!r.ok()) {
    failed = std::move(r);
    return false;
  }
  VectorXd lT;
  impact::friction_impulses(r.z, static_cast<int>(na), normal_of, mu, lambda_N, lT);
  v_next += WGt.leftCols(na) * lambda_N + WGt.rightCols(nf) * lT;
  for (Eigen::Index j = 0; j < nf; ++j)
    lambda_T(m_.friction[static_cast<size_t>(fric[j])].contact) = lT(j);
  return true;
}

}  // namespace lcsim::sim::detail
