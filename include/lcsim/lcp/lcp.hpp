// The LCP layer: w = M z + q, 0 <= z ⟂ w >= 0 (thesis eq. (3.11)-(3.12)).
//
// Public face of src/lcp. Eigen only. Every solver returns a Result value and
// never throws: the status says what happened, the diagnostics say how well.
#pragma once

#include <Eigen/Dense>
#include <lcsim/core/outcome.hpp>
#include <lcsim/core/registry.hpp>
#include <lcsim/core/status.hpp>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace lcsim::lcp {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// The one status vocabulary (include/lcsim/core/status.hpp); an LCP solve
// uses kSolved, kRayTermination, kIterationLimit, kNumericalFailure (a
// singular pivot, non-finite values, a failed residual test) and
// kInvalidInput (dimensions disagree, empty or non-finite data).
using lcsim::Status;
using lcsim::to_string;

// status and message (the Outcome): kInvalidInput until a solver sets it;
// message is the human-readable detail ("" when solved cleanly).
struct Result : OutcomeStartingAs<Status::kInvalidInput> {
  VectorXd z;             // the solution (size k); empty only on kInvalidInput
  VectorXd w;             // M z + q
  int pivots = 0;         // pivoting solvers: number of pivots
  int iterations = 0;     // iterative solvers: sweeps
  double residual = 0.0;  // natural residual ||min(z, w)||_inf (unscaled diagnostics)
  // The acceptance measure: the worst row of scaled_residual() below, in
  // [0, 1]; "solved" means scaled_residual <= Options::tolerance.
  double scaled_residual = 0.0;
  int worst_row = -1;  // the row attaining scaled_residual (-1 if k = 0)
  double min_z = 0.0;  // most negative entry of z (0 if none negative)
  double min_w = 0.0;  // most negative entry of w (0 if none negative)
};

// Diagnostics of a candidate z: fills w, residual, min_z, min_w.
Result evaluate(const MatrixXd& M, const VectorXd& q, const VectorXd& z);
// ||min(z, w)||_inf with w = M z + q.
double natural_residual(const MatrixXd& M, const VectorXd& q, const VectorXd& z);
// The row-scaled residual, the one acceptance measure of every solver:
//   max_i |min(z_i / ||z||_inf, w_i / s_i)|,  s_i = |q_i| + sum_j |M_ij| |z_j|,
// (0/0 read as 0). s_i is the magnitude of the terms that form w_i, so w_i is
// judged against its own row, whatever the scale of the other rows (computing
// w_i alone already costs rounding ~ k eps s_i); z is judged against
// ||z||_inf because the principal solves that produce z are normwise backward
// stable: an entry below tol ||z||_inf is zero to working accuracy. The value
// lies in [0, 1] and is invariant under positive row scaling of (M, q) and
// under scaling of z; a negative z_i or w_i counts with its magnitude. Sets
// *worst_row to the row attaining it (-1 if k = 0). Infinity on size mismatch.
double scaled_residual(const MatrixXd& M, const VectorXd& q, const VectorXd& z,
                       int* worst_row = nullptr);
// Empty string if (M, q) is a well-formed LCP, else what is wrong.
std::string validate(const MatrixXd& M, const VectorXd& q);

struct Options {
  // The one acceptance tolerance: a z is "solved" when scaled_residual(M, q, z)
  // <= tolerance, i.e. every row i has z_i >= -tol ||z||_inf, w_i >= -tol s_i
  // and min(z_i / ||z||_inf, w_i / s_i) within tol (see scaled_residual). 1e-12
  // leaves ~1e4 eps for the rounding of a k <= 100 solve and refinement.
  double tolerance = 1e-12;
  // Pivoting solvers: cap on pivots (0 = default, 50 * k + 1000 for Lemke).
  int max_pivots = 0;
  // Iterative solvers.
  int max_iterations = 10000;
  double relaxation = 1.0;               // SOR parameter omega in (0, 2); 1 is Gauss–Seidel
  const VectorXd* warm_start = nullptr;  // initial z (projected onto z >= 0)
};

// The acceptance test as a result, for solvers outside this layer (Bullet's
// MLCP solvers): the diagnostics of z for (M, q), and status kSolved iff z is
// finite and scaled_residual <= opt.tolerance, else kNumericalFailure with a
// message naming the worst row. Every "solved" of lcsim means this.
Result accept(const MatrixXd& M, const VectorXd& q, VectorXd z, const Options& opt);

// The pivoting solvers (Lemke, enumeration) pivot on the row-equilibrated LCP
// (R M, R q), R = diag(2^-e_i) with 2^e_i ~ max_j |M_ij|: exact in floating
// point and the same solution set (0 <= z ⟂ R w >= 0 iff 0 <= z ⟂ w >= 0), so
// a row of size 1 next to a row of size 1e12 keeps its weight in ratio tests
// and rank decisions. Principal pivoting and PGS, whose decisions are signs
// and row-wise updates, test each row against its own scale instead.
//
// Lemke's complementary pivoting with covering vector e = (1,...,1) and
// lexicographic degeneracy resolution (no cycling on degenerate q or ties).
// Returns kRayTermination on a secondary ray.
Result solve_lemke(const MatrixXd& M, const VectorXd& q, const Options& opt = {});

// Principal pivoting for P-matrices, nonsymmetric included: block principal
// pivoting (Júdice–Pires) that falls back to Murty's least-index rule when the
// number of infeasibilities stalls. pivots counts index flips, iterations the
// principal subsystems solved. On a non-P matrix it may fail: it then reports
// kNumericalFailure or kIterationLimit, never a wrong "solved".
Result solve_principal_pivoting(const MatrixXd& M, const VectorXd& q, const Options& opt = {});
// Murty's least-index principal pivoting alone (one flip per pivot): finite on
// every P-matrix, 2^k - 1 pivots in the worst case. Mainly for tests.
Result solve_murty(const MatrixXd& M, const VectorXd& q, const Options& opt = {});

// Projected Gauss–Seidel / SOR with relaxation, tolerance, iteration cap and
// warm start. Converges for symmetric positive (semi)definite M with positive
// diagonal; elsewhere it reports kIterationLimit.
Result solve_pgs(const MatrixXd& M, const VectorXd& q, const Options& opt = {});

// Enumeration of all 2^k complementary bases (k <= 16): the test oracle.
struct EnumerationResult : OutcomeStartingAs<Status::kInvalidInput> {
  std::vector<VectorXd> solutions;  // every distinct solution z found
};
EnumerationResult enumerate_solutions(const MatrixXd& M, const VectorXd& q,
                                      const Options& opt = {});
// The first solution of the enumeration as a Result (kNumericalFailure if none).
Result solve_enumeration(const MatrixXd& M, const VectorXd& q, const Options& opt = {});

// Matrix classes. Tolerances are relative to the matrix scale.
bool is_p_matrix(const MatrixXd& M, double rel_tol = 1e-12);  // all principal minors > 0 (k <= 20)
bool is_positive_definite(const MatrixXd& M,
                          double rel_tol = 1e-12);  // x'Mx > 0, M not nec. symmetric
bool is_positive_semidefinite(const MatrixXd& M, double rel_tol = 1e-12);  // x'Mx >= 0
bool is_symmetric(const MatrixXd& M, double rel_tol = 1e-12);

// Strategy interface: solvers chosen by name ("lemke", "pivot", "pgs", "enum",
// and later back-ends registered by other layers, e.g. Bullet's).
class Solver {
 public:
  virtual ~Solver() = default;
  virtual std::string name() const = 0;
  virtual Result solve(const MatrixXd& M, const VectorXd& q, const Options& opt) const = 0;
};
// The solvers by name: the built-in ones, then the back-ends of components a
// program links (lcsim::bullet adds bullet-dantzig, bullet-lemke, bullet-pgs).
Registry<Solver>& solvers();
// Throws std::invalid_argument naming the unknown solver and the known names.
std::unique_ptr<Solver> make_solver(std::string_view name);
std::vector<std::string> solver_names();

// The LCP solved by `first`, then, while unsolved, by Lemke, PGS and (k <= 12)
// enumeration, each skipped if it is `first`. A result that is not kSolved is
// still accepted when its z passes the acceptance test (scaled_residual <=
// opt.tolerance)
// (Lemke can stop on a ray with a complementary z in hand on a singular M).
// What impacts, mode selection and time steps do when the configured solver
// fails: dependent constraints make their matrices PSD, not P, and principal
// pivoting then stops on a singular block (thesis §4.6.1: the motion is
// still unique). `attempts` counts the solves, `tried` lists the names.
Result solve_with_fallbacks(const Solver& first, const MatrixXd& M, const VectorXd& q,
                            const Options& opt, int* attempts = nullptr,
                            std::string* tried = nullptr);

// solve_with_fallbacks on the diagonally scaled problem
//   (D M D) z' + D q / s,  D = diag(1 / sqrt(M_ii)) (1 where M_ii <= 0),
//   s = max |D q| (1 if 0),  z = s D z',
// (the same detail::Scaling as the solvers' row equilibration, with columns
// scaled too so that a symmetric M stays symmetric and its diagonal becomes
// 1): a step LCP whose matrix is h^2 E M^-1 E' (backward Euler, ~1e-16 at
// h = 1e-8) reaches the solvers with unit diagonal and unit q. The result is
// unscaled (z, w, residuals in the original units) and its status is decided
// by the acceptance test on the original (M, q).
Result solve_scaled(const Solver& first, const MatrixXd& M, const VectorXd& q, const Options& opt,
                    int* attempts = nullptr, std::string* tried = nullptr);

}  // namespace lcsim::lcp
