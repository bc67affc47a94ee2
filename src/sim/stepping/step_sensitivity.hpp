// Private to src/sim: the derivative of the time-stepping schemes' discrete
// map (docs/sensitivities.md, "The time-stepping derivative"): for
// Moreau–Jean and backward Euler, dx_j/dtheta carried from step to step by
// the implicit function theorem on each step's LCP at its active set, as a
// differentiable time-stepping simulator computes it. Strictly active rows
// (positive multiplier) are equalities, inactive rows (positive gap or
// velocity) are dropped; a degenerate row (both zero) ends every column: the
// step map has no derivative there.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

// The columns, S = dx/dtheta on the user's state (rows as x) and the losses,
// shared by both schemes.
class StepSensitivity {
 public:
  StepSensitivity(const mech::Model& model, const SensColumns& cols);
  std::vector<std::string> column_names() const;
  // A sample's or the final dx and its flags.
  void fill(MatrixXd& dx, std::vector<char>& exists) const;
  const std::vector<SensitivityLoss>& losses() const { return losses_; }
  // Writes the columns, the final derivative and the losses into tr.
  void finish(Trajectory& tr) const;

 protected:
  // The rows of a step's LCP: -1 when row r is degenerate (multiplier and
  // residual both within sqrt(eps) of `scale`), else the strictly active
  // positions (z_a * diag_a > the threshold) in `active`.
  static int classify(const VectorXd& z, const VectorXd& w, const VectorXd& diag, double scale,
                      std::vector<int>& active);
  // Every column absent from t on (once), naming constraint `row`.
  void lose_all(double t, int row, const std::string& reason);
  // Column `column` absent from t on (once), naming constraint `row`.
  void lose_column(double t, int row, const std::string& reason, int column);
  // The columns `which` selects that still exist: absent from t on, one loss.
  void lose_columns(double t, int row, const std::string& reason,
                    const std::function<bool(int)>& which);
  bool any_exists() const;
  // d f(t)/d amplitude of input `input` (the parameter kind 'a'): its force
  // gains times the sine's unit waveform at t (docs/inputs.md).
  VectorXd amplitude_force(int input, double t) const;

  const mech::Model& model_;
  SensColumns cols_;
  int nx0_ = 0, m_ = 0;
  MatrixXd S_;  // dx/dtheta: state rows (the scheme's), m_ columns
  std::vector<char> exists_;
  std::vector<SensitivityLoss> losses_;
};

// Moreau–Jean: W (v+ - v) = h (f - D v - K (q + h theta v)) + E_A' z,
// q+ = q + h ((1 - theta) v + theta v+), E_S v+ + e_S . E_S v = 0 on the
// strictly active rows S. Columns x0, f, K, D, M, e (g is refused: the map
// depends on it only through the active set).
// With `euler_gap` (backward Euler with friction, euler_friction.cpp: this
// step at theta = 1 with the normal rows at the position level) the active
// rows hold E_S v+ = -(E_S q + g_S) / h instead, so they move with dq and
// dg (columns g[c]; e is refused for euler).
class MjStepSensitivity : public StepSensitivity {
 public:
  MjStepSensitivity(const mech::Model& model, const SensColumns& cols, double theta,
                    bool euler_gap = false);
  // A step's friction: the tangential impulses per constraint along t and
  // t2 (N s; t2 null for a planar model) and the step's velocity scale V
  // (m/s; friction_labels.hpp's stick band).
  struct Friction {
    const VectorXd* t = nullptr;
    const VectorXd* t2 = nullptr;
    double V = 0.0;
  };
  // The step of length h starting at t0 from (q, v) to v_next with the
  // impulses z on the active set A (and its friction, null without).
  void step(double t0, double h, const VectorXd& q, const VectorXd& v, const VectorXd& v_next,
            const IndexSet& A, const VectorXd& z, const Friction* friction = nullptr);

 private:
  // The friction's part of the step map at the step's outcome: impulse
  // columns added to a strictly active normal's (a sliding contact's mu D,
  // D its cone's vertex) and further unknowns, each a column with the row
  // it holds (a stuck contact's tangents; a contact sliding on a face of
  // its cone, the face's direction).
  struct Pieces {
    std::vector<std::pair<int, VectorXd>> normal;  // (position in S, column)
    std::vector<VectorXd> cols, rows;
    // A sliding contact's friction impulse over mu, F / mu (generalised,
    // N s), by its mechanical.friction entry: its mu[c] column's forcing.
    std::vector<std::pair<int, VectorXd>> per_mu;
  };
  // The mu[c] columns' forcing W^-1 F / mu of each sliding contact (zero for
  // a stuck one, at its outcome), added to dVn.
  void mu_terms(const Eigen::LLT<MatrixXd>& W, const Pieces& pc, MatrixXd& dVn) const;
  // The impulses' part of dv+ (added to dVn): the strictly active normal
  // rows S as equalities with the friction's pieces; false when the step
  // map has no derivative (a loss recorded).
  bool impulse_terms(double t0, double h, const Eigen::LLT<MatrixXd>& W, const VectorXd& q,
                     const VectorXd& v, const VectorXd& v_next, const IndexSet& A,
                     const VectorXd& z, const Friction* friction, MatrixXd& dVn);
  // The active row r's right-hand side for its impulse's change: E_r dv+
  // (Moreau–Jean's -e_r E_r dv - de_r E_r v, or euler's -(E_r dq + dg_r) /
  // h) less E_r dVn, the change without it; `rate` is E_r v or (E_r q +
  // g_r) / h.
  Eigen::RowVectorXd normal_rhs(int r, double h, double rate, const MatrixXd& dVn) const;
  // "moreau-jean" or "euler": the losses' messages.
  const char* scheme() const { return euler_gap_ ? "euler" : "moreau-jean"; }
  // The pieces of the frictional contacts on S (`rows`, constraint indices,
  // normal impulses lambda_N); false (a loss recorded) where two outcomes
  // meet or the impulse is not Coulomb's at the velocity.
  bool friction_pieces(double t0, const std::vector<int>& rows, const VectorXd& lambda_N,
                       const Friction& fr, const VectorXd& v_next, Pieces& out);
  // One contact's piece: fc on S at position a with normal impulse ln and
  // friction impulse (p1, p2).
  bool contact_piece(double t0, const mech::FrictionalContact& fc, int entry, int a, double ln,
                     double p1, double p2, const VectorXd& v_next, double V, Pieces& out);
  const Eigen::LLT<MatrixXd>& factor(double h);
  // The parameters' part of W dv+ (before the impulses): h (df - dD v -
  // dK (q + h theta v)) - dW (v+ - v) for each parameter column.
  // With inputs, the step's force theta f(t0 + h) + (1 - theta) f(t0) adds
  // its amplitudes' columns.
  void parameter_terms(double t0, double h, const VectorXd& q, const VectorXd& v,
                       const VectorXd& v_next, MatrixXd& R) const;

  double theta_;
  bool euler_gap_ = false;
  int N_ = 0;
  MatrixXd M_, D_, K_, E_;
  VectorXd e_;
  double h_[2] = {-1.0, -1.0};
  Eigen::LLT<MatrixXd> llt_[2];
};

// Backward Euler on the LCS (A, B, C, D) (augmented for a mechanical model):
// (I - hA) x+ = x + h B u, w = C x+ + D u, w_S = 0 on the strictly active
// rows. Columns x0, and for a mechanical model f, g, K, D, M (e is refused:
// the scheme ignores restitution).
class EulerStepSensitivity : public StepSensitivity {
 public:
  EulerStepSensitivity(const mech::Model& model, const SensColumns& cols, const lcs::Lcs& sys);
  // The step of length h starting at t0 to x_next (augmented) with the
  // multipliers u; Phi = (I - hA)^{-1}, PhiB = h Phi B, G = D + C PhiB.
  void step(double t0, double h, const MatrixXd& Phi, const MatrixXd& PhiB, const MatrixXd& G,
            const VectorXd& x_next, const VectorXd& u);

 private:
  // A model with inputs: the step's drive h (0, M^{-1} (f(t1) - f), 0)
  // (euler.cpp) moves the M and amplitude columns too.
  void input_terms(double t1, double h, MatrixXd& R) const;

  const lcs::Lcs& sys_;
  int n_ = 0, nu_ = 0;
  MatrixXd G_;                // M^{-1} (mechanical models)
  std::vector<MatrixXd> dG_;  // dM^{-1} of each M column (else empty)
  MatrixXd Sa_;               // S on the augmented state (its last row zero)
  // dA, dB, dC of each parameter column (mechanical models).
  std::vector<MatrixXd> dA_, dB_, dC_;
};

}  // namespace lcsim::sim::detail
