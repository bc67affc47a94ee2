// Forward sensitivities of the exact method (docs/sensitivities.md).
//
// Along a phase of mode I the state obeys x' = Acl x (augmented for
// mechanical models, so constant forces are columns of Acl) and
// S = dx/dtheta obeys S' = Acl S + (dAcl/dtheta) x: S and x are advanced
// together by the Taylor series of the block-triangular system's exponential
// (Van Loan), in substeps of norm at most 1 (as Phase::expv).
// At an event at tau where the monitor h = w x (+ its parameter terms)
// reaches zero, dtau/dtheta = -(w S- + dh/dtheta)/(w x'-), and S jumps by
// the saltation matrix S+ = J S- + (J x'- - x'+) dtau/dtheta + dR/dtheta,
// with J = dR/dx the derivative of the re-initialisation: the identity for
// releases and contacts, for an impact the composition of the impact law's
// rounds, each linear in v at its fixed active set.
#include "sim/exact/sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>

namespace lcsim::sim::detail {

namespace {

MatrixXd dense(const Eigen::SparseMatrix<double>& A) { return MatrixXd(A); }

// e^{[Ab b; 0 0] tau} (Pade with scaling and squaring, Eigen's): Phi =
// e^{Ab tau} its upper-left block, Gamma = int_0^tau e^{Ab s} ds b its
// upper-right one (b: none, or the constant forcings' columns). Up to 16
// rows in a matrix type of that bounded size, whose temporaries live on the
// stack: the same arithmetic (the same products and pivots, the same
// numbers bit for bit), without the ~20 heap allocations of the dynamic
// type's, which cost a small phase's exponential (n = 12) about a sixth.
template <class Mat>
void augmented_exp_as(const MatrixXd& Ab, const MatrixXd& b, double tau, MatrixXd& Phi,
                      MatrixXd& Gamma) {
  const Eigen::Index n = Ab.rows(), nc = b.cols();
  Mat big = Mat::Zero(n + nc, n + nc);
  big.topLeftCorner(n, n) = Ab * tau;
  big.topRightCorner(n, nc) = b * tau;
  const Mat e = big.exp();
  Phi = e.topLeftCorner(n, n);
  Gamma = e.topRightCorner(n, nc);
}

void augmented_exp(const MatrixXd& Ab, const MatrixXd& b, double tau, MatrixXd& Phi,
                   MatrixXd& Gamma) {
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 16, 16>;
  if (Ab.rows() + b.cols() <= 16)
    augmented_exp_as<Small>(Ab, b, tau, Phi, Gamma);
  else
    augmented_exp_as<MatrixXd>(Ab, b, tau, Phi, Gamma);
}

// The exosystem columns of H = [-K -D f H_w] (docs/inputs.md): a force input
// enters the v rows of A as M^{-1} gain times its output row, so H_w is gain
// times that row at the input's exosystem states (after (q, v, 1)).
void add_input_forces(const mech::MechanicalModel& m, MatrixXd& H) {
  std::vector<int> at;
  int next = 2 * m.dofs() + 1;
  for (const mech::Input& in : m.inputs) {
    at.push_back(next);
    next += in.exo_size();
  }
  for (const mech::InputUse& use : m.force_inputs) {
    const mech::Input& in = m.inputs[static_cast<size_t>(use.input)];
    H.middleCols(at[static_cast<size_t>(use.input)], in.exo_size()) += use.gain * in.exo_output();
  }
}

}  // namespace

Sensitivity::Sensitivity(const mech::Model& model, const lcs::Lcs& sys, const SensColumns& cols,
                         const std::string& law)
    : model_(model), sys_(sys), cols_(cols) {
  law_ = law == "newton" ? 'n' : law == "inelastic" ? 'i' : 'r';
  n_ = sys.n();
  mech_ = model.is_mechanical();
  N_ = mech_ ? model.mechanical->dofs() : 0;
  nx0_ = cols.x0 ? static_cast<int>(model.state_size()) : 0;
  m_ = nx0_ + static_cast<int>(cols.params.size());
  exists_.assign(static_cast<size_t>(m_), 1);
  if (mech_) G_ = dense(model.mechanical->M).inverse();
  if (mech_)
    for (const mech::FrictionalContact& fc : model.mechanical->friction) {
      cone_d_.push_back(model.mechanical->edges_of(fc));
      has_3d_ = has_3d_ || fc.is_3d();
    }
}

std::vector<std::string> Sensitivity::column_names() const {
  std::vector<std::string> out;
  for (int i = 0; i < nx0_; ++i) out.push_back("x0[" + std::to_string(i) + "]");
  for (const SensParam& p : cols_.params) out.push_back(p.name);
  return out;
}

std::string Sensitivity::contact_name(int r) const {
  if (r < 0) return "";
  if (mech_) return model_.mechanical->constraints[static_cast<size_t>(r)];
  // A general LCS: its pair's name (a circuit's diode), else y<r>.
  if (static_cast<size_t>(r) < model_.pair_names.size())
    return model_.pair_names[static_cast<size_t>(r)];
  return "y" + std::to_string(r);
}

void Sensitivity::lose(double t, int contact, const std::string& reason,
                       const std::vector<int>& cols, bool always) {
  SensitivityLoss l;
  l.t = t;
  l.contact = contact_name(contact);
  l.reason = reason;
  for (int c : cols)
    if (exists_[static_cast<size_t>(c)]) {
      exists_[static_cast<size_t>(c)] = 0;
      l.columns.push_back(c);
    }
  if (!l.columns.empty() || always) losses_.push_back(std::move(l));
}

void Sensitivity::lose_all(double t, int contact, const std::string& reason) {
  std::vector<int> all(static_cast<size_t>(m_));
  for (int c = 0; c < m_; ++c) all[static_cast<size_t>(c)] = c;
  lose(t, contact, reason, all);
}

void Sensitivity::start(const VectorXd& xa) {
  MatrixXd S = MatrixXd::Zero(n_, m_);
  for (int i = 0; i < nx0_; ++i) S(i, i) = 1.0;
  if (mech_) input_start(S);  // an input's parameters move w(0)
  S0_ = S;
  Sc_ = S;
  t0_ = tc_ = 0.0;
  x0_ = xa;
  dtau_ = RowVectorXd::Zero(m_);
  S_minus_ = S;
  xdot_minus_ = VectorXd::Zero(n_);
  x_minus_ = xa;
  if (!mech_) {
    start_on_boundary(xa);
    return;
  }
  // A zero gap at the start: x0 lies on the boundary of the admissible set
  // E q + g >= 0, where x(t) has one-sided derivatives only (a perturbation
  // that closes the gap is inadmissible, one that opens it changes the
  // events); the zero test of infeasible_start (sim.hpp).
  const mech::MechanicalModel& m = *model_.mechanical;
  const VectorXd q = xa.head(N_);
  // With gap inputs (a moving stop) the gap is C x: E q + g + the stops' terms.
  const VectorXd gap = m.has_inputs() ? VectorXd(sys_.C * xa) : VectorXd(m.E * q + m.g);
  const VectorXd scale = m.has_inputs() ? VectorXd(sys_.C.cwiseAbs() * xa.cwiseAbs())
                                        : VectorXd(m.E.cwiseAbs() * q.cwiseAbs() + m.g.cwiseAbs());
  const MatrixXd E = m.has_friction() ? dense(m.E) : MatrixXd();
  for (int r = 0; r < m.num_constraints(); ++r) {
    if (std::abs(gap(r)) > 1e-9 * scale(r) + 1e-13) continue;
    std::vector<int> cols;
    // With friction (x0 columns only): an entry that moves neither the gap
    // nor its rate (E_r e_c = 0: sliding along the floor) keeps the start on
    // the boundary surface in the same mode, so its derivative exists (a
    // block sliding to rest, d/dv0). Frictionless models keep the rule
    // above for every entry (their tests count the columns it leaves).
    for (int c = 0; c < nx0_; ++c)
      if (E.size() == 0 || E(r, c % N_) != 0.0) cols.push_back(c);
    for (size_t p = 0; p < cols_.params.size(); ++p) {
      const SensParam& sp = cols_.params[p];
      bool moves = sp.kind == 'g' && sp.i == r;
      for (const mech::InputUse& u : m.gap_inputs)  // an input moving this stop
        moves = moves || (input_param_kind(sp.kind) && u.input == sp.i && u.gain(r) != 0.0);
      if (moves) cols.push_back(nx0_ + static_cast<int>(p));
    }
    lose(0.0, r,
         "zero gap at the start: the initial state is on the boundary of the admissible set, "
         "where only one-sided derivatives exist",
         cols, true);
  }
}

// A general LCS's start with y_i = C_i x0 = 0 on a row i without
// feedthrough (row i of D zero): x0 is on the surface C_i x = 0, whose one
// side has the constraint free and the other a jump P_I x (or a different
// event sequence: a rectifier started at the zero of its source), so only
// one-sided derivatives exist (the zero test of the mechanical start's gaps).
// A row with feedthrough has y_i = 0 held by its multiplier, which moves
// with x0 (the half-wave RLC's diode).
void Sensitivity::start_on_boundary(const VectorXd& xa) {
  const VectorXd y = sys_.C * xa;
  const VectorXd scale = sys_.C.cwiseAbs() * xa.cwiseAbs();
  for (Eigen::Index r = 0; r < y.size(); ++r) {
    if (!sys_.D.row(r).isZero(0.0) || std::abs(y(r)) > 1e-9 * scale(r) + 1e-13) continue;
    std::vector<int> cols;
    for (int c = 0; c < nx0_; ++c) cols.push_back(c);
    lose(0.0, static_cast<int>(r),
         "zero output at the start on a row without feedthrough: the initial state is on a "
         "switching surface, where only one-sided derivatives exist",
         cols, true);
  }
}

// dAcl/dtheta and dF_I/dtheta of mode I: with G = M^{-1}, E_I the mode's
// rows, W = E_I G E_I', Q = G - G E_I' W^{-1} E_I G and H = [-K -D f],
// Acl's velocity rows are Q H and F_I = -W^{-1} E_I G H (eq. (3.65) with
// the leading rows of order 2), so dQ = -Q dM Q and
// dF_I = W^{-1} E_I G (dM Q H - dH).
// Each parameter moves one or two entries of H or M, so its terms are
// columns of Q and rows of Q H (O(N n) each, not products of N x N
// matrices). Kept per mode: Acl, its balancing and these depend on the mode
// only (frictionless models).
void Sensitivity::mode_derivatives(const lcs::IndexSet& mode, double t) {
  const int P = static_cast<int>(cols_.params.size());
  dAb_.assign(static_cast<size_t>(P), MatrixXd());
  dF_.assign(static_cast<size_t>(P), MatrixXd());
  dW_.assign(static_cast<size_t>(P), MatrixXd());
  if (P == 0) return;
  if (const auto it = mode_cache_.find(mode); it != mode_cache_.end()) {
    dAb_ = it->second.dAb;
    dF_ = it->second.dF;
    dW_ = it->second.dW;
    return;
  }
  if (!mech_) {
    lcs_mode_derivatives(mode, t);
    mode_cache_.emplace(mode, ModeDerivatives{dAb_, dF_, dW_});
    return;
  }
  const mech::MechanicalModel& m = *model_.mechanical;
  const int kI = static_cast<int>(mode.size());
  MatrixXd EI(kI, N_);
  const MatrixXd E = dense(m.E);
  for (int i = 0; i < kI; ++i) EI.row(i) = E.row(mode[static_cast<size_t>(i)]);
  MatrixXd Q = G_, WinvEG = MatrixXd::Zero(kI, N_);
  if (kI > 0) {
    const MatrixXd W = EI * G_ * EI.transpose();
    WinvEG = W.ldlt().solve(EI * G_);
    Q = G_ - G_ * EI.transpose() * WinvEG;
  }
  MatrixXd H = MatrixXd::Zero(N_, n_);
  H.leftCols(2 * N_ + 1) << -dense(m.K), -dense(m.D), m.f;
  add_input_forces(m, H);
  const MatrixXd QH = Q * H;
  for (int p = 0; p < P; ++p) {
    const SensParam& sp = cols_.params[static_cast<size_t>(p)];
    if (input_param_kind(sp.kind)) {  // an input's own (sensitivity_inputs.cpp)
      input_mode_derivatives(static_cast<size_t>(p), mode);
      continue;
    }
    // dH has one entry -1 (K, D) or +1 (f) at (i, col); dM is the unit
    // entry (i, j) and its mirror.
    MatrixXd dAv = MatrixXd::Zero(N_, n_), dF = MatrixXd::Zero(kI, n_);
    if (sp.kind == 'M') {
      dAv -= Q.col(sp.i) * QH.row(sp.j);
      dF += WinvEG.col(sp.i) * QH.row(sp.j);
      if (sp.i != sp.j) {
        dAv -= Q.col(sp.j) * QH.row(sp.i);
        dF += WinvEG.col(sp.j) * QH.row(sp.i);
      }
    } else {
      const int col = sp.kind == 'f' ? 2 * N_ : sp.kind == 'K' ? sp.j : N_ + sp.j;
      const double sign = sp.kind == 'f' ? 1.0 : -1.0;
      if (sp.kind == 'f' || sp.kind == 'K' || sp.kind == 'D') {
        dAv.col(col) = sign * Q.col(sp.i);
        dF.col(col) = -sign * WinvEG.col(sp.i);
      }
    }
    MatrixXd dA = MatrixXd::Zero(n_, n_);
    dA.middleRows(N_, N_) = dAv;
    dAb_[static_cast<size_t>(p)] = D_.cwiseInverse().asDiagonal() * dA * D_.asDiagonal();
    dF_[static_cast<size_t>(p)] = dF;
  }
  mode_cache_.emplace(mode, ModeDerivatives{dAb_, dF_, dW_});
}

void Sensitivity::begin_phase(const Phase& ph, double t0, const VectorXd& xa, const MatrixXd& S) {
  Acl_ = ph.Acl;
  Ab_ = ph.Ab;
  use_sparse_ = ph.use_sparse;
  if (use_sparse_) Ab_sparse_ = ph.Ab_sparse;
  D_ = ph.D;
  mode_ = ph.mode;
  monitors_ = ph.monitors;
  for (Monitor& mon : monitors_) mon.w = mon.w.cwiseQuotient(ph.D.transpose());
  const bool friction = mech_ && model_.mechanical->has_friction() && !cols_.params.empty();
  if (std::any_of(exists_.begin(), exists_.end(), [](char e) { return e != 0; }))
    friction ? (has_3d_ ? cone_mode_derivatives(ph, t0) : friction_mode_derivatives(ph, t0))
             : mode_derivatives(ph.mode, t0);
  else
    dAb_.clear(), dF_.assign(cols_.params.size(), MatrixXd()),
        dW_.assign(cols_.params.size(), MatrixXd());  // at() carries nothing
  Ab_norm1_ = Ab_.cwiseAbs().colwise().sum().maxCoeff();
  norm1_ = Ab_norm1_;
  double dnorm = 0.0;
  for (const MatrixXd& d : dAb_)
    if (d.size() > 0) dnorm = std::max(dnorm, d.cwiseAbs().colwise().sum().maxCoeff());
  norm1_ += dnorm;
  t0_ = tc_ = t0;
  x0_ = xa;
  S0_ = S;
  for (int c = 0; c < m_; ++c)
    if (!exists_[static_cast<size_t>(c)]) S0_.col(c).setZero();
  Sc_ = S0_;
  zc_ = xa.cwiseQuotient(D_);
  dense_ = !use_sparse_ && n_ <= Phase::kDenseExpMax;
  forcing_structure();
  match_blocks();
}

// Each parameter's forcing dAb z along the phase: dAb's nonzero columns
// (f[i], K[i][j], D[i][j]: one; M[i][j]: every column), and whether all of
// them are constant states (a zero row of Ab: the augmented 1 of a
// mechanical model, a general LCS's DC source), where dAb z is one vector
// all along the phase: f[i]'s sensitivity is then s' = Ab s + b, whose
// forcing term over tau is int_0^tau e^{Ab s} ds b.
void Sensitivity::forcing_structure() {
  const size_t P = cols_.params.size();
  dcols_.assign(P, {});
  dcols_all_.assign(P, 0);
  dconst_.assign(P, 0);
  const_.clear();
  for (size_t p = 0; p < P && p < dAb_.size(); ++p) {
    const MatrixXd& d = dAb_[p];
    if (d.size() == 0) continue;
    std::vector<Eigen::Index> cols;
    for (Eigen::Index c = 0; c < d.cols(); ++c)
      if (!d.col(c).isZero(0.0)) cols.push_back(c);
    if (cols.size() * 8 > static_cast<size_t>(n_)) {  // dense enough: the full product
      dcols_all_[p] = 1;
      continue;
    }
    dconst_[p] = !cols.empty() && std::all_of(cols.begin(), cols.end(), [&](Eigen::Index c) {
      return Ab_.row(c).isZero(0.0);
    });
    if (dconst_[p])
      for (Eigen::Index c : cols) const_.emplace_back(static_cast<int>(p), c);
    dcols_[p] = std::move(cols);
  }
  forcing_.resize(n_, static_cast<Eigen::Index>(const_.size()));
  for (size_t k = 0; k < const_.size(); ++k)
    forcing_.col(static_cast<Eigen::Index>(k)) =
        dAb_[static_cast<size_t>(const_[k].first)].col(const_[k].second);
}

// S from the cursor to t: on a dense phase by its exponentials (at_dense),
// else by the Taylor series (at_taylor).
const MatrixXd& Sensitivity::at(double t) {
  if (t < tc_) {  // before the cursor: from the phase start
    tc_ = t0_;
    Sc_ = S0_;
    zc_ = x0_.cwiseQuotient(D_);
  }
  const double tau = t - tc_;
  if (tau == 0.0 || Acl_.size() == 0) return Sc_;
  if (std::none_of(exists_.begin(), exists_.end(), [](char e) { return e != 0; })) {
    tc_ = t;  // every column absent: nothing to carry (Sc_ is zero)
    return Sc_;
  }
  return dense_ ? at_dense(t, tau) : at_taylor(t, tau);
}

// A large phase: the Taylor series of exp(tau [Ab dAb; 0 Ab]) on (S, z) in
// balanced coordinates, in substeps with norm at most 1, each truncated
// once two consecutive terms are below eps/4 of the sum. The x0 block
// (S_x0' = Ab S_x0, no forcing) goes by Phi = e^{Ab tau} instead where
// forming Phi costs less than the action on its columns
// (x0_by_exponential): a chain's dx/dx0 is Phi itself. A parameter's forcing
// dAb z is a product over dAb's nonzero columns only (one for f, K, D).
const MatrixXd& Sensitivity::at_taylor(double t, double tau) {
  const int P = static_cast<int>(cols_.params.size());
  Eigen::Index c0 = 0;
  if (nx0_ > 0 && x0_by_exponential(tau)) {
    const DenseBlock& b = dense_block(tau, false);
    const MatrixXd Sb = D_.cwiseInverse().asDiagonal() * Sc_.leftCols(nx0_);
    Sc_.leftCols(nx0_) = D_.asDiagonal() * (b.Phi * Sb);
    c0 = nx0_;
    if (P == 0) {
      zc_ = b.Phi * zc_;
      tc_ = t;
      return Sc_;
    }
  }
  const Eigen::Index mc = m_ - c0;
  const long steps = std::max(1L, static_cast<long>(std::ceil(norm1_ * tau)));
  const double dt = tau / static_cast<double>(steps);
  MatrixXd Sb = D_.cwiseInverse().asDiagonal() * Sc_.rightCols(mc);
  VectorXd z = zc_;
  MatrixXd tS(n_, mc), nS(n_, mc), sumS(n_, mc);
  VectorXd tz(n_), nz(n_), sumz(n_);
  for (long st = 0; st < steps; ++st) {
    tS = Sb;
    sumS = Sb;
    tz = z;
    sumz = z;
    double prev = std::max(tS.cwiseAbs().maxCoeff(), tz.cwiseAbs().maxCoeff());
    for (int k = 1; k <= 80; ++k) {
      const double c = dt / static_cast<double>(k);
      if (use_sparse_) {
        nS.noalias() = Ab_sparse_ * tS;
        nz.noalias() = Ab_sparse_ * tz;
      } else {
        nS.noalias() = Ab_ * tS;
        nz.noalias() = Ab_ * tz;
      }
      for (int p = 0; p < P; ++p) {
        const MatrixXd& d = dAb_[static_cast<size_t>(p)];
        if (d.size() == 0) continue;
        auto col = nS.col(nx0_ + p - c0);
        if (dcols_all_[static_cast<size_t>(p)])
          col.noalias() += d * tz;
        else
          for (Eigen::Index j : dcols_[static_cast<size_t>(p)]) col += d.col(j) * tz(j);
      }
      tS = nS * c;
      tz = nz * c;
      sumS += tS;
      sumz += tz;
      const double cur = std::max(tS.cwiseAbs().maxCoeff(), tz.cwiseAbs().maxCoeff());
      const double bound =
          0.25 * kEps * std::max(sumS.cwiseAbs().maxCoeff(), sumz.cwiseAbs().maxCoeff());
      if (cur <= bound && prev <= bound) break;
      prev = cur;
    }
    Sb = sumS;
    z = sumz;
  }
  Sc_.rightCols(mc) = D_.asDiagonal() * Sb;
  zc_ = z;
  tc_ = t;
  return Sc_;
}

// Forming Phi = e^{Ab tau} (Pade 13 with scaling and squaring: ~8 products
// and one per squaring, n^3 each) against the Taylor action on the x0
// block's columns (ceil(||Ab||_1 tau) substeps of ~18 products with Ab, its
// non-zeros when sparse, each of 2 nnz flops per column). The action's
// products run about 8 times below the dense product's rate (thin or
// sparse operands, and the truncation test's passes over the block:
// measured on the chain of 100, n = 201, at tau = 10, 0.3 s against 0.04 s
// for Eigen's exp). A Phi already kept for tau costs its product only.
bool Sensitivity::x0_by_exponential(double tau) const {
  if (find_block(tau, false) != nullptr) return true;
  const double n = static_cast<double>(n_), cols = static_cast<double>(nx0_);
  const double nnz = use_sparse_ ? static_cast<double>(Ab_sparse_.nonZeros()) : n * n;
  const double a = Ab_norm1_ * tau;
  const double taylor = cols * std::max(1.0, std::ceil(a)) * 18.0 * 2.0 * nnz * 8.0;
  const double squarings = std::max(0.0, std::ceil(std::log2(std::max(1.0, a))));
  const double dense = (8.0 + squarings) * 2.0 * n * n * n + 2.0 * n * n * cols;
  return dense < taylor;
}

// Phi = e^{Ab tau} and, with `params`, each parameter's term over tau: for
// the constant forcings b (forcing_structure) Gamma = int_0^tau e^{Ab s} ds
// b, the upper-right block of the exponential of [Ab b; 0 0] (size n + their
// count, one for all of them; its upper-left block is Phi); for the others
// Psi_p, the upper-right block of e^{[Ab dAb_p; 0 Ab] tau} (Van Loan, size
// 2n). By Pade with scaling and squaring. Kept per tau and phase matrix
// (samples share dt_out; phases of one mode share Ab), the least recently
// used dropped first.
const Sensitivity::DenseBlock& Sensitivity::dense_block(double tau, bool params) {
  if (const DenseBlock* c = find_block(tau, params)) {
    c->used = ++dense_clock_;
    return *c;
  }
  DenseBlock b;
  b.tau = tau;
  b.params = params;
  b.mode = mode_;
  b.Ab = Ab_;
  b.D = D_;
  b.forcing = forcing_;
  if (params) b.dAb = dAb_;
  if (params) {
    const Eigen::Index nc = static_cast<Eigen::Index>(const_.size());
    if (nc > 0) augmented_exp(Ab_, forcing_, tau, b.Phi, b.Gamma);
    b.Psi.assign(cols_.params.size(), MatrixXd());
    for (size_t p = 0; p < cols_.params.size() && p < dAb_.size(); ++p) {
      const MatrixXd& d = dAb_[p];
      if (d.size() == 0 || dconst_[p] || (dcols_[p].empty() && !dcols_all_[p])) continue;
      MatrixXd big = MatrixXd::Zero(2 * n_, 2 * n_);
      big.topLeftCorner(n_, n_) = Ab_;
      big.topRightCorner(n_, n_) = d;
      big.bottomRightCorner(n_, n_) = Ab_;
      const MatrixXd e = (big * tau).exp();
      b.Psi[p] = e.topRightCorner(n_, n_);
      if (b.Phi.size() == 0) b.Phi = e.topLeftCorner(n_, n_);  // e^{Ab tau}
    }
  }
  if (b.Phi.size() == 0) {
    MatrixXd none;
    augmented_exp(Ab_, MatrixXd(n_, 0), tau, b.Phi, none);
  }
  b.fits = true;
  b.fits_params = params;
  b.used = ++dense_clock_;
  // As many blocks as fit in ~4 MB (a block keeps Ab and Phi, and per
  // parameter dAb and Psi: (2 + 2P) n^2 doubles), 8 to 32: phases of a few
  // modes alternate, and each event leaves steps of new lengths (the NAO
  // legs to 0.28 s: 19 exponentials before grid steps' roundings of dt were
  // taken as dt by find_block, where 8 kept blocks gave the same 19).
  const double block_bytes = 8.0 * (2.0 + 2.0 * static_cast<double>(cols_.params.size())) *
                             static_cast<double>(n_) * static_cast<double>(n_);
  const size_t capacity = static_cast<size_t>(std::clamp(4e6 / block_bytes, 8.0, 32.0));
  if (dense_cache_.size() < capacity) {
    dense_cache_.push_back(std::move(b));
    return dense_cache_.back();
  }
  DenseBlock& slot =
      *std::min_element(dense_cache_.begin(), dense_cache_.end(),
                        [](const DenseBlock& x, const DenseBlock& y) { return x.used < y.used; });
  slot = std::move(b);
  return slot;
}

// The kept block for tau of this phase's matrix (its mode, Ab, D and
// constant forcings, and with `params` its parameters' forcings: fits and
// fits_params, set once per phase by match_blocks), or null. A step from
// the cursor tc_ to t = tc_ + tau within 4 ulps of t (or of tau) of a kept
// length is taken as that length, the nearest: grid steps t_k - t_(k-1)
// differ from dt by the rounding of k dt, an ulp or two of t, as
// GridSampler::at takes the plain run's samples. That saves 11 of the 19
// exponentials of the NAO legs' f[0] run to 0.28 s and moves S by rounding
// (bench/README.md gives the measured change).
namespace {
// Two phases' parameter forcings dAb, bit for bit (a block's Psi is formed
// from them: the mode and Ab alone do not fix an input's or a friction
// coefficient's column).
bool same_forcings(const std::vector<MatrixXd>& a, const std::vector<MatrixXd>& b) {
  if (a.size() != b.size()) return false;
  for (size_t p = 0; p < a.size(); ++p)
    if (a[p].rows() != b[p].rows() || a[p].cols() != b[p].cols() || a[p] != b[p]) return false;
  return true;
}
}  // namespace

const Sensitivity::DenseBlock* Sensitivity::find_block(double tau, bool params) const {
  const double ulps = 4.0 * kEps * std::max(std::abs(tc_ + tau), tau);
  const DenseBlock* best = nullptr;
  for (const DenseBlock& c : dense_cache_) {
    if (!c.fits || (params && !c.fits_params) || std::abs(c.tau - tau) > ulps) continue;
    if (best == nullptr || std::abs(c.tau - tau) < std::abs(best->tau - tau)) best = &c;
  }
  return best;
}

void Sensitivity::match_blocks() {
  for (DenseBlock& c : dense_cache_) {
    c.fits = c.mode == mode_ && c.Ab.rows() == Ab_.rows() && c.Ab == Ab_ && c.D == D_ &&
             c.forcing.cols() == forcing_.cols() && c.forcing == forcing_;
    c.fits_params = c.fits && c.params && same_forcings(c.dAb, dAb_);
  }
}

// A dense phase (n <= Phase::kDenseExpMax, as the phase's own exponential):
// over tau, S_x0 <- Phi S_x0 and, per parameter p, s_p <- Phi s_p + Gamma_p
// (a constant forcing) or Phi s_p + Psi_p z (dense_block): O(log(|Ab| tau))
// products where the Taylor substeps cost |Ab| tau (a stiff contact's
// phase).
const MatrixXd& Sensitivity::at_dense(double t, double tau) {
  const DenseBlock& b = dense_block(tau, true);
  next_ = D_.cwiseInverse().asDiagonal() * Sc_;
  Sc_.noalias() = b.Phi * next_;
  for (size_t k = 0; k < const_.size(); ++k)  // z's constant entry: fixed along the phase
    Sc_.col(nx0_ + const_[k].first) +=
        b.Gamma.col(static_cast<Eigen::Index>(k)) * zc_(const_[k].second);
  for (size_t p = 0; p < b.Psi.size(); ++p)
    if (b.Psi[p].size() > 0)
      Sc_.col(nx0_ + static_cast<Eigen::Index>(p)).noalias() += b.Psi[p] * zc_;
  Sc_ = D_.asDiagonal() * Sc_;
  znext_.noalias() = b.Phi * zc_;
  zc_.swap(znext_);
  tc_ = t;
  return Sc_;
}

void Sensitivity::fill(double t, MatrixXd& dx, std::vector<char>& exists) {
  const MatrixXd& S = at(t);
  dx = S.topRows(mech_ ? 2 * N_ : n_);
  for (int c = 0; c < m_; ++c)
    if (!exists_[static_cast<size_t>(c)]) dx.col(c).setZero();
  exists = exists_;
}

void Sensitivity::fill_sample(double t, Sample& s) {
  s.dx.swap(spare_dx_);
  s.dx_exists.swap(spare_exists_);
  fill(t, s.dx, s.dx_exists);  // the same size each time: no allocation
}

void Sensitivity::take_back(Sample& s) {
  spare_dx_.swap(s.dx);
  spare_exists_.swap(s.dx_exists);
}

void Sensitivity::before_event(double tau, const VectorXd& x_minus, int monitor) {
  S_minus_ = at(tau);
  xdot_minus_ = Acl_ * x_minus;
  event_t_ = tau;
  x_minus_ = x_minus;
  dtau_ = RowVectorXd::Zero(m_);
  if (monitor < 0) return;
  const Monitor& mon = monitors_[static_cast<size_t>(monitor)];
  trigger_ = mon.constraint;
  trigger_stick_ = mon.multiplier && mon.friction >= 0;
  if (mon.multiplier && mon.friction < 0) released_ = mon.constraint;
  const double rate = mon.w.dot(xdot_minus_);
  // Grazing: the monitor reaches zero with a zero rate (to sqrt(eps) of its
  // terms); dtau/dtheta = -(...)/rate does not exist.
  if (std::abs(rate) <= kSqrtEps * mon.w.cwiseAbs().dot(xdot_minus_.cwiseAbs())) {
    lose_all(tau, mon.constraint,
             mon.multiplier ? "the contact force reaches zero with a zero rate (grazing release)"
                            : "grazing contact: the gap reaches zero with a zero rate");
    return;
  }
  // Another monitor at zero too: coinciding events (an impact as a held
  // contact's force vanishes, two gaps closing at once), where the event
  // sequence of nearby runs differs on either side.
  co_triggers_.clear();
  for (size_t j = 0; j < monitors_.size(); ++j) {
    const Monitor& other = monitors_[j];
    if (static_cast<int>(j) == monitor || other.friction >= 0) continue;
    if (same_event(other, mon)) {
      co_triggers_.push_back(other.constraint);
      continue;
    }
    // Zero to sqrt(eps) of its row times the state's size (a held force's
    // own terms may all vanish there: springs relaxed, no load).
    if (std::abs(other.w.dot(x_minus)) <=
        kSqrtEps * other.w.cwiseAbs().sum() * x_minus.cwiseAbs().maxCoeff())
      lose_all(tau, other.constraint,
               other.multiplier
                   ? "coinciding events: this contact's force vanishes at another event"
                   : "coinciding events: this contact closes at the same time as another");
  }
  RowVectorXd dh = mon.w * S_minus_;
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    const Eigen::Index c = nx0_ + static_cast<Eigen::Index>(p);
    if (mon.friction >= 0) {  // a stick force's or a sliding velocity's
      if (dF_[p].size() > 0)
        dh(c) += has_3d_ ? cone_monitor_dh(p, static_cast<size_t>(monitor), x_minus)
                         : friction_monitor_dh(p, static_cast<size_t>(monitor), x_minus);
      continue;
    }
    if (!mon.multiplier && sp.kind == 'g' && sp.i == mon.constraint) dh(c) += 1.0;
    if (!mon.multiplier && dW_[p].size() > 0) dh(c) += dW_[p].row(mon.constraint).dot(x_minus);
    if (mon.multiplier && dF_[p].size() > 0) {
      const auto it = std::find(mode_.begin(), mode_.end(), mon.constraint);
      dh(c) += dF_[p].row(it - mode_.begin()).dot(x_minus);
    }
  }
  dtau_ = -dh / rate;
  if (has_3d_) check_cone_event(tau, x_minus, static_cast<size_t>(monitor));
  for (int c = 0; c < m_; ++c)
    if (!exists_[static_cast<size_t>(c)]) dtau_(c) = 0.0;
}

// Two monitors of a general LCS that are one function up to a positive
// factor (w_o = c w, the diodes of a bridge switching together at a zero of
// one voltage): they reach zero at the same time for every x0 (a general
// LCS takes x0 only), so that is no coincidence of two events but one event
// of two constraints. Parallel to sqrt(eps) of |w_o|.
bool Sensitivity::same_event(const Monitor& other, const Monitor& mon) const {
  if (mech_) return false;  // a parameter (g[c], f[i]) could move one alone
  const double ww = mon.w.squaredNorm();
  if (ww == 0.0) return false;
  const double c = other.w.dot(mon.w) / ww;
  return c > 0.0 && (other.w - c * mon.w).norm() <= kSqrtEps * other.w.norm();
}

// Moving stops (docs/inputs.md): the law acts on v + delta with
// E_J delta = gdot_J = (C_w A_w w)_J, so E_A v_rel = E_A v + gdot_A and
// v+ = v + G E_A' mu(v_rel): J_vw = G E_A' Tc (C_w A_w)_A with T = Tc E_A
// (Tc = -W^{-1} (1 + e) for moreau-restitution, -(1 + e) W^{-1} for newton).
void Sensitivity::moving_stop_columns(const std::vector<int>& A, const MatrixXd& EA,
                                      const Eigen::LDLT<MatrixXd>& Wf, const VectorXd& one_e,
                                      MatrixXd& J) const {
  const int a = static_cast<int>(A.size()), ne = n_ - 2 * N_ - 1;
  const MatrixXd rate = sys_.C.rightCols(ne) * sys_.A.bottomRightCorner(ne, ne);
  MatrixXd rateA(a, ne);
  for (int i = 0; i < a; ++i) rateA.row(i) = rate.row(A[static_cast<size_t>(i)]);
  const MatrixXd Tc = law_ == 'r'
                          ? MatrixXd(Wf.solve(-MatrixXd(one_e.asDiagonal())))
                          : MatrixXd(-(one_e.asDiagonal() * Wf.solve(MatrixXd::Identity(a, a))));
  J.block(N_, 2 * N_ + 1, N_, ne) = G_ * EA.transpose() * Tc * rateA;
}

ImpactActive impact_active(const EventResult::ImpactRound& rd, const MatrixXd& E) {
  ImpactActive a;
  const VectorXd& v = rd.v_before;
  for (int r : rd.closed) {
    a.pmax = std::max(a.pmax, std::abs(rd.impulse(r)));
    a.amax = std::max(a.amax, std::abs(E.row(r).dot(v)));
  }
  for (int r : rd.closed)
    if (rd.impulse(r) > kSqrtEps * a.pmax) a.A.push_back(r);
  return a;
}

// One round of the impact law at its fixed active set A (the closed
// contacts with a positive impulse): v+ = v + G E_A' mu with
// mu = -W^{-1} (1 + e) E_A v (moreau-restitution: E_A v+ = -e E_A v) or
// mu = -(1 + e) W^{-1} E_A v (newton; inelastic: e = 0), W = E_A G E_A'.
// J (augmented) has the velocity block I + G E_A' dmu/dv, dR the derivative
// of v+ in each parameter (e of a contact in A, entries of M). False when
// the active set is not locally constant: a closed contact with a zero
// impulse and a zero separation rate (several LCP solutions nearby).
bool Sensitivity::impact_map(double t, const EventResult::ImpactRound& rd, MatrixXd& J,
                             MatrixXd& dR) {
  const mech::MechanicalModel& m = *model_.mechanical;
  const MatrixXd E = dense(m.E);
  const VectorXd e = law_ == 'i' ? VectorXd::Zero(rd.restitution.size()) : rd.restitution;
  const VectorXd& v = rd.v_before;
  const ImpactActive act = impact_active(rd, E);
  const std::vector<int>& A = act.A;
  const double amax = act.amax;
  const int a = static_cast<int>(A.size());
  MatrixXd EA(a, N_);
  VectorXd eA(a);
  for (int i = 0; i < a; ++i) {
    EA.row(i) = E.row(A[static_cast<size_t>(i)]);
    eA(i) = e(A[static_cast<size_t>(i)]);
  }
  const MatrixXd W = EA * G_ * EA.transpose();
  const Eigen::LDLT<MatrixXd> Wf(W);
  const VectorXd aA = EA * v;
  // The inelastic impulse lambda (newton) and mu.
  const VectorXd lambda = Wf.solve(-aA);
  const VectorXd mu = law_ == 'r' ? VectorXd(Wf.solve(-(aA + eA.cwiseProduct(aA))))
                                  : VectorXd(lambda + eA.cwiseProduct(lambda));
  const VectorXd vplus = v + G_ * EA.transpose() * mu;
  const VectorXd vin = v + G_ * EA.transpose() * lambda;  // the inelastic velocity
  for (int r : rd.closed) {
    if (std::find(A.begin(), A.end(), r) != A.end()) continue;
    const double sep =
        law_ == 'r' ? E.row(r).dot(vplus) + e(r) * E.row(r).dot(v) : E.row(r).dot(vin);
    if (std::abs(sep) <= kSqrtEps * amax) {
      lose_all(t, r,
               "degenerate impact: a zero impulse and a zero separation rate (the impact LCP's "
               "active set is not locally constant)");
      return false;
    }
  }
  const VectorXd one_e = (eA.array() + 1.0).matrix();
  const MatrixXd T = law_ == 'r' ? MatrixXd(Wf.solve(-(one_e.asDiagonal() * EA)))
                                 : MatrixXd(-(one_e.asDiagonal() * Wf.solve(EA)));
  J = MatrixXd::Identity(n_, n_);
  J.block(N_, N_, N_, N_) += G_ * EA.transpose() * T;
  if (!m.gap_inputs.empty()) moving_stop_columns(A, EA, Wf, one_e, J);
  dR = MatrixXd::Zero(n_, m_);
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    VectorXd dv = VectorXd::Zero(N_);
    if (sp.kind == 'e' && law_ != 'i') {
      const auto it = std::find(A.begin(), A.end(), sp.i);
      if (it == A.end()) continue;
      const Eigen::Index i = it - A.begin();
      VectorXd dmu = VectorXd::Zero(a);
      if (law_ == 'r') {
        VectorXd unit = VectorXd::Zero(a);
        unit(i) = aA(i);
        dmu = Wf.solve(-unit);
      } else {
        dmu(i) = lambda(i);
      }
      dv = G_ * EA.transpose() * dmu;
    } else if (sp.kind == 'M') {
      MatrixXd dM = MatrixXd::Zero(N_, N_);
      dM(sp.i, sp.j) = dM(sp.j, sp.i) = 1.0;
      const MatrixXd dG = -G_ * dM * G_;
      const MatrixXd dW = EA * dG * EA.transpose();
      VectorXd dmu =
          law_ == 'r' ? VectorXd(Wf.solve(-dW * mu))
                      : VectorXd((eA.array() + 1.0).matrix().cwiseProduct(Wf.solve(-dW * lambda)));
      dv = dG * EA.transpose() * mu + G_ * EA.transpose() * dmu;
    } else if (input_param_kind(sp.kind) && !m.gap_inputs.empty()) {
      dv = input_impact_dv(p, A, EA, Wf, one_e);  // the stops' rate moves
    } else {
      continue;
    }
    dR.block(N_, nx0_ + static_cast<Eigen::Index>(p), N_, 1) = dv;
  }
  return true;
}

void Sensitivity::after_event(const EventResult& ev, const Phase& next, double t,
                              const VectorXd& x_plus, const lcs::IndexSet& held, int trigger) {
  MatrixXd J = MatrixXd::Identity(n_, n_), dR = MatrixXd::Zero(n_, m_);
  // An accumulation's limit, composed where the run took it among the rounds.
  auto limit = [&](size_t round) {
    if (!mech_ || !ev.accumulation || ev.limit_round != round) return;
    MatrixXd Jl, dRl;
    if (!limit_map(t, ev, Jl, dRl)) return;
    J = Jl * J;
    dR = Jl * dR + dRl;
  };
  if (!mech_ && ev.jumped) {
    for (const EventResult::LcsJump& jump : ev.lcs_jumps) {
      MatrixXd Jr, dRr;
      if (!lcs_jump(t, jump, Jr, dRr)) break;
      J = Jr * J;
      dR = Jr * dR + dRr;
    }
    // The jump is P_I x (thesis §3.4.2): the re-initialised state must be
    // J x- to rounding, else J is not its derivative.
    if (!ev.lcs_jumps.empty() &&
        (J * ev.lcs_jumps.front().x_before - x_plus).cwiseAbs().maxCoeff() >
            1e-9 * (1.0 + x_plus.cwiseAbs().maxCoeff()))
      lose_all(t, trigger, "a jump of a general LCS that is not P_I x: its derivative is unknown");
  }
  if (mech_ && !ev.rounds.empty()) {
    const bool friction = model_.mechanical->has_friction();
    // Another contact closing at the same time: coinciding events.
    for (int r : ev.rounds.front().closed)
      if (r != trigger && t > 0.0 && std::find(held.begin(), held.end(), r) == held.end())
        lose_all(t, r, "coinciding events: this contact closes at the same time as another");
    for (size_t i = 0; i < ev.rounds.size(); ++i) {
      limit(i);
      const auto& rd = ev.rounds[i];
      MatrixXd Jr, dRr = MatrixXd::Zero(n_, m_);
      if (friction
              ? !(has_3d_ ? cone_impact_map(t, rd, Jr, dRr) : friction_impact_map(t, rd, Jr, dRr))
              : !impact_map(t, rd, Jr, dRr))
        break;
      J = Jr * J;
      dR = Jr * dR + dRr;
    }
  }
  limit(ev.rounds.size());
  if (mech_) plastic_restitution(ev, next, t);
  const VectorXd xdot_plus = next.Acl * x_plus;
  MatrixXd S = J * S_minus_ + (J * xdot_minus_ - xdot_plus) * dtau_ + dR;
  // A start at rest (stick) or on a face's bisector: see project_friction_start.
  if (mech_ && model_.mechanical->has_friction() && t == 0.0 && trigger < 0)
    project_friction_start(next, S);
  begin_phase(next, t, x_plus, S);
}

// e[c] at a plastic impact (e_c = 0, the law's restitution, on a contact
// that approached in one of the event's rounds, E_c v < 0) after which the
// contact is held: any e_c > 0 makes it bounce instead (another event
// sequence), so only a one-sided derivative exists and the column is lost
// (the map's own dv+/de_c is no derivative of the run there). A contact that
// leaves after a plastic impact keeps its column: with e_c > 0 it leaves
// with a small rate, the same sequence. The law `inelastic` ignores e.
void Sensitivity::plastic_restitution(const EventResult& ev, const Phase& next, double t) {
  if (law_ == 'i') return;
  const MatrixXd E = dense(model_.mechanical->E);
  for (size_t p = 0; p < cols_.params.size(); ++p) {
    const SensParam& sp = cols_.params[p];
    if (sp.kind != 'e' || std::find(next.mode.begin(), next.mode.end(), sp.i) == next.mode.end())
      continue;
    const bool approached = std::any_of(ev.rounds.begin(), ev.rounds.end(), [&](const auto& rd) {
      return rd.restitution(sp.i) == 0.0 &&
             std::find(rd.closed.begin(), rd.closed.end(), sp.i) != rd.closed.end() &&
             E.row(sp.i).dot(rd.v_before) < 0.0;
    });
    if (approached)
      lose(t, sp.i,
           "a plastic impact (e = 0) after which the contact is held: any restitution e > 0 "
           "makes it bounce (another event sequence), so only a one-sided derivative in e exists",
           {nx0_ + static_cast<int>(p)});
  }
}

void Sensitivity::check_phase_start(const Phase& ph, double t, const std::vector<int>& m0,
                                    const lcs::IndexSet& undetermined) {
  const int released = released_, trigger = trigger_;
  const bool stuck = trigger_stick_;
  released_ = trigger_ = -1;
  trigger_stick_ = false;
  if (!undetermined.empty())
    lose_all(t, undetermined.front(),
             "mode selection left a constraint undetermined (its multiplier and output vanish "
             "identically)");
  for (size_t j = 0; j < ph.monitors.size() && j < m0.size(); ++j) {
    const Monitor& mon = ph.monitors[j];
    if (m0[j] == 0) continue;
    if (mon.friction >= 0) {
      if (is_cone_entry(mon.friction))
        check_cone_start(mon, ph.friction[static_cast<size_t>(mon.friction)], t, m0[j], trigger,
                         stuck);
      else
        check_friction_start(mon, t, m0[j], trigger, stuck);
      continue;
    }
    // A multiplier starting at zero (with a nonzero rate for the contact
    // whose output just reached zero: a general LCS's continuous contact),
    // or a free output zero to the second derivative (third for the
    // contact just released): the multiplier and the gap's acceleration
    // both vanish.
    const bool triggered =
        mon.constraint == trigger ||
        std::find(co_triggers_.begin(), co_triggers_.end(), mon.constraint) != co_triggers_.end();
    const bool degenerate =
        mon.multiplier ? !(m0[j] == 1 && triggered)
                       : m0[j] < 0 || m0[j] > 3 || (m0[j] == 3 && mon.constraint != released);
    if (degenerate)
      lose_all(t, mon.constraint,
               "degenerate mode: the multiplier and the gap's acceleration both vanish (several "
               "mode selections nearby)");
  }
  co_triggers_.clear();
}

// A friction monitor starting at zero (order m0 of its first nonzero
// derivative) at a phase start. Generic: the sliding velocity of the
// contact whose slip just reversed (m0 = 1), or whose stick force just
// reached the cone's edge (m0 = 2: the friction force is continuous there,
// so is the tangential acceleration, zero). At t = 0, a contact starting to
// slip from rest: only the entries of x0 that move its sliding velocity
// (w e_c != 0) see another stick / slip sequence on one side. Anything else
// (a stick force starting at the edge, a sliding velocity with zero
// acceleration) has several stick / slip selections nearby.
void Sensitivity::check_friction_start(const Monitor& mon, double t, int m0, int trigger,
                                       bool stuck) {
  if (mon.constraint == trigger && (m0 == 1 || (m0 == 2 && stuck))) return;
  if (t == 0.0 && trigger < 0 && !mon.multiplier && m0 == 1) {
    std::vector<int> cols;
    for (int c = 0; c < nx0_; ++c)
      if (mon.w(c) != 0.0) cols.push_back(c);
    lose(t, mon.constraint,
         "slip from rest at the start: the sliding velocity is zero, so only one-sided "
         "derivatives exist in the entries that move it",
         cols, true);
    return;
  }
  lose_all(t, mon.constraint,
           "degenerate stick / slip: a friction monitor starts at zero (the stick force at the "
           "cone's edge, or a sliding velocity with zero acceleration)");
}

void Sensitivity::graze(double t, int trigger) {
  lose_all(t, trigger, "grazing: the event changed no mode");
}

void Sensitivity::fill_event(Event& e) const {
  e.dt = dtau_;
  e.dt_exists = exists_;
}

}  // namespace lcsim::sim::detail
