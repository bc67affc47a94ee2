// The derivative of the time-stepping schemes' discrete map
// (step_sensitivity.hpp, docs/sensitivities.md "The time-stepping
// derivative"). Dense linear algebra: the schemes' models here are the small
// ones (backward Euler is dense already; a Moreau–Jean run asking for it pays
// one dense factorisation of W per step length and O(N^2 (N + columns)) per
// step).
#include "sim/stepping/step_sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <lcsim/impact/impact.hpp>
#include <limits>
#include <string>

#include "sim/stepping/friction_labels.hpp"

namespace lcsim::sim::detail {

namespace {

MatrixXd dense(const Eigen::SparseMatrix<double>& A) { return MatrixXd(A); }

// A row within this fraction of the step's scale in both its multiplier (as
// a residual: z_a times the Delassus diagonal) and its residual is
// degenerate: as the exact method's sqrt(eps) test of a degenerate impact.
const double kDegenerate = std::sqrt(std::numeric_limits<double>::epsilon());

// dM of M[i][j]: the entries (i, j) and (j, i) together (M stays symmetric).
MatrixXd unit_mass(int N, int i, int j) {
  MatrixXd dM = MatrixXd::Zero(N, N);
  dM(i, j) = 1.0;
  dM(j, i) = 1.0;
  return dM;
}

}  // namespace

StepSensitivity::StepSensitivity(const mech::Model& model, const SensColumns& cols)
    : model_(model), cols_(cols) {
  nx0_ = cols.x0 ? static_cast<int>(model.state_size()) : 0;
  m_ = nx0_ + static_cast<int>(cols.params.size());
  exists_.assign(static_cast<size_t>(m_), 1);
}

std::vector<std::string> StepSensitivity::column_names() const {
  std::vector<std::string> out;
  for (int i = 0; i < nx0_; ++i) out.push_back("x0[" + std::to_string(i) + "]");
  for (const SensParam& p : cols_.params) out.push_back(p.name);
  return out;
}

void StepSensitivity::fill(MatrixXd& dx, std::vector<char>& exists) const {
  dx = S_.topRows(model_.state_size());
  for (int c = 0; c < m_; ++c)
    if (!exists_[static_cast<size_t>(c)]) dx.col(c).setZero();
  exists = exists_;
}

void StepSensitivity::finish(Trajectory& tr) const {
  tr.sensitivity_columns = column_names();
  fill(tr.dx_final, tr.dx_final_exists);
  tr.sensitivity_losses = losses_;
}

bool StepSensitivity::any_exists() const {
  for (char e : exists_)
    if (e) return true;
  return false;
}

VectorXd StepSensitivity::amplitude_force(int input, double t) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  mech::Input unit = m.inputs[static_cast<size_t>(input)];
  unit.offset = 0.0;
  unit.amplitude = 1.0;
  VectorXd out = VectorXd::Zero(m.dofs());
  for (const mech::InputUse& use : m.force_inputs)
    if (use.input == input) out += use.gain * unit.value(t);
  return out;
}

void StepSensitivity::lose_column(double t, int row, const std::string& reason, int column) {
  lose_columns(t, row, reason, [column](int c) { return c == column; });
}

void StepSensitivity::lose_all(double t, int row, const std::string& reason) {
  lose_columns(t, row, reason, [](int) { return true; });
}

void StepSensitivity::lose_columns(double t, int row, const std::string& reason,
                                   const std::function<bool(int)>& which) {
  SensitivityLoss l;
  for (int c = 0; c < m_; ++c)
    if (exists_[static_cast<size_t>(c)] && which(c)) {
      exists_[static_cast<size_t>(c)] = 0;
      l.columns.push_back(c);
    }
  if (l.columns.empty()) return;
  l.t = t;
  l.contact = model_.is_mechanical() ? model_.mechanical->constraints[static_cast<size_t>(row)]
                                     : "y" + std::to_string(row);
  l.reason = reason;
  losses_.push_back(std::move(l));
}

int StepSensitivity::classify(const VectorXd& z, const VectorXd& w, const VectorXd& diag,
                              double scale, std::vector<int>& active) {
  active.clear();
  const double tol = kDegenerate * scale + std::numeric_limits<double>::min();
  for (int a = 0; a < z.size(); ++a) {
    if (z(a) * diag(a) > tol)
      active.push_back(a);
    else if (w(a) <= tol)
      return a;
  }
  return -1;
}

// ---- Moreau–Jean ----

MjStepSensitivity::MjStepSensitivity(const mech::Model& model, const SensColumns& cols,
                                     double theta, bool euler_gap)
    : StepSensitivity(model, cols), theta_(theta), euler_gap_(euler_gap) {
  const mech::MechanicalModel& m = *model.mechanical;
  N_ = m.dofs();
  M_ = dense(m.M);
  D_ = dense(m.D);
  K_ = dense(m.K);
  E_ = dense(m.E);
  e_ = m.restitution.size() == m.num_constraints() ? m.restitution
                                                   : VectorXd::Zero(m.num_constraints());
  S_ = MatrixXd::Zero(2 * N_, m_);
  S_.topLeftCorner(nx0_, nx0_).setIdentity();
}

const Eigen::LLT<MatrixXd>& MjStepSensitivity::factor(double h) {
  for (int s = 0; s < 2; ++s)
    if (h_[s] == h) return llt_[s];
  const int s = h_[0] < 0.0 ? 0 : 1;  // the grid's step, then its last one
  h_[s] = h;
  llt_[s].compute(M_ + h * theta_ * D_ + h * h * theta_ * theta_ * K_);
  return llt_[s];
}

void MjStepSensitivity::parameter_terms(double t0, double h, const VectorXd& q, const VectorXd& v,
                                        const VectorXd& v_next, MatrixXd& R) const {
  const VectorXd qt = q + h * theta_ * v, dv = v_next - v;
  const double ht = h * theta_;
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    auto col = R.col(nx0_ + static_cast<int>(p));
    switch (sp.kind) {
      case 'f':
        col(sp.i) += h;
        break;
      case 'K':
        col(sp.i) -= h * qt(sp.j) + ht * ht * dv(sp.j);
        break;
      case 'D':
        col(sp.i) -= h * v(sp.j) + ht * dv(sp.j);
        break;
      case 'M':
        col -= unit_mass(N_, sp.i, sp.j) * dv;
        break;
      case 'a':  // ops_.set_step's force, theta f(t0 + h) + (1 - theta) f(t0)
        col += h * (theta_ * amplitude_force(sp.i, t0 + h) +
                    (1.0 - theta_) * amplitude_force(sp.i, t0));
        break;
      default:
        break;  // 'e' enters the active rows' equation
    }
  }
}

void MjStepSensitivity::step(double t0, double h, const VectorXd& q, const VectorXd& v,
                             const VectorXd& v_next, const IndexSet& A, const VectorXd& z,
                             const Friction* friction) {
  if (!any_exists()) return;
  const Eigen::LLT<MatrixXd>& W = factor(h);
  const auto dQ = S_.topRows(N_);
  const auto dV = S_.bottomRows(N_);
  // W dv+ = W dv + h drhs - dW (v+ - v) + B dlambda.
  MatrixXd R = M_ * dV - h * (D_ * dV + K_ * (dQ + h * theta_ * dV)) + h * theta_ * D_ * dV +
               h * h * theta_ * theta_ * K_ * dV;
  parameter_terms(t0, h, q, v, v_next, R);
  MatrixXd dVn = W.solve(R);
  if (!A.empty() && !impulse_terms(t0, h, W, q, v, v_next, A, z, friction, dVn)) return;
  const MatrixXd dQn = dQ + h * ((1.0 - theta_) * dV + theta_ * dVn);
  S_.topRows(N_) = dQn;
  S_.bottomRows(N_) = dVn;
}

Eigen::RowVectorXd MjStepSensitivity::normal_rhs(int r, double h, double rate,
                                                 const MatrixXd& dVn) const {
  Eigen::RowVectorXd out;
  if (euler_gap_) {  // E_r dv+ = -(E_r dq + dg_r) / h
    out = -(E_.row(r) * S_.topRows(N_)) / h - E_.row(r) * dVn;
    for (size_t p = 0; p < cols_.params.size(); ++p)
      if (cols_.params[p].kind == 'g' && cols_.params[p].i == r)
        out(nx0_ + static_cast<int>(p)) -= 1.0 / h;
    return out;
  }
  // E_S dv+ = -e_S (E_S dv) - de_S (E_S v)
  out = -e_(r) * (E_.row(r) * S_.bottomRows(N_)) - E_.row(r) * dVn;
  for (size_t p = 0; p < cols_.params.size(); ++p)
    if (cols_.params[p].kind == 'e' && cols_.params[p].i == r)
      out(nx0_ + static_cast<int>(p)) -= rate;
  return out;
}

bool MjStepSensitivity::impulse_terms(double t0, double h, const Eigen::LLT<MatrixXd>& W,
                                      const VectorXd& q, const VectorXd& v, const VectorXd& v_next,
                                      const IndexSet& A, const VectorXd& z,
                                      const Friction* friction, MatrixXd& dVn) {
  const int na = static_cast<int>(A.size());
  MatrixXd EA(na, N_);
  for (int a = 0; a < na; ++a) EA.row(a) = E_.row(A[static_cast<size_t>(a)]);
  const VectorXd Gd = (EA * W.solve(EA.transpose())).diagonal();
  // The rows' rates: E v (Moreau–Jean's, times e) or euler's (E q + g) / h.
  VectorXd Ev = EA * v;
  if (euler_gap_)
    for (int a = 0; a < na; ++a)
      Ev(a) = (EA.row(a).dot(q) + model_.mechanical->g(A[static_cast<size_t>(a)])) / h;
  const VectorXd Evn = EA * v_next;
  VectorXd w(na);
  for (int a = 0; a < na; ++a)
    w(a) = Evn(a) + (euler_gap_ ? 1.0 : e_(A[static_cast<size_t>(a)])) * Ev(a);
  const double scale = std::max({Ev.cwiseAbs().maxCoeff(), Evn.cwiseAbs().maxCoeff(),
                                 (Gd.cwiseProduct(z)).cwiseAbs().maxCoeff()});
  std::vector<int> act;
  if (const int bad = classify(z, w, Gd, scale, act); bad >= 0) {
    lose_all(t0, A[static_cast<size_t>(bad)],
             std::string("degenerate step LCP (") + scheme() + "): zero impulse and zero velocity");
    return false;
  }
  const int ns = static_cast<int>(act.size());
  std::vector<int> rows(static_cast<size_t>(ns));
  VectorXd lambda_N(ns);
  for (int a = 0; a < ns; ++a) {
    rows[static_cast<size_t>(a)] = A[static_cast<size_t>(act[a])];
    lambda_N(a) = z(act[a]);
  }
  Pieces pc;
  if (friction && !friction_pieces(t0, rows, lambda_N, *friction, v_next, pc)) return false;
  mu_terms(W, pc, dVn);
  const int nu = ns + static_cast<int>(pc.cols.size());
  if (nu == 0) return true;
  // Unknowns: the normal impulses of S, then the pieces' (stuck tangents,
  // faces); X the rows held, B the impulses' columns.
  MatrixXd X(nu, N_), B(N_, nu), rhs(nu, m_);
  for (int a = 0; a < ns; ++a) {
    const int r = rows[static_cast<size_t>(a)];
    X.row(a) = E_.row(r);
    B.col(a) = E_.row(r).transpose();
    rhs.row(a) = normal_rhs(r, h, Ev(act[a]), dVn);
  }
  for (const auto& [a, col] : pc.normal) B.col(a) += col;
  for (size_t k = 0; k < pc.cols.size(); ++k) {
    const int i = ns + static_cast<int>(k);
    X.row(i) = pc.rows[k].transpose();
    B.col(i) = pc.cols[k];
    rhs.row(i) = -X.row(i) * dVn;  // the held velocity stays as it is
  }
  const MatrixXd WB = W.solve(B);
  const Eigen::FullPivLU<MatrixXd> lu(X * WB);
  if (!lu.isInvertible()) {
    lose_all(t0, rows.front(),
             std::string("a step LCP (") + scheme() +
                 ") whose linear map at its active set is singular");
    return false;
  }
  dVn += WB * lu.solve(rhs);
  return true;
}

void MjStepSensitivity::mu_terms(const Eigen::LLT<MatrixXd>& W, const Pieces& pc,
                                 MatrixXd& dVn) const {
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    if (sp.kind != 'u') continue;
    for (const auto& [f, Fmu] : pc.per_mu)
      if (f == sp.j) dVn.col(nx0_ + static_cast<int>(p)) += W.solve(Fmu);
  }
}

bool MjStepSensitivity::friction_pieces(double t0, const std::vector<int>& rows,
                                        const VectorXd& lambda_N, const Friction& fr,
                                        const VectorXd& v_next, Pieces& out) {
  const mech::MechanicalModel& m = *model_.mechanical;
  for (size_t entry = 0; entry < m.friction.size(); ++entry) {
    const mech::FrictionalContact& fc = m.friction[entry];
    const auto it = std::find(rows.begin(), rows.end(), fc.contact);
    if (it == rows.end()) continue;  // open
    if (fc.mu == 0.0) {  // frictionless here; its mu[c] is one-sided where it would stick
      for (size_t p = 0; p < cols_.params.size(); ++p)
        if (cols_.params[p].kind == 'u' && cols_.params[p].i == fc.contact)
          lose_column(t0, fc.contact,
                      "mu = 0 at this contact: the derivative in mu is one-sided (it would "
                      "stick)",
                      nx0_ + static_cast<int>(p));
      continue;
    }
    const int a = static_cast<int>(it - rows.begin());
    const double p2 = fr.t2 ? (*fr.t2)(fc.contact) : 0.0;
    if (!contact_piece(t0, fc, static_cast<int>(entry), a, lambda_N(a), (*fr.t)(fc.contact), p2,
                       v_next, fr.V, out))
      return false;
  }
  return true;
}

// Coulomb's law at the step's end (friction_labels.hpp's tests): stuck
// (impulse strictly inside the cone, velocity in the stick band), sliding
// (impulse on the boundary, velocity above the band) on a vertex of the
// cone (impulse mu P_N D_i) or a face (impulse between D_i and D_i+1, the
// velocity along the face's normal: (D_i+1 - D_i).u = 0 held). A planar
// contact, or a 3-D one with d = 1 (a flat cone), has friction along t only.
bool MjStepSensitivity::contact_piece(double t0, const mech::FrictionalContact& fc, int entry,
                                      int a, double ln, double p1, double p2,
                                      const VectorXd& v_next, double V, Pieces& out) {
  const int d = model_.mechanical->edges_of(fc);
  const bool flat = !fc.is_3d() || d == 1;
  const double s = fc.sliding(v_next), s2 = flat ? 0.0 : fc.tangent2.dot(v_next);
  const double mu_pn = fc.mu * ln;
  const bool inside = strictly_inside_cone(p1, flat ? 0.0 : p2, mu_pn, flat ? 1 : d);
  const bool still = std::max(std::abs(s), std::abs(s2)) <= stick_band(fc, V);
  auto lose = [&](const char* why) {
    lose_all(t0, fc.contact, std::string("a step (") + scheme() + ") " + why);
    return false;
  };
  if (!inside && still)
    return lose("that sticks on its cone's boundary: stick and slip meet there");
  if (inside && !still) return lose("whose friction impulse is not Coulomb's at its velocity");
  const VectorXd t = fc.tangent;
  if (inside) {
    out.cols.push_back(t), out.rows.push_back(t);
    if (!flat) out.cols.push_back(VectorXd(fc.tangent2)), out.rows.push_back(VectorXd(fc.tangent2));
    return true;
  }
  if (flat) {
    if (p1 * s >= 0.0) return lose("whose friction impulse does not oppose its sliding");
    out.normal.emplace_back(a, -(s > 0.0 ? 1.0 : -1.0) * fc.mu * t);
    out.per_mu.emplace_back(entry, p1 / fc.mu * t);
    return true;
  }
  const impact::ConeFacet f = impact::cone_facet(s, s2, d);
  const VectorXd t2 = fc.tangent2;
  const auto [c0, s0] = impact::cone_edge(f.edge, d);
  const VectorXd Di = c0 * t + s0 * t2;
  if (!f.face) {
    if (std::hypot(p1 - mu_pn * c0, p2 - mu_pn * s0) > kDegenerate * mu_pn)
      return lose("whose friction impulse is not its cone's vertex opposing the sliding");
    out.normal.emplace_back(a, fc.mu * Di);
    out.per_mu.emplace_back(entry, ln * Di);
    return true;
  }
  // On the face: (p1, p2) = mu (ln D_i + b (D_i+1 - D_i)), 0 < b < ln.
  const auto [c1, s1] = impact::cone_edge((f.edge + 1) % (2 * d), d);
  const double dc = c1 - c0, ds = s1 - s0;
  const double b =
      ((p1 / fc.mu - ln * c0) * dc + (p2 / fc.mu - ln * s0) * ds) / (dc * dc + ds * ds);
  if (!(b > kDegenerate * ln && b < (1.0 - kDegenerate) * ln))
    return lose("sliding where a vertex and a face of its cone meet");
  const VectorXd Dd = dc * t + ds * t2;
  out.normal.emplace_back(a, fc.mu * Di);
  out.cols.push_back(fc.mu * Dd), out.rows.push_back(Dd);
  out.per_mu.emplace_back(entry, ln * Di + b * Dd);
  return true;
}

// ---- backward Euler ----

EulerStepSensitivity::EulerStepSensitivity(const mech::Model& model, const SensColumns& cols,
                                           const lcs::Lcs& sys)
    : StepSensitivity(model, cols), sys_(sys), n_(sys.n()), nu_(sys.k()) {
  Sa_ = MatrixXd::Zero(n_, m_);
  Sa_.topLeftCorner(nx0_, nx0_).setIdentity();
  S_ = Sa_;
  const size_t P = cols_.params.size();
  dA_.assign(P, MatrixXd());
  dB_.assign(P, MatrixXd());
  dC_.assign(P, MatrixXd());
  if (!model.is_mechanical()) return;
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs();
  const MatrixXd G = dense(m.M).inverse();
  G_ = G;
  dG_.assign(P, MatrixXd());
  for (size_t p = 0; p < P; ++p) {
    const SensParam& sp = cols_.params[p];
    MatrixXd dA = MatrixXd::Zero(n_, n_), dB = MatrixXd::Zero(n_, nu_),
             dC = MatrixXd::Zero(nu_, n_);
    switch (sp.kind) {  // A = [0 I 0; -GK -GD Gf; 0 0 0], B = [0; GE'; 0], C = [E 0 g]
      case 'f':
        dA.block(N, 2 * N, N, 1) = G.col(sp.i);
        break;
      case 'K':
        dA.block(N, sp.j, N, 1) = -G.col(sp.i);
        break;
      case 'D':
        dA.block(N, N + sp.j, N, 1) = -G.col(sp.i);
        break;
      case 'g':
        dC(sp.i, 2 * N) = 1.0;
        break;
      case 'M': {
        const MatrixXd dG = -G * unit_mass(N, sp.i, sp.j) * G;
        dG_[p] = dG;
        dA.block(N, 0, N, N) = -dG * dense(m.K);
        dA.block(N, N, N, N) = -dG * dense(m.D);
        dA.block(N, 2 * N, N, 1) = dG * m.f;
        dB.block(N, 0, N, nu_) = dG * dense(m.E).transpose();
        break;
      }
      default:
        break;  // 'e' is refused (check_sensitivity)
    }
    dA_[p] = dA;
    dB_[p] = dB;
    dC_[p] = dC;
  }
}

void EulerStepSensitivity::input_terms(double t1, double h, MatrixXd& R) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  const int N = m.dofs();
  VectorXd drive;  // f(t1) - f, formed once for the M columns
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    auto col = R.col(nx0_ + static_cast<int>(p)).segment(N, N);
    if (sp.kind == 'M') {
      if (drive.size() == 0) drive = mech::force_at(m, t1) - m.f;
      col += h * (dG_[p] * drive);
    } else if (sp.kind == 'a') {
      col += h * (G_ * amplitude_force(sp.i, t1));
    }
  }
}

void EulerStepSensitivity::step(double t0, double h, const MatrixXd& Phi, const MatrixXd& PhiB,
                                const MatrixXd& G, const VectorXd& x_next, const VectorXd& u) {
  if (!any_exists()) return;
  // (I - hA) dx+ = dx + h dA x+ + h dB u + h B du (+ h dd, the inputs' drive).
  MatrixXd R = Sa_;
  for (size_t p = 0; p < dA_.size(); ++p) {
    if (dA_[p].size() == 0) continue;
    R.col(nx0_ + static_cast<int>(p)) += h * (dA_[p] * x_next + dB_[p] * u);
  }
  if (model_.is_mechanical() && model_.mechanical->has_inputs()) input_terms(t0 + h, h, R);
  Sa_ = Phi * R;
  if (nu_ > 0) {
    const VectorXd w = sys_.C * x_next + sys_.D * u;
    const VectorXd q = w - G * u;  // the step's LCP vector C (I - hA)^{-1} x
    const double scale =
        std::max(q.cwiseAbs().maxCoeff(), (G.diagonal().cwiseProduct(u)).cwiseAbs().maxCoeff());
    std::vector<int> act;
    if (const int bad = classify(u, w, G.diagonal(), scale, act); bad >= 0) {
      lose_all(t0, bad, "degenerate step LCP (euler): zero multiplier and zero output");
      S_ = Sa_;
      return;
    }
    if (!act.empty()) {  // G_SS du_S = -(C_S dx+ + dC_S x+) with dx+ before du
      const int ns = static_cast<int>(act.size());
      MatrixXd GS(ns, ns), rhs(ns, m_), PS(n_, ns);
      for (int a = 0; a < ns; ++a) {
        PS.col(a) = PhiB.col(act[a]);
        for (int b = 0; b < ns; ++b) GS(a, b) = G(act[a], act[b]);
        rhs.row(a) = -sys_.C.row(act[a]) * Sa_;
        for (size_t p = 0; p < dC_.size(); ++p)
          if (dC_[p].size() > 0)
            rhs(a, nx0_ + static_cast<int>(p)) -= dC_[p].row(act[a]).dot(x_next);
      }
      Sa_ += PS * GS.fullPivLu().solve(rhs);
    }
  }
  S_ = Sa_;
}

}  // namespace lcsim::sim::detail
