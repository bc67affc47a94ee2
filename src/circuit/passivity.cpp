// Passivity and well-posedness of a circuit (thesis Ch. 5), judged on its
// LCS with the sources set to zero: the circuit states alone.
#include <Eigen/Eigenvalues>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/core/format.hpp>

namespace lcsim::circuit {
namespace {

lcs::Lcs circuit_part(const Circuit& c) {
  const lcs::Lcs& s = *c.model.lcs;
  const int nc = c.circuit_states;
  return {s.A.topLeftCorner(nc, nc), s.B.topRows(nc), s.C.leftCols(nc), s.D};
}

// [X, A X, ..., A^{n-1} X] and its numerical rank.
int krylov_rank(const MatrixXd& A, const MatrixXd& X) {
  const Eigen::Index n = A.rows();
  if (n == 0) return 0;
  MatrixXd K(n, n * X.cols());
  MatrixXd P = X;
  for (Eigen::Index i = 0; i < n; ++i) {
    K.middleCols(i * X.cols(), X.cols()) = P;
    P = A * P;
  }
  return lcs::numerical_rank(K);
}

void judge_passive(const Circuit& c, const lcs::Lcs& sub, PassivityReport& r) {
  const auto cert = lcs::verify_passivity_certificate(sub, c.energy);
  if (cert.ok()) {
    r.passive = "yes";
    r.passive_reason =
        "the stored energy (sum of C v^2/2 and L i^2/2) is a storage function: "
        "[A'K+KA, KB-C'; B'K-C, -(D+D')] <= 0 with K = diag(C, L) (eq. (5.4))";
    return;
  }
  if (sub.n() > 0) {
    const Eigen::VectorXcd ev = Eigen::EigenSolver<MatrixXd>(sub.A, false).eigenvalues();
    const double scale = std::max(sub.A.cwiseAbs().maxCoeff(), 1e-300);
    Eigen::Index worst = 0;
    const double re = ev.real().maxCoeff(&worst);
    if (re > 1e-9 * scale) {
      r.passive = "no";
      r.passive_reason =
          "A has the eigenvalue " + short_number(re) +
          (ev(worst).imag() != 0.0 ? " ± " + short_number(std::abs(ev(worst).imag())) + "i"
                                   : std::string()) +
          " in the right half plane, which (5.4) forbids (A'K + KA <= 0 with K > 0)";
      return;
    }
  }
  const lcs::WellPosednessReport wp = lcs::analyze_well_posedness(sub);
  r.passive = wp.passive == "no" ? "no" : "unknown";
  r.passive_reason = wp.passive == "no"
                         ? wp.passivity_reason
                         : "the stored energy is not a storage function (" + cert.message +
                               ") and no necessary condition of passivity fails";
}

}  // namespace

PassivityReport judge_passivity(const Circuit& c) {
  PassivityReport r;
  for (const Element& e : c.netlist.elements)
    if ((e.kind == ElementKind::kResistor || e.kind == ElementKind::kCapacitor ||
         e.kind == ElementKind::kInductor) &&
        e.value < 0.0)
      r.negative_elements.push_back(e.name);
  const lcs::Lcs sub = circuit_part(c);
  judge_passive(c, sub, r);
  const int n = sub.n(), k = sub.k();
  r.full_column_rank_b = lcs::numerical_rank(sub.B) == k;
  r.controllable = krylov_rank(sub.A, sub.B) == n;
  r.observable = krylov_rank(sub.A.transpose(), sub.C.transpose()) == n;
  r.locally_well_posed = lcs::analyze_well_posedness(sub).locally_well_posed;
  r.globally_well_posed =
      r.passive == "yes" && r.full_column_rank_b && r.controllable && r.observable;
  if (r.globally_well_posed) {
    r.verdict =
        "passive, and Assumption 5.2.2 holds: one solution from every initial state "
        "(Theorems 5.5.2 and 5.5.3)";
    return r;
  }
  std::string fails;
  if (r.passive != "yes") fails = "passivity (" + r.passive + ")";
  if (!r.full_column_rank_b)
    fails += (fails.empty() ? "" : ", ") + std::string("B of full column rank (rank ") +
             std::to_string(lcs::numerical_rank(sub.B)) + " < " + std::to_string(k) + " diodes)";
  if (!r.controllable) fails += (fails.empty() ? "" : ", ") + std::string("(A, B) controllable");
  if (!r.observable) fails += (fails.empty() ? "" : ", ") + std::string("(C, A) observable");
  r.verdict = "Theorems 5.5.2-5.5.3 do not apply: " + fails + " fails; Theorem 3.6.3 " +
              (r.locally_well_posed ? "gives local well-posedness"
                                    : "does not apply either: the exact method's mode selection "
                                      "is not guaranteed (a run may end in a numerical failure)");
  return r;
}

}  // namespace lcsim::circuit
