// Private to src/sim: forward sensitivities of the exact event-driven method
// (docs/sensitivities.md).
//   sensitivity_names.cpp  the columns asked ("x0", "f[1]", "e[stop]"):
//                          parsing and the run's check (check_sensitivity)
//   sensitivity.cpp        their propagation: along a phase the variational
//                          equation S' = Acl S + (dAcl/dtheta) x, at an event
//                          the saltation matrix
//   sensitivity_friction.cpp  an impact with planar friction at its outcome
//   sensitivity_cone.cpp   phases with 3-D contacts on a polyhedral cone
//                          (stick, edge and face slip), their monitors and
//                          starts; sensitivity_cone_impact.cpp their impacts
//   sensitivity_lcs.cpp    a general LCS's parts: dAcl/dtheta of a mode for
//                          the entries of A, B, C, D, and the jump P_I x
//   sensitivity_inputs.cpp an input's own parameters (a sine's, a piecewise
//                          linear input's): the exosystem's rows
#pragma once

#include <Eigen/Dense>
#include <lcsim/sim/sim.hpp>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

// A named parameter: f[i], g[c], e[c], K[i][j], D[i][j], M[i][j], mu[c]
// (kind 'u', j the friction entry) of a mechanical model, A[i][j], B[i][j], C[i][j], D[i][j] of a
// general LCS (0-based indices resolved from names), or an input's own (i the input, j a point;
// kinds in input_param_kind).
struct SensParam {
  char kind = 'f';
  int i = -1, j = -1;
  std::string name;  // as asked
};

// An input's parameter of a mechanical model (sensitivity_inputs.cpp):
// 'a' amplitude, 'o' offset, 'w' frequency, 'z' damping, 'p' phase of a
// sine; 'v' a point's value, 't' a point's time, 'y' the delay, '1' v1,
// '2' v2, 'd' width, 'r' rise, 'l' fall, 'T' period of a piecewise linear
// input (a pulse's names move its points).
bool input_param_kind(char kind);
// Such a parameter's dA of the augmented LCS (the exosystem's rows; a sine
// force's amplitude in the velocity rows, M^-1 gain): what a friction
// phase's forces and closed loop move by (sensitivity_friction.cpp).
MatrixXd input_param_dA(const mech::MechanicalModel& m, const lcs::Lcs& sys, const SensParam& p);
// M[i][j]'s velocity rows of dAcl in a friction phase with held rows H,
// force columns Gc, forces F (lu factors H M^-1 Gc'); sets dF
// (sensitivity_friction.cpp, planar and 3-D).
MatrixXd mass_phase_rows(const SensParam& sp, const MatrixXd& G, const MatrixXd& Av,
                         const MatrixXd& H, const MatrixXd& Gc, const MatrixXd& F,
                         const Eigen::FullPivLU<MatrixXd>& lu, MatrixXd& dF);
// M[i][j] and e[c] of an impact map at a fixed outcome, v+ = v + G B lambda
// with X G B lambda = c - R v, planar or cone (sensitivity_friction.cpp):
// into dR's velocity rows of their columns.
void mass_restitution_impact_columns(const std::vector<SensParam>& params, int nx0,
                                     const MatrixXd& G, const MatrixXd& GB, const MatrixXd& X,
                                     const Eigen::FullPivLU<MatrixXd>& W, const VectorXd& lambda,
                                     const std::vector<int>& A, const VectorXd& erate,
                                     MatrixXd& dR);
// Parses amplitude[in], offset[in], ..., pwl_v[in][k], pwl_t[in][k]: "" or
// the input error; false (untouched) when `s` is none of those names.
bool parse_input_param(const mech::MechanicalModel& m, const std::string& s, SensParam& p,
                       std::string& error);

// The columns asked: x0 (every entry of the initial state) first, then the
// parameters in the order asked. `error` is "" or the input error.
struct SensColumns {
  bool x0 = false;
  std::vector<SensParam> params;
  std::string error;
};
SensColumns parse_sensitivity(const mech::Model& model, const std::vector<std::string>& asked);

// The rows of an impact round's closed set that carry an impulse (above
// sqrt(eps) of the largest), and the largest impulse and approach rate
// |E_r v-| over the closed set (the scales of the maps' degeneracy tests).
struct ImpactActive {
  std::vector<int> A;
  double pmax = 0.0, amax = 0.0;
};
ImpactActive impact_active(const EventResult::ImpactRound& rd, const MatrixXd& E);

// The sensitivity S = dx/dtheta (augmented state x n columns) of one run,
// carried along beside the state by EventDriven's stages.
class Sensitivity {
 public:
  Sensitivity(const mech::Model& model, const lcs::Lcs& sys, const SensColumns& cols,
              const std::string& law);
  std::vector<std::string> column_names() const;
  // At t = 0: S = dx0/dtheta, and the losses of a start on the boundary of
  // the admissible set (a zero gap).
  void start(const VectorXd& xa);
  // S at t (within the current phase, t >= its start), augmented rows.
  const MatrixXd& at(double t);
  // Fills a sample's or the final dx and its existence flags.
  void fill(double t, MatrixXd& dx, std::vector<char>& exists);
  // The same into a streamed sample (Options::sample_sink) in storage this
  // run keeps: fill_sample lends it to s.dx and s.dx_exists, take_back takes
  // it back once the sink has seen s, so no sample allocates its dx.
  void fill_sample(double t, Sample& s);
  void take_back(Sample& s);
  // Before the re-initialisation at tau: S-, and dtau/dtheta from the
  // monitor `monitor` of the ending phase (-1 at t = 0).
  void before_event(double tau, const VectorXd& x_minus, int monitor);
  // After it: the saltation into the new phase from x_plus. `held`: the
  // constraints the ending phase kept closed; `released`: the constraint a
  // multiplier monitor released (-1 if none), kept for check_phase_start.
  void after_event(const EventResult& ev, const Phase& next, double t, const VectorXd& x_plus,
                   const lcs::IndexSet& held, int trigger);
  // A phase start where a monitor is zero with the wrong order (m0: the
  // order of its first nonzero derivative) or the mode selection left some
  // constraint undetermined: the active set is not locally constant.
  void check_phase_start(const Phase& ph, double t, const std::vector<int>& m0,
                         const lcs::IndexSet& undetermined);
  // An event that changed no mode (a graze).
  void graze(double t, int trigger);
  // Between before_event and after_event of a scheduled event: the last
  // `rows` states (the inputs' exosystems) are re-set to functions of t
  // alone, so their derivative is zero from there.
  // An input's own parameters (sensitivity_inputs.cpp): those rows are set
  // to the re-initialised state's derivative instead, and a parameter that
  // moves this breakpoint (a point's time, a delay) gets dt_b/dtheta.
  void reset_exosystem(int rows);
  // The last event's dtau/dtheta.
  void fill_event(Event& e) const;
  const std::vector<SensitivityLoss>& losses() const { return losses_; }

 private:
  void begin_phase(const Phase& ph, double t0, const VectorXd& xa, const MatrixXd& S);
  // Marks `cols` absent from t on; the loss is recorded when it ends some
  // column, or `always`.
  void lose(double t, int contact, const std::string& reason, const std::vector<int>& cols,
            bool always = false);
  void lose_all(double t, int contact, const std::string& reason);
  void start_on_boundary(const VectorXd& xa);
  const MatrixXd& at_dense(double t, double tau);
  const MatrixXd& at_taylor(double t, double tau);
  // The exponentials of the current phase over tau (kept per tau): Phi =
  // e^{Ab tau}, and with `params` each parameter's term.
  struct DenseBlock;
  const DenseBlock& dense_block(double tau, bool params);
  const DenseBlock* find_block(double tau, bool params) const;
  // Marks the kept blocks formed from the current phase's matrices
  // (DenseBlock::fits), once per phase: find_block then compares lengths only.
  void match_blocks();
  // A large phase: whether the x0 block goes by Phi (formed, Pade) rather
  // than by the Taylor action on its columns, by their estimated costs.
  bool x0_by_exponential(double tau) const;
  // The forcing structure of each parameter in the current phase (begin_phase).
  void forcing_structure();
  bool impact_map(double t, const EventResult::ImpactRound& round, MatrixXd& J, MatrixXd& dR);
  // e[c] lost at a plastic impact after which the contact is held.
  void plastic_restitution(const EventResult& ev, const Phase& next, double t);
  // An accumulation's limit as the run takes it (sensitivity_accumulation.cpp):
  // the M-orthogonal projection onto E_J q + g_J = 0, E_J v = 0 from
  // ev.limit_x; false (every column lost) where it has no derivative.
  bool limit_map(double t, const EventResult& ev, MatrixXd& J, MatrixXd& dR);
  // An impact round with planar friction (sensitivity_friction.cpp): J at
  // its outcome and dR for mu[c] (a sliding contact's impulse); false, with
  // every column lost, where the outcome is not locally constant.
  bool friction_impact_map(double t, const EventResult::ImpactRound& round, MatrixXd& J,
                           MatrixXd& dR);
  // A phase with planar friction (sensitivity_friction.cpp): dAcl and the
  // forces' dF (normals, then the sticking tangents) for f[i], g[c],
  // K[i][j], D[i][j]; a stick monitor's parameter term dh.
  void friction_mode_derivatives(const Phase& ph, double t);
  double friction_monitor_dh(size_t p, size_t monitor, const VectorXd& x) const;
  bool friction_impact_regular(double t, const EventResult::ImpactRound& rd,
                               const std::vector<int>& A, const std::vector<int>& stuck,
                               const std::vector<int>& sliding, const VectorXd& lambda,
                               const VectorXd& vplus);
  void moving_stop_columns(const std::vector<int>& A, const MatrixXd& EA,
                           const Eigen::LDLT<MatrixXd>& Wf, const VectorXd& one_e,
                           MatrixXd& J) const;
  // dAcl/dtheta and dF/dtheta of a mode for each parameter.
  void mode_derivatives(const lcs::IndexSet& mode, double t);
  // A general LCS (sensitivity_lcs.cpp): the same for the entries of A, B,
  // C, D (and dW_, the free outputs' monitors), losing a column whose entry
  // changes a leading row index of the mode; and one jump x+ = P_I x: J = P_I
  // and dR = (dP_I/dtheta) x (false when not available: every column lost).
  void lcs_mode_derivatives(const lcs::IndexSet& mode, double t);
  bool lcs_jump(double t, const EventResult::LcsJump& jump, MatrixXd& J, MatrixXd& dR);
  // An input's parameter p (sensitivity_inputs.cpp): its phases' dAcl, dF
  // and dW from the augmented LCS's exosystem block and outputs, its start
  // (dw(0)/dtheta), and its impacts on a moving stop (dv+/dtheta from the
  // stop's rate).
  void input_mode_derivatives(size_t p, const lcs::IndexSet& mode);
  void input_start(MatrixXd& S);
  VectorXd input_impact_dv(size_t p, const std::vector<int>& A, const MatrixXd& EA,
                           const Eigen::LDLT<MatrixXd>& Wf, const VectorXd& one_e) const;
  // Models with a 3-D contact (sensitivity_cone.cpp): a phase's dAcl and
  // dF for f[i], K[i][j], D[i][j], mu[c] with cone rows and columns (planar
  // entries as friction_mode_derivatives); a cone monitor's parameter term;
  // a cone monitor starting at zero; at t = 0 the projection of S onto the
  // rows that mode selection put at zero (stick, a face's cross row); an
  // impact round with a 3-D contact closed (sensitivity_cone_impact.cpp:
  // Stewart–Trinkle at its outcome; false, every column lost, where it is
  // not locally constant), else friction_impact_map.
  void cone_mode_derivatives(const Phase& ph, double t);
  double cone_monitor_dh(size_t p, size_t monitor, const VectorXd& x) const;
  void check_cone_start(const Monitor& mon, FrictionMode mode, double t, int m0, int trigger,
                        bool stuck);
  void project_friction_start(const Phase& ph, MatrixXd& S) const;
  // Before an event ended by monitor `mon` of a cone entry: the losses of
  // its non-generic forms (a slide stopping on an edge, a stick force
  // reaching the polygon at a vertex).
  void check_cone_event(double tau, const VectorXd& x_minus, size_t monitor);
  bool cone_impact_map(double t, const EventResult::ImpactRound& round, MatrixXd& J, MatrixXd& dR);
  bool is_cone_entry(int f) const {
    return f >= 0 && static_cast<size_t>(f) < cone_d_.size() &&
           cone_d_[static_cast<size_t>(f)] >= 2;
  }
  std::string contact_name(int r) const;
  bool same_event(const Monitor& other, const Monitor& mon) const;
  void check_friction_start(const Monitor& mon, double t, int m0, int trigger, bool stuck);

  const mech::Model& model_;
  const lcs::Lcs& sys_;
  SensColumns cols_;
  char law_ = 'r';  // 'r' moreau-restitution, 'n' newton, 'i' inelastic
  int n_ = 0, N_ = 0, nx0_ = 0, m_ = 0;
  bool mech_ = false;
  MatrixXd G_;  // M^{-1} (mechanical)
  std::vector<char> exists_;
  std::vector<SensitivityLoss> losses_;
  MatrixXd spare_dx_;  // a streamed sample's dx and flags (fill_sample)
  std::vector<char> spare_exists_;
  // The current phase: start, closed loop, balancing, monitors, derivatives.
  double t0_ = 0.0;
  MatrixXd S0_;
  VectorXd x0_;
  MatrixXd Acl_, Ab_;
  Eigen::SparseMatrix<double, Eigen::RowMajor> Ab_sparse_;  // when the phase uses it
  bool use_sparse_ = false;
  struct ModeDerivatives {
    std::vector<MatrixXd> dAb, dF, dW;
  };
  std::map<lcs::IndexSet, ModeDerivatives> mode_cache_;
  VectorXd D_;
  double norm1_ = 0.0;
  std::vector<MatrixXd> dAb_;  // balanced dAcl/dtheta per parameter
  std::vector<MatrixXd> dF_;   // dF_I/dtheta per parameter (unbalanced)
  // A general LCS: d(monitor row)/dtheta of each free output (k x n, rows
  // C_r + D_rI F_I; the mode's rows zero) per parameter, empty otherwise.
  std::vector<MatrixXd> dW_;
  lcs::IndexSet mode_;
  std::vector<Monitor> monitors_;  // unbalanced w
  // A phase's exponentials per step length (at_dense; a large phase's x0
  // block, at_taylor), kept across phases: a later phase of the same mode
  // (the same Ab, D and constant forcings) reuses them, as the plain run's
  // grid steps do (StepExp).
  struct DenseBlock {
    double tau = 0.0;
    bool params = false;  // Gamma and Psi computed
    lcs::IndexSet mode;
    MatrixXd Ab, forcing;
    VectorXd D;
    std::vector<MatrixXd> dAb;  // the parameters' forcings Psi was formed from
    MatrixXd Phi;
    // Constant forcings (const_): int_0^tau e^{Ab s} ds times forcing_, by
    // columns (one augmented exponential of size n + their count).
    MatrixXd Gamma;
    std::vector<MatrixXd> Psi;  // per parameter (Van Loan, size 2n), others
    // Formed from the current phase's mode, Ab, D and constant forcings
    // (fits), and its parameters' forcings dAb too (fits_params): set by
    // match_blocks at each phase start and for a block formed in it.
    bool fits = false, fits_params = false;
    // When it last served a step (dense_clock_): once the cache is full, the
    // least recently used block goes.
    mutable long used = 0;
  };
  bool dense_ = false;
  std::vector<DenseBlock> dense_cache_;
  long dense_clock_ = 0;  // steps served by blocks so far (DenseBlock::used)
  MatrixXd next_;         // at_dense's product (kept: no allocation per sample)
  VectorXd znext_;
  double Ab_norm1_ = 0.0;  // ||Ab||_1 (norm1_ adds the parameters')
  // Per parameter in the current phase: the nonzero columns of dAb when few
  // (the product dAb z over them; all columns: empty and dcols_all_), and
  // whether they are all constant states (Ab's row zero: the augmented 1),
  // so dAb z = sum over them of dAb.col(c) z(c), the same all along the
  // phase (f[i]): const_ lists the pairs (parameter, column c), forcing_
  // their columns dAb.col(c) (balanced; per mode, not per state).
  std::vector<std::vector<Eigen::Index>> dcols_;
  std::vector<char> dcols_all_, dconst_;
  std::vector<std::pair<int, Eigen::Index>> const_;
  MatrixXd forcing_;  // n x const_.size()
  // The cursor: S and the balanced state at tc_.
  double tc_ = 0.0;
  MatrixXd Sc_;
  VectorXd zc_;
  // The pending event.
  MatrixXd S_minus_;
  VectorXd xdot_minus_;
  RowVectorXd dtau_;
  double event_t_ = 0.0;  // the pending event's time
  VectorXd x_minus_;      // the state before it (augmented)
  int released_ = -1;     // the constraint the last event released (-1 if none)
  int trigger_ = -1;      // the constraint whose monitor ended the last phase
  // Constraints whose monitors are the trigger's up to a positive factor
  // (same_event): they switch with it.
  std::vector<int> co_triggers_;
  bool trigger_stick_ = false;
  std::vector<Eigen::Index> stick_row_;  // per friction entry: its row of dF (-1 if not stuck)
  // Models with a 3-D contact: d per friction entry (1 planar), the phase's
  // modes and each entry's first held row of dF / friction_F_ (-1 if none).
  bool has_3d_ = false;
  std::vector<int> cone_d_;
  std::vector<FrictionMode> cone_modes_;
  std::vector<Eigen::Index> cone_first_;
  MatrixXd friction_F_;  // the friction phase's forces (normals, sticking tangents)  //
                         // the trigger was a stick force reaching the cone's edge
};

}  // namespace lcsim::sim::detail
