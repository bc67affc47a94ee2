// The well-posedness report: Markov parameters (3.32), leading indices and
// coefficient matrices (3.39), the P-matrix conditions of Theorem 3.6.3, the
// backward Euler guard of Example 7.3.3 and passivity checks (§7.2, Lemma
// 7.2.8). What is checked for passivity is documented in lcs.hpp.
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <lcsim/lcs/lcs.hpp>
#include <sstream>

namespace lcsim::lcs {

namespace {

double spectral_norm(const MatrixXd& X) {
  if (X.size() == 0) return 0.0;
  return Eigen::JacobiSVD<MatrixXd>(X).singularValues()(0);
}

struct Verdict {
  bool failed = false;
  std::string reason;
};

// N1: D + D' >= 0. Eigenvalues of the symmetric part are accurate to
// ~eps ||D||; 1e-12 ||D|| leaves room for rounding in the data.
Verdict check_feedthrough(const Lcs& sys) {
  Verdict v;
  if (sys.k() == 0) return v;
  const MatrixXd S = sys.D + sys.D.transpose();
  const double lmin = Eigen::SelfAdjointEigenSolver<MatrixXd>(S).eigenvalues()(0);
  if (lmin < -1e-12 * std::max(spectral_norm(S), spectral_norm(sys.D))) {
    std::ostringstream os;
    os << "not passive: D + D' has eigenvalue " << lmin
       << " < 0 (necessary: D + D' >= 0; D is "
          "the LCS's feedthrough in y = C x + D u, not a mechanical damping)";
    v.failed = true;
    v.reason = os.str();
  }
  return v;
}

// N2: on Z = Ker(D + D'), Z'CBZ symmetric PSD with Ker(Z'CBZ) = Ker(BZ).
Verdict check_first_markov(const Lcs& sys) {
  Verdict v;
  const int k = sys.k();
  if (k == 0 || sys.n() == 0) return v;
  const MatrixXd S = sys.D + sys.D.transpose();
  MatrixXd Z;
  {
    Eigen::JacobiSVD<MatrixXd> svd(S, Eigen::ComputeFullV);
    const double tol = rank_tolerance(S);
    int r = 0;
    while (r < k && svd.singularValues()(r) > tol) ++r;
    Z = svd.matrixV().rightCols(k - r);
  }
  if (Z.cols() == 0) return v;
  const MatrixXd H1 = Z.transpose() * sys.C * sys.B * Z;
  const MatrixXd BZ = sys.B * Z;
  // Entries of CB are sums of products bounded by ||C|| ||B||; 1e-10 of that
  // is far above rounding (~1e-16) and far below any physical asymmetry.
  const double scale = spectral_norm(sys.C) * spectral_norm(sys.B);
  const double tol = 1e-10 * std::max(scale, 1e-300);
  std::ostringstream os;
  if ((H1 - H1.transpose()).cwiseAbs().maxCoeff() > tol) {
    os << "not passive: on Ker(D + D') (D the LCS's feedthrough in y = C x + D u) the first "
          "Markov parameter CB is not symmetric (necessary: KB = C' there, so CB = B'KB)";
    v.failed = true;
  } else {
    const MatrixXd Hs = 0.5 * (H1 + H1.transpose());
    Eigen::SelfAdjointEigenSolver<MatrixXd> es(Hs, Eigen::ComputeEigenvectors);
    if (es.eigenvalues()(0) < -tol) {
      os << "not passive: on Ker(D + D') (D the LCS's feedthrough in y = C x + D u) the first "
            "Markov parameter CB has eigenvalue "
         << es.eigenvalues()(0) << " < 0 (necessary: CB = B'KB >= 0 there)";
      v.failed = true;
    } else {
      // Directions w with w'(CB)w ~ 0 must satisfy B Z w = 0 (K > 0).
      const double bscale = std::max(spectral_norm(sys.B), 1e-300);
      for (int i = 0; i < es.eigenvalues().size(); ++i) {
        if (es.eigenvalues()(i) > tol) break;
        const double bw = (BZ * es.eigenvectors().col(i)).norm();
        if (bw > 1e-8 * bscale) {
          os << "not passive: the feedthrough D + D' (y = C x + D u) is singular and CB "
                "vanishes on an input direction w "
                "with B w != 0 (necessary: KB = C' there, so w'CBw = |K^{1/2} B w|^2 > 0); "
                "e.g. relative degree >= 2 such as a position output";
          v.failed = true;
          break;
        }
      }
    }
  }
  v.reason = os.str();
  return v;
}

// N3: G(l) + G(l)^* >= 0 for Re l >= 0, l not an eigenvalue of A.
Verdict check_frequency(const Lcs& sys, int* points_checked) {
  Verdict v;
  *points_checked = 0;
  const int n = sys.n(), k = sys.k();
  if (k == 0 || n == 0) return v;
  using Eigen::MatrixXcd;
  using cd = std::complex<double>;
  const double a = std::max(spectral_norm(sys.A), 1.0);
  const MatrixXcd Ac = sys.A.cast<cd>(), Bc = sys.B.cast<cd>(), Cc = sys.C.cast<cd>(),
                  Dc = sys.D.cast<cd>();
  const double normC = spectral_norm(sys.C), normD = spectral_norm(sys.D);
  const double pi = std::acos(-1.0);
  const int per_decade = 20;
  for (double deg : {90.0, 60.0, 30.0, 0.0}) {
    for (int p = -4 * per_decade; p <= 4 * per_decade; ++p) {
      const double r = a * std::pow(10.0, static_cast<double>(p) / per_decade);
      const double th = deg * pi / 180.0;
      const cd l(deg == 90.0 ? 0.0 : r * std::cos(th), r * std::sin(th));
      const MatrixXcd R = l * MatrixXcd::Identity(n, n) - Ac;
      Eigen::PartialPivLU<MatrixXcd> lu(R);
      // Near an eigenvalue of A, G is inaccurate: skip points with
      // rcond < 1e-8, so the relative error of X is <~ n eps / rcond < 1e-6.
      if (!(lu.rcond() >= 1e-8)) continue;
      const MatrixXcd X = lu.solve(Bc);
      const MatrixXcd G = Cc * X + Dc;
      const MatrixXcd H = G + G.adjoint();
      const double lmin = Eigen::SelfAdjointEigenSolver<MatrixXcd>(H).eigenvalues()(0);
      ++*points_checked;
      // The terms of G are bounded by ||C|| ||X|| + ||D||; with the 1e-6
      // relative accuracy above, -1e-5 of that scale is a real violation.
      const double scale = normC * X.norm() + normD;
      if (lmin < -1e-5 * scale) {
        std::ostringstream os;
        os << "not passive: G(l) + G(l)^* has eigenvalue " << lmin << " < 0 at l = " << l.real()
           << (l.imag() >= 0 ? "+" : "") << l.imag()
           << "i (necessary: G positive real on Re l >= 0)";
        v.failed = true;
        v.reason = os.str();
        return v;
      }
    }
  }
  return v;
}

}  // namespace

PassivityCertificateCheck verify_passivity_certificate(const Lcs& sys, const MatrixXd& K) {
  PassivityCertificateCheck out;
  const int n = sys.n(), k = sys.k();
  if (K.rows() != n || K.cols() != n) {
    out.message = "certificate K has size " + std::to_string(K.rows()) + "x" +
                  std::to_string(K.cols()) + ", expected " + std::to_string(n) + "x" +
                  std::to_string(n);
    return out;
  }
  const double nk = spectral_norm(K);
  const double scale = nk * (spectral_norm(sys.A) + spectral_norm(sys.B)) + spectral_norm(sys.C) +
                       spectral_norm(sys.D);
  // 1e-10: the entries of L(K) are sums of products of data of size `scale`;
  // rounding is ~1e-16 of it, and a certificate typed from physical constants
  // (e.g. blockdiag(stiffness, mass)) is exact to ~1e-15.
  const double tol = 1e-10 * std::max(scale, 1e-300);
  std::ostringstream os;
  if (n > 0 && (K - K.transpose()).cwiseAbs().maxCoeff() > 1e-12 * std::max(nk, 1e-300)) {
    os << "K is not symmetric";
    out.message = os.str();
    return out;
  }
  const MatrixXd Ks = 0.5 * (K + K.transpose());
  out.k_min_eigenvalue = n > 0 ? Eigen::SelfAdjointEigenSolver<MatrixXd>(Ks).eigenvalues()(0) : 1.0;
  MatrixXd L(n + k, n + k);
  L << sys.A.transpose() * Ks + Ks * sys.A, Ks * sys.B - sys.C.transpose(),
      sys.B.transpose() * Ks - sys.C, -(sys.D + sys.D.transpose());
  out.lmi_max_eigenvalue =
      n + k > 0 ? Eigen::SelfAdjointEigenSolver<MatrixXd>(L).eigenvalues()(n + k - 1) : 0.0;
  // K > 0 relative to its own size (1e-10: a genuinely definite K from
  // physical data has condition number far below 1e10).
  if (n > 0 && !(out.k_min_eigenvalue > 1e-10 * nk)) {
    os << "K is not positive definite (smallest eigenvalue " << out.k_min_eigenvalue << ")";
  } else if (out.lmi_max_eigenvalue > tol) {
    os << "[A'K+KA, KB-C'; B'K-C, -(D+D')] has eigenvalue " << out.lmi_max_eigenvalue << " > 0";
  } else {
    out.status = Status::kOk;
  }
  out.message = os.str();
  return out;
}

WellPosednessReport analyze_well_posedness(const Lcs& sys) {
  WellPosednessReport r;
  r.n = sys.n();
  r.k = sys.k();
  r.markov = markov_parameters(sys, r.n + 1);
  r.rho = leading_row_indices(sys);
  r.eta = leading_column_indices(sys);
  r.row_coefficients = leading_row_coefficients(sys);
  r.column_coefficients = leading_column_coefficients(sys);

  const auto all_finite = [](const std::vector<int>& idx) {
    return std::none_of(idx.begin(), idx.end(), [](int i) { return i == kInfiniteIndex; });
  };
  // An infinite index leaves a zero row/column in the coefficient matrix, so
  // it is not a P-matrix; the empty matrix (k = 0) is one vacuously.
  r.row_p_matrix = r.k == 0 || (all_finite(r.rho) && lcp::is_p_matrix(r.row_coefficients));
  r.column_p_matrix = r.k == 0 || (all_finite(r.eta) && lcp::is_p_matrix(r.column_coefficients));
  r.locally_well_posed = r.row_p_matrix && r.column_p_matrix;  // Theorem 3.6.3
  r.backward_euler_risky = std::any_of(r.rho.begin(), r.rho.end(), [](int i) {
    return i != kInfiniteIndex && i >= 3;  // Example 7.3.3
  });

  // Passivity, in the order documented in lcs.hpp.
  std::vector<std::string> passed;
  for (const Verdict& v : {check_feedthrough(sys), check_first_markov(sys)}) {
    if (v.failed) {
      r.passive = "no";
      r.passivity_reason = v.reason;
      return r;
    }
  }
  passed.push_back("feedthrough D + D' >= 0 (D of y = C x + D u, not a mechanical damping)");
  passed.push_back("CB symmetric PSD on Ker(D + D') with Ker = Ker(B)");
  int points = 0;
  const Verdict f = check_frequency(sys, &points);
  if (f.failed) {
    r.passive = "no";
    r.passivity_reason = f.reason;
    return r;
  }
  passed.push_back("G + G^* >= 0 at " + std::to_string(points) + " points with Re l >= 0");

  const auto cert = verify_passivity_certificate(sys, MatrixXd::Identity(r.n, r.n));
  if (cert.ok()) {
    r.passive = "yes";
    r.passivity_reason =
        "certificate K = I: [A'+A, B-C'; B'-C, -(D+D')] <= 0 holds (largest eigenvalue " +
        std::to_string(cert.lmi_max_eigenvalue) + ")";
    return r;
  }
  r.passive = "unknown";
  std::string s = "necessary conditions hold (";
  for (std::size_t i = 0; i < passed.size(); ++i) s += (i ? "; " : "") + passed[i];
  s += "), but no certificate was found (K = I fails: " + cert.message +
       "); a caller that knows the structure (e.g. blockdiag(stiffness, mass) for a "
       "velocity-output mechanical model) can check one with verify_passivity_certificate";
  r.passivity_reason = s;
  return r;
}

std::vector<std::string> summary_left_out(const WellPosednessReport& r) {
  std::vector<std::string> out;
  Eigen::Index markov = 0;
  for (const auto& H : r.markov) markov += H.size();
  if (!summary_shows(markov)) out.push_back("markov");
  if (!summary_shows(r.row_coefficients.size())) out.push_back("row_coefficients");
  if (!summary_shows(r.column_coefficients.size())) out.push_back("column_coefficients");
  return out;
}

}  // namespace lcsim::lcs
