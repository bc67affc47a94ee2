// Which constraints can be active together, and Theorem 3.6.3 evaluated on
// those index sets only (declarations and the reasoning in mech.hpp).
#include <Eigen/SVD>
#include <algorithm>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/mech/mech.hpp>
#include <map>
#include <set>
#include <string>

namespace lcsim::mech {

namespace {

// Rows of E (dense) and entries of g for the index set J.
MatrixXd rows_of(const MatrixXd& E, const std::vector<int>& J) {
  MatrixXd R(J.size(), E.cols());
  for (size_t i = 0; i < J.size(); ++i) R.row(i) = E.row(J[i]);
  return R;
}
VectorXd entries_of(const VectorXd& g, const std::vector<int>& J) {
  VectorXd r(J.size());
  for (size_t i = 0; i < J.size(); ++i) r(i) = g(J[i]);
  return r;
}

// Feasibility of { q : E_J q + g_J = 0, E_K q + g_K >= 0 } (K = the rest).
// 1. E_J q = -g_J: a least-squares q_p by complete orthogonal decomposition;
//    infeasible when its residual is not zero by gap_is_zero (the
//    integrator's zero test for a gap, mech/tolerances.hpp).
// 2. q = q_p + Z z with Z a basis of Ker E_J: the inequalities A z + b >= 0,
//    A = E_K Z, b = E_K q_p + g_K. A row E_k in the row space of E_J (a
//    corner above a closed one: equal rows of E) has A_k = 0: its gap is the
//    constant b_k on the whole solution set, so it is judged alone (b_k >= 0
//    or zero by gap_is_zero) and kept out of the LCP. Computed, A_k is the
//    SVD's rounding (~eps |E_k|), not zero; handed to Lemke, whose row
//    equilibration scales that row to 1 and its b_k to ~b_k / eps, it swamps
//    the scale of every other basic value and Lemke stopped after 2 pivots on
//    a wrong basis (numerical failure, read as "infeasible").
// 3. The other rows are feasible iff the convex QP min |z|^2/2 s.t.
//    A z + b >= 0 has a solution, iff its KKT LCP 0 <= A A' l + b ⟂ l >= 0 is
//    solvable (z = A' l). A A' is PSD, so Lemke's method either solves it or
//    ends on a ray, which for a PSD (copositive-plus) matrix proves the LCP
//    infeasible (Cottle-Pang-Stone, Thm 4.4.13); any other end (a numerical
//    failure) decides nothing: kUndecided.
enum class Verdict { kFeasible, kInfeasible, kUndecided };

// Whether row `row` of A is zero to the SVD's rounding: |A_k| <= 1e-12
// max(rows, cols) |E_k| (the rank threshold of step 1, relative to the row's
// own size; Z is orthonormal, so |A_k| <= |E_k| always).
bool constant_on_solution_set(const MatrixXd& A, const MatrixXd& EK, Eigen::Index row,
                              double rank_rel) {
  // A with no columns (J fixes every coordinate): each row is empty, so zero;
  // no row view is taken (Eigen's view of an empty matrix offsets a null pointer).
  if (A.cols() == 0) return true;
  return A.row(row).norm() <= rank_rel * EK.row(row).norm();
}

Verdict feasible_exact(const MatrixXd& E, const VectorXd& g, const std::vector<int>& J) {
  const int k = static_cast<int>(E.rows()), N = static_cast<int>(E.cols());
  std::vector<int> K;
  for (int i = 0; i < k; ++i)
    if (!std::binary_search(J.begin(), J.end(), i)) K.push_back(i);
  VectorXd qp = VectorXd::Zero(N);
  MatrixXd Z = MatrixXd::Identity(N, N);
  const double rank_rel = 1e-12 * std::max<double>(static_cast<double>(J.size()), N);
  if (!J.empty()) {
    const MatrixXd EJ = rows_of(E, J);
    const VectorXd gJ = entries_of(g, J);
    Eigen::JacobiSVD<MatrixXd> svd(EJ, Eigen::ComputeFullU | Eigen::ComputeFullV);
    svd.setThreshold(rank_rel);
    qp = svd.solve(-gJ);
    const VectorXd res = EJ * qp + gJ;
    const VectorXd scale = gap_scale(EJ, qp, gJ);
    for (Eigen::Index i = 0; i < res.size(); ++i)
      if (!gap_is_zero(res(i), scale(i))) return Verdict::kInfeasible;
    const int r = static_cast<int>(svd.rank());
    Z = svd.matrixV().rightCols(N - r);
  }
  if (K.empty()) return Verdict::kFeasible;
  const MatrixXd EK = rows_of(E, K);
  const VectorXd gK = entries_of(g, K);
  const MatrixXd A = EK * Z;
  const VectorXd b = EK * qp + gK;
  const VectorXd scale = gap_scale(EK, qp, gK);
  std::vector<int> live;  // rows of A that move on the solution set
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    if (!constant_on_solution_set(A, EK, i, rank_rel))
      live.push_back(static_cast<int>(i));
    else if (b(i) < 0.0 && !gap_is_zero(b(i), scale(i)))
      return Verdict::kInfeasible;
  }
  if (live.empty()) return Verdict::kFeasible;
  const MatrixXd AL = rows_of(A, live);
  const VectorXd bL = entries_of(b, live);
  if (bL.minCoeff() >= 0.0) return Verdict::kFeasible;
  const auto lemke = lcp::make_solver("lemke");
  const lcp::Result sol = lemke->solve(AL * AL.transpose(), bL, lcp::Options{});
  if (sol.ok()) return Verdict::kFeasible;
  return sol.status == lcp::Status::kRayTermination ? Verdict::kInfeasible : Verdict::kUndecided;
}

// At most this many feasibility tests (each a small SVD and LCP, ~0.1 ms at
// N = 20) per enumeration: about 2 s; `complete` is false beyond.
constexpr long kMaxChecks = 20000;

// feasible_exact, counted: beyond `left` checks the enumeration stops
// (answering false, with `exhausted` set) so a model with many rows and
// exponentially many sets cannot hang `analyze`.
struct Checker {
  const MatrixXd& E;
  const VectorXd& g;
  long left;
  bool exhausted = false;
  bool undecided = false;  // some LCP ended neither solved nor on a ray
  bool operator()(const std::vector<int>& J) {
    if (left <= 0) {
      exhausted = true;
      return false;
    }
    --left;
    const Verdict v = feasible_exact(E, g, J);
    if (v == Verdict::kUndecided) undecided = true;
    return v == Verdict::kFeasible;
  }
};

// P-property: for a symmetric matrix, positive definiteness (equivalent, and
// one eigenvalue decomposition instead of 2^k minors); else all minors.
bool p_matrix(const MatrixXd& M) {
  return lcp::is_symmetric(M, 1e-12) ? lcp::is_positive_definite(M) : lcp::is_p_matrix(M);
}

// Bron-Kerbosch with pivoting: the maximal cliques of the graph `adj` among
// the vertices in P (at most `cap`; `complete` false when cut short).
void cliques(const std::vector<std::vector<bool>>& adj, std::vector<int> R, std::vector<int> P,
             std::vector<int> X, std::vector<std::vector<int>>& out, size_t cap, bool& complete) {
  if (out.size() >= cap) {
    complete = false;
    return;
  }
  if (P.empty() && X.empty()) {
    std::sort(R.begin(), R.end());
    out.push_back(R);
    return;
  }
  int pivot = P.empty() ? X.front() : P.front();
  std::vector<int> candidates;
  for (int v : P)
    if (!adj[pivot][v]) candidates.push_back(v);
  for (int v : candidates) {
    std::vector<int> R2 = R, P2, X2;
    R2.push_back(v);
    for (int u : P)
      if (adj[v][u]) P2.push_back(u);
    for (int u : X)
      if (adj[v][u]) X2.push_back(u);
    cliques(adj, R2, P2, X2, out, cap, complete);
    P.erase(std::find(P.begin(), P.end(), v));
    X.push_back(v);
  }
}

// The maximal feasible subsets of a clique that is not feasible as a whole
// (pairwise compatibility does not imply joint): drop one index at a time.
void feasible_subsets(Checker& feasible, const std::vector<int>& C,
                      std::set<std::vector<int>>& seen, std::vector<std::vector<int>>& out,
                      size_t cap) {
  if (!seen.insert(C).second || out.size() >= cap || feasible.exhausted) return;
  if (feasible(C)) {
    out.push_back(C);
    return;
  }
  for (size_t i = 0; i < C.size(); ++i) {
    std::vector<int> D = C;
    D.erase(D.begin() + static_cast<std::ptrdiff_t>(i));
    feasible_subsets(feasible, D, seen, out, cap);
  }
}

bool subset_of(const std::vector<int>& a, const std::vector<int>& b) {
  return std::includes(b.begin(), b.end(), a.begin(), a.end());
}

}  // namespace

bool can_be_active_together(const MechanicalModel& m, std::vector<int> J) {
  std::sort(J.begin(), J.end());
  return feasible_exact(MatrixXd(m.E), m.g, J) == Verdict::kFeasible;
}

CoactiveSets coactive_sets(const MechanicalModel& m, size_t max_sets) {
  CoactiveSets out;
  const int k = m.num_constraints();
  const MatrixXd E(m.E);
  Checker feasible{E, m.g, kMaxChecks};
  std::vector<int> single;
  for (int i = 0; i < k; ++i) {
    if (feasible({i}))
      single.push_back(i);
    else
      out.never_active.push_back(i);
  }
  std::vector<std::vector<bool>> adj(k, std::vector<bool>(k, false));
  for (size_t a = 0; a < single.size(); ++a)
    for (size_t b = a + 1; b < single.size(); ++b) {
      const int i = single[a], j = single[b];
      if (feasible({i, j}))
        adj[i][j] = adj[j][i] = true;
      else
        out.exclusive_pairs.emplace_back(i, j);
    }
  std::vector<std::vector<int>> cl;
  cliques(adj, {}, single, {}, cl, max_sets, out.complete);
  std::set<std::vector<int>> seen;
  std::vector<std::vector<int>> sets;
  for (const auto& C : cl) feasible_subsets(feasible, C, seen, sets, max_sets);
  if (sets.size() >= max_sets || feasible.exhausted || feasible.undecided) out.complete = false;
  // Keep the maximal ones (a dropped-index subset may lie in another clique).
  for (const auto& S : sets) {
    const bool dominated = std::any_of(sets.begin(), sets.end(), [&](const auto& T) {
      return T.size() > S.size() && subset_of(S, T);
    });
    if (!dominated && std::find(out.maximal.begin(), out.maximal.end(), S) == out.maximal.end())
      out.maximal.push_back(S);
  }
  std::sort(out.maximal.begin(), out.maximal.end());
  return out;
}

namespace {

// Sub-matrix (J, J).
MatrixXd principal(const MatrixXd& X, const std::vector<int>& J) {
  const auto n = static_cast<Eigen::Index>(J.size());
  MatrixXd S(n, n);
  for (Eigen::Index a = 0; a < n; ++a)
    for (Eigen::Index b = 0; b < n; ++b) S(a, b) = X(J[a], J[b]);
  return S;
}

// The leading row (or column) coefficient matrix (3.39) of the LCS restricted
// to J. Row i's leading index in the restricted system is never below the
// full one's (lower Markov parameters vanish on every column) and equals it
// when the full coefficient matrix has X(i, i) != 0; then the restricted
// matrix is the principal submatrix X(J, J). Otherwise it is computed.
MatrixXd restricted_coefficients(const lcs::Lcs& sys, const MatrixXd& X, const std::vector<int>& J,
                                 bool rows) {
  if (std::all_of(J.begin(), J.end(), [&](int i) { return X(i, i) != 0.0; }))
    return principal(X, J);
  const auto n = static_cast<Eigen::Index>(J.size());
  lcs::Lcs sub;
  sub.A = sys.A;
  sub.B.resize(sys.n(), n);
  sub.C.resize(n, sys.n());
  for (Eigen::Index a = 0; a < n; ++a) {
    sub.B.col(a) = sys.B.col(J[a]);
    sub.C.row(a) = sys.C.row(J[a]);
  }
  sub.D = principal(sys.D, J);
  const std::vector<int> idx =
      rows ? lcs::leading_row_indices(sub) : lcs::leading_column_indices(sub);
  if (std::any_of(idx.begin(), idx.end(), [](int i) { return i == lcs::kInfiniteIndex; }))
    return MatrixXd::Zero(n, n);  // a zero row: not a P-matrix
  return rows ? lcs::leading_row_coefficients(sub) : lcs::leading_column_coefficients(sub);
}

}  // namespace

CoactiveWellPosedness coactive_well_posedness(const MechanicalModel& m, const CoactiveSets& s) {
  CoactiveWellPosedness out;
  const lcs::Lcs sys = to_lcs(m);
  const MatrixXd W = delassus(m);
  const MatrixXd E(m.E);
  // Infinite indices leave zero rows (columns): X(i, i) = 0 sends those sets
  // to the restricted computation.
  const MatrixXd R = lcs::leading_row_coefficients(sys);
  const MatrixXd Cc = lcs::leading_column_coefficients(sys);
  for (const auto& J : s.maximal) {
    CoactiveWellPosedness::Set r;
    r.indices = J;
    const bool empty = J.empty();
    r.rank = empty ? 0 : lcs::numerical_rank(rows_of(E, J));
    r.delassus_p_matrix = empty || p_matrix(principal(W, J));
    r.row_p_matrix = empty || p_matrix(restricted_coefficients(sys, R, J, true));
    r.column_p_matrix = empty || p_matrix(restricted_coefficients(sys, Cc, J, false));
    out.sets.push_back(std::move(r));
  }
  out.all_delassus_p = std::all_of(out.sets.begin(), out.sets.end(),
                                   [](const auto& r) { return r.delassus_p_matrix; });
  out.locally_well_posed =
      s.complete && std::all_of(out.sets.begin(), out.sets.end(),
                                [](const auto& r) { return r.row_p_matrix && r.column_p_matrix; });
  out.dependent = std::any_of(out.sets.begin(), out.sets.end(), [](const auto& r) {
    return r.rank < static_cast<int>(r.indices.size());
  });
  return out;
}

std::vector<std::string> coactive_not_judged(const MechanicalModel& m, const CoactiveSets* sets,
                                             int rank_E) {
  const int k = m.num_constraints();
  const std::string rank = "rank E = " + std::to_string(rank_E) + " < k = " + std::to_string(k);
  std::vector<std::string> out;
  if (!sets) {
    if (k == 0) return out;
    out.push_back("the sets of constraints that can be active together were not enumerated (k = " +
                  std::to_string(k) + " > " + std::to_string(kMaxCoactiveConstraints) +
                  "): Theorem 3.6.3 and the Delassus P-property are judged on all k rows at "
                  "once only, which asks more than an admissible state reaches (e.g. both "
                  "limits of a joint closed), not on the sets an admissible state can reach");
    if (rank_E < k)
      out.push_back(rank +
                    " was not explained: dependent constraints (§4.6.1) and rows that "
                    "merely cannot be active together (the two limits of a joint) were "
                    "not told apart");
    return out;
  }
  if (sets->complete) return out;
  out.push_back("the enumeration of the sets that can be active together was cut short after " +
                std::to_string(sets->maximal.size()) +
                " maximal sets: the sets not enumerated were not judged (Theorem 3.6.3, the "
                "Delassus P-property, dependent rows)");
  return out;
}

}  // namespace lcsim::mech
