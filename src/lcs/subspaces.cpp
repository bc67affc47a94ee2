// Consistent subspace V_I (3.4), jump space T_I (3.7), projection P_I onto V_I
// along T_I (§3.3, §3.4.2), mode feedback F_I (§3.4.1) and the regular-state
// test (3.40).
//
// Numerics. Every subspace is an orthonormal basis obtained from an SVD whose
// rank decision uses rank_tolerance() with an a-priori scale: the largest
// singular value of the (balanced) data [A B_.I; C_I. D_II], never the
// computed product itself, so that a product that is zero in exact arithmetic
// but 1e-17 in floating point is not mistaken for a direction. Before the
// recursions the mode quadruple is balanced by transformations that leave V
// and T unchanged exactly (time scaling of (A, B), scaling of each output row,
// scaling of each input column), so rank decisions do not depend on units.
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <lcsim/lcs/lcs.hpp>
#include <sstream>
#include <stdexcept>

namespace lcsim::lcs {

namespace {

void check_system(const Lcs& sys) {
  const int n = sys.n(), k = sys.k();
  if (sys.A.cols() != n || sys.B.rows() != n || sys.C.rows() != k || sys.C.cols() != n ||
      sys.D.rows() != k || sys.D.cols() != k) {
    std::ostringstream os;
    os << "Lcs dimensions disagree: A " << sys.A.rows() << "x" << sys.A.cols() << ", B "
       << sys.B.rows() << "x" << sys.B.cols() << ", C " << sys.C.rows() << "x" << sys.C.cols()
       << ", D " << sys.D.rows() << "x" << sys.D.cols();
    throw std::invalid_argument(os.str());
  }
}

void check_index_set(const Lcs& sys, const IndexSet& I) {
  for (std::size_t a = 0; a < I.size(); ++a) {
    if (I[a] < 0 || I[a] >= sys.k()) {
      std::ostringstream os;
      os << "index set: constraint index " << I[a] << " out of range [0, " << sys.k() << ")";
      throw std::invalid_argument(os.str());
    }
    if (a > 0 && I[a] <= I[a - 1])
      throw std::invalid_argument("index set: indices must be sorted and distinct");
  }
}

// (K, L, M, N) = (A, B_.I, C_I., D_II) of (3.15).
struct Quadruple {
  MatrixXd K, L, M, N;
};

Quadruple mode_quadruple(const Lcs& sys, const IndexSet& I) {
  check_system(sys);
  check_index_set(sys, I);
  const int m = static_cast<int>(I.size());
  Quadruple q;
  q.K = sys.A;
  q.L.resize(sys.n(), m);
  q.M.resize(m, sys.n());
  q.N.resize(m, m);
  for (int a = 0; a < m; ++a) {
    q.L.col(a) = sys.B.col(I[a]);
    q.M.row(a) = sys.C.row(I[a]);
    for (int b = 0; b < m; ++b) q.N(a, b) = sys.D(I[a], I[b]);
  }
  return q;
}

// Exact equivalences of the quadruple that leave V and T unchanged:
// (K, L) -> (K, L) / alpha (time scaling; (3.4) and (3.7) only see images),
// row i of [M N] -> row / ||row|| (output scaling y_i -> y_i / c_i),
// column j of [L; N] -> column / ||column|| (input scaling u_j -> c_j u_j).
// Zero rows/columns are left alone: they are data, not rounding.
Quadruple balanced(Quadruple q) {
  double alpha = q.K.norm();
  if (alpha == 0.0) alpha = q.L.norm();
  if (alpha > 0.0) {
    q.K /= alpha;
    q.L /= alpha;
  }
  for (int i = 0; i < q.M.rows(); ++i) {
    const double r = std::sqrt(q.M.row(i).squaredNorm() + q.N.row(i).squaredNorm());
    if (r > 0.0) {
      q.M.row(i) /= r;
      q.N.row(i) /= r;
    }
  }
  for (int j = 0; j < q.L.cols(); ++j) {
    const double c = std::sqrt(q.L.col(j).squaredNorm() + q.N.col(j).squaredNorm());
    if (c > 0.0) {
      q.L.col(j) /= c;
      q.N.col(j) /= c;
    }
  }
  return q;
}

// The a-priori tolerance for all rank decisions on products of the balanced
// data: rank_tolerance of the stacked [K L; M N] (its largest singular value
// bounds every product with orthonormal factors formed below).
double data_tolerance(const Quadruple& q) {
  const int n = static_cast<int>(q.K.rows()), m = static_cast<int>(q.L.cols());
  MatrixXd S(n + m, n + m);
  S << q.K, q.L, q.M, q.N;
  return rank_tolerance(S);
}

// Orthonormal basis of Im X: left singular vectors with sigma > tol.
MatrixXd orth(const MatrixXd& X, double tol) {
  if (X.cols() == 0 || X.rows() == 0) return MatrixXd(X.rows(), 0);
  Eigen::JacobiSVD<MatrixXd> svd(X, Eigen::ComputeThinU);
  int r = 0;
  while (r < svd.singularValues().size() && svd.singularValues()(r) > tol) ++r;
  return svd.matrixU().leftCols(r);
}

// Orthonormal basis of Ker X: right singular vectors with sigma <= tol.
MatrixXd kernel(const MatrixXd& X, double tol) {
  const int c = static_cast<int>(X.cols());
  if (X.rows() == 0 || c == 0) return MatrixXd::Identity(c, c);
  Eigen::JacobiSVD<MatrixXd> svd(X, Eigen::ComputeFullV);
  int r = 0;
  while (r < svd.singularValues().size() && svd.singularValues()(r) > tol) ++r;
  return svd.matrixV().rightCols(c - r);
}

// Orthonormal basis of the orthogonal complement of Im V (V orthonormal).
MatrixXd complement(const MatrixXd& V) {
  const int n = static_cast<int>(V.rows()), d = static_cast<int>(V.cols());
  if (d == 0) return MatrixXd::Identity(n, n);
  Eigen::HouseholderQR<MatrixXd> qr(V);
  const MatrixXd Q = qr.householderQ() * MatrixXd::Identity(n, n);
  return Q.rightCols(n - d);
}

// Tolerance for the x-part of an orthonormal kernel basis: its singular values
// lie in [0, 1], so the scale is 1; 1e-12 as in rank_tolerance.
double unit_tolerance(const MatrixXd& X) {
  return static_cast<double>(std::max(X.rows(), X.cols())) * 1e-12;
}

MatrixXd consistent_basis(const Quadruple& q) {
  const int n = static_cast<int>(q.K.rows()), m = static_cast<int>(q.L.cols());
  const double tol = data_tolerance(q);
  MatrixXd V = MatrixXd::Identity(n, n);  // V_0 = R^n
  // V_{i+1} = {x | exists u: Kx + Lu in V_i, Mx + Nu = 0} is the x-projection
  // of Ker [Q'K Q'L; M N] with Q an orthonormal basis of V_i^perp. The
  // sequence is nonincreasing, so equal dimensions mean convergence (<= n steps).
  for (int it = 0; it <= n; ++it) {
    const MatrixXd Q = complement(V);
    MatrixXd S(Q.cols() + m, n + m);
    S << Q.transpose() * q.K, Q.transpose() * q.L, q.M, q.N;
    const MatrixXd Z = kernel(S, tol);
    const MatrixXd X = Z.topRows(n);
    MatrixXd Vnext = orth(X, unit_tolerance(X));
    const bool done = Vnext.cols() == V.cols();
    V = std::move(Vnext);
    if (done) break;
  }
  return V;
}

MatrixXd jump_basis(const Quadruple& q) {
  const int n = static_cast<int>(q.K.rows()), m = static_cast<int>(q.L.cols());
  const double tol = data_tolerance(q);
  MatrixXd W(n, 0);  // T_0 = {0}
  // T_{i+1} = {K xb + L u | xb in T_i, M xb + N u = 0} = [K W, L] Ker [M W, N].
  // The sequence is nondecreasing, so equal dimensions mean convergence.
  for (int it = 0; it <= n; ++it) {
    MatrixXd S(m, W.cols() + m);
    S << q.M * W, q.N;
    const MatrixXd Z = kernel(S, tol);
    MatrixXd G(n, W.cols() + m);
    G << q.K * W, q.L;
    MatrixXd Wnext = orth(G * Z, tol);
    const bool done = Wnext.cols() == W.cols();
    W = std::move(Wnext);
    if (done) break;
  }
  return W;
}

std::string set_to_string(const IndexSet& I) {
  std::ostringstream os;
  os << "{";
  for (std::size_t a = 0; a < I.size(); ++a) os << (a ? "," : "") << I[a];
  os << "}";
  return os.str();
}

}  // namespace

ConsistentSubspace consistent_subspace(const Lcs& sys, const IndexSet& I) {
  return {consistent_basis(balanced(mode_quadruple(sys, I)))};
}

JumpSpace jump_space(const Lcs& sys, const IndexSet& I) {
  return {jump_basis(balanced(mode_quadruple(sys, I)))};
}

Projection projection(const Lcs& sys, const IndexSet& I) {
  const Quadruple q = balanced(mode_quadruple(sys, I));
  const int n = sys.n(), m = static_cast<int>(I.size());
  const MatrixXd V = consistent_basis(q);
  const MatrixXd T = jump_basis(q);
  Projection out;
  std::ostringstream why;
  const std::string name = "mode " + set_to_string(I);

  // Lemma 3.3.3 (3): autonomous iff V ⊕ T = R^n and Ker [L; N] = {0}.
  MatrixXd LN(n + m, m);
  if (m > 0) LN << q.L, q.N;  // m = 0: no data (a comma initialiser would offset a null pointer)
  const int ker_dim = static_cast<int>(kernel(LN, data_tolerance(q)).cols());

  bool direct_sum = V.cols() + T.cols() == n;
  if (!direct_sum) {
    why << name << " is not autonomous: dim V_I + dim T_I = " << V.cols() << " + " << T.cols()
        << " != n = " << n << " (V_I ⊕ T_I != R^n, Lemma 3.3.3)";
  } else if (n > 0) {
    MatrixXd S(n, n);
    S << V, T;
    Eigen::JacobiSVD<MatrixXd> svd(S);
    // [V T] has orthonormal blocks, sigma_max in [1, sqrt 2]; sigma_min is the
    // sine-like gap between V_I and T_I. Zero by rank_tolerance means they meet.
    if (svd.singularValues()(n - 1) <= rank_tolerance(S)) {
      direct_sum = false;
      why << name << " is not autonomous: V_I ∩ T_I != {0} (Lemma 3.3.3)";
    } else {
      const MatrixXd Sinv = S.colPivHouseholderQr().solve(MatrixXd::Identity(n, n));
      out.P = V * Sinv.topRows(V.cols());  // P = [V 0] [V T]^{-1}
    }
  } else {
    out.P = MatrixXd(0, 0);
  }
  if (ker_dim > 0) {
    if (!why.str().empty()) why << "; ";
    why << name << " is not autonomous: Ker [B_.I; D_II] has dimension " << ker_dim
        << " (some inputs of the mode act on neither x nor y, Lemma 3.3.3)";
  }
  out.status = (direct_sum && ker_dim == 0) ? Status::kOk : Status::kNumericalFailure;
  out.message = why.str();
  return out;
}

namespace {

// A singular script M_II (rows scaled to unit max-norm) whose rows are
// dependent: a combination w' (R x + M_II u) = w' R x of the mode's
// relations y_i^(rho_i) = 0 holds no input, so w' R x vanishes identically on
// the phase and so does its derivative w' R A x + w' R B_.I u (the u' it
// would carry is w' M_II u' = 0). That derivative replaces the row of
// largest |w_j| (the others and w' R x = 0 imply it back); repeated until
// M_II is regular (Silverman's structure algorithm, as §3.3's V_I recursion
// differentiates outputs). An ideal bridge's tank meeting a loaded capacitor
// through two diodes (C1 || C2: y_D2 + y_D3 = v + w has no feedthrough)
// needs one round. True when M_II became regular; false when a combination
// vanishes in x too (a redundant output) or the rounds run out.
bool differentiate_dependent_rows(const MatrixXd& A, const MatrixXd& BI, MatrixXd& R,
                                  MatrixXd& Mc) {
  const Eigen::Index m = Mc.rows();
  for (Eigen::Index round = 0; round < m * (A.rows() + 1); ++round) {
    const Eigen::JacobiSVD<MatrixXd> svd(Mc, Eigen::ComputeFullU);
    if (svd.singularValues()(m - 1) > rank_tolerance(Mc)) return true;
    const VectorXd w = svd.matrixU().col(m - 1);
    Eigen::Index j = 0;
    w.cwiseAbs().maxCoeff(&j);
    const Eigen::RowVectorXd r = w.transpose() * R;
    const double terms = (w.cwiseAbs().transpose() * R.cwiseAbs()).maxCoeff();
    if (r.cwiseAbs().maxCoeff() <= 1e-12 * terms) return false;  // vanishes in x too
    R.row(j) = r * A;
    Mc.row(j) = r * BI;
    const double s = Mc.row(j).cwiseAbs().maxCoeff() > 0.0 ? Mc.row(j).cwiseAbs().maxCoeff()
                                                           : R.row(j).cwiseAbs().maxCoeff();
    if (s == 0.0) return false;
    R.row(j) /= s;
    Mc.row(j) /= s;
  }
  return false;
}

}  // namespace

ModeFeedback mode_feedback(const Lcs& sys, const IndexSet& I) {
  const Quadruple q = mode_quadruple(sys, I);
  const int n = sys.n(), m = static_cast<int>(I.size());
  ModeFeedback out;
  out.F = MatrixXd::Zero(m, n);
  if (m == 0) {
    out.status = Status::kOk;
    return out;
  }
  // Leading rows of the mode's own system (A, B_.I, C_I., D_II): these equal
  // the full system's rho_i and script M_{iI} whenever H^{rho_i}_{iI} != 0,
  // and are the right ones otherwise (u_{I^c} = 0 in mode I).
  const Lcs sub{q.K, q.L, q.M, q.N};
  const std::vector<int> rho = leading_row_indices(sub);
  MatrixXd Mc = leading_row_coefficients(sub);
  MatrixXd R(m, n);  // rows C_i A^{rho_i}
  for (int a = 0; a < m; ++a) {
    if (rho[a] == kInfiniteIndex) {
      out.message = "mode " + set_to_string(I) + ": constraint " + std::to_string(I[a]) +
                    " has no leading row index (its row of H^0..H^n vanishes), so the mode is "
                    "not autonomous (Lemma 3.6.5)";
      return out;
    }
    Eigen::RowVectorXd r = q.M.row(a);
    for (int p = 0; p < rho[a]; ++p) r = r * q.K;
    R.row(a) = r;
  }
  // Scale each row to unit max-norm: y_i^(rho_i) has its own units, and a row
  // scaling changes neither the solution F nor the singularity of script M_II.
  for (int a = 0; a < m; ++a) {
    const double s = Mc.row(a).cwiseAbs().maxCoeff();  // > 0 by definition of rho
    Mc.row(a) /= s;
    R.row(a) /= s;
  }
  Eigen::JacobiSVD<MatrixXd> svd(Mc);
  if (svd.singularValues()(m - 1) <= rank_tolerance(Mc) &&
      !differentiate_dependent_rows(q.K, q.L, R, Mc)) {
    std::ostringstream os;
    os << "mode " << set_to_string(I)
       << ": leading row coefficient matrix script M_II is singular (sigma_min/sigma_max = "
       << svd.singularValues()(m - 1) / svd.singularValues()(0)
       << "), F_I cannot be built from leading rows";
    out.message = os.str();
    return out;
  }
  out.F = -Mc.colPivHouseholderQr().solve(R);
  out.status = Status::kOk;
  return out;
}

bool is_regular_state(const Lcs& sys, const VectorXd& x, double tol) {
  check_system(sys);
  if (x.size() != sys.n())
    throw std::invalid_argument("is_regular_state: state has size " + std::to_string(x.size()) +
                                ", expected " + std::to_string(sys.n()));
  const std::vector<int> rho = leading_row_indices(sys);
  // C_i A^j x counts as zero below tol * || |C_i| |A|^j ||_1 * ||x||_inf:
  // the rounding of the state's entries (relative to its size) carried
  // through the magnitudes of the row's terms. |A|^j, not ||A||^j: a stiff
  // spring elsewhere in A does not inflate the bound of a row it is not on.
  const MatrixXd A_abs = sys.A.cwiseAbs();
  const double x_norm = x.size() > 0 ? x.cwiseAbs().maxCoeff() : 0.0;
  for (int i = 0; i < sys.k(); ++i) {
    // With an infinite index y_i = C_i e^{At} x does not depend on u; by
    // Cayley–Hamilton its first n derivatives decide its sign near 0+.
    const int count = rho[i] == kInfiniteIndex ? sys.n() : rho[i];
    Eigen::RowVectorXd r = sys.C.row(i);
    Eigen::RowVectorXd r_abs = r.cwiseAbs();
    for (int j = 0; j < count; ++j) {
      const double v = r.dot(x);
      if (std::abs(v) > tol * r_abs.sum() * x_norm) {
        if (v < 0.0) return false;
        break;  // lexicographically positive
      }
      r = r * sys.A;
      r_abs = r_abs * A_abs;
    }
  }
  return true;
}

}  // namespace lcsim::lcs
