// Which constraints can be active together, and Theorem 3.6.3 evaluated on
// those index sets only (declarations and the reasoning in mech.hpp).
#include <Eigen/SVD>
#include <algorithm>
#include <map>
#include <set>

#include "lcp/lcp.hpp"
#include "mech/mech.hpp"

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
//    infeasible when its residual exceeds 1e-9 (|E_J||q_p| + |g_J|) (the
//    integrator's zero test for a gap, with room for the SVD's rounding).
// 2. q = q_p + Z z with Z a basis of Ker E_J: the inequalities A z + b >= 0,
//    A = E_K Z, b = E_K q_p + g_K, are feasible iff the convex QP
//    min |z|^2/2 s.t. A z + b >= 0 has a solution, iff its KKT LCP
//    0 <= A A' l + b ⟂ l >= 0 is solvable (z = A' l). A A' is PSD, so Lemke's
//    method either solves it or ends on a ray, which for a PSD (copositive-
//    plus) matrix proves the LCP infeasible (Cottle-Pang-Stone, Thm 4.4.13).
bool feasible(const MatrixXd& E, const VectorXd& g, const std::vector<int>& J) {
  const int k = static_cast<int>(E.rows()), N = static_cast<int>(E.cols());
  std::vector<int> K;
  for (int i = 0; i < k; ++i)
    if (!std::binary_search(J.begin(), J.end(), i)) K.push_back(i);
  VectorXd qp = VectorXd::Zero(N);
  MatrixXd Z = MatrixXd::Identity(N, N);
  if (!J.empty()) {
    const MatrixXd EJ = rows_of(E, J);
    const VectorXd gJ = entries_of(g, J);
    Eigen::JacobiSVD<MatrixXd> svd(EJ, Eigen::ComputeFullU | Eigen::ComputeFullV);
    svd.setThreshold(1e-12 * std::max<double>(EJ.rows(), EJ.cols()));
    qp = svd.solve(-gJ);
    const VectorXd res = EJ * qp + gJ;
    const VectorXd scale = EJ.cwiseAbs() * qp.cwiseAbs() + gJ.cwiseAbs();
    for (Eigen::Index i = 0; i < res.size(); ++i)
      if (std::abs(res(i)) > 1e-9 * scale(i) + 1e-13) return false;
    const int r = static_cast<int>(svd.rank());
    Z = svd.matrixV().rightCols(N - r);
  }
  if (K.empty()) return true;
  const MatrixXd A = rows_of(E, K) * Z;
  const VectorXd b = rows_of(E, K) * qp + entries_of(g, K);
  if (b.minCoeff() >= 0.0) return true;
  const auto lemke = lcp::make_solver("lemke");
  const lcp::Result sol = lemke->solve(A * A.transpose(), b, lcp::Options{});
  return sol.ok();
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
void feasible_subsets(const MatrixXd& E, const VectorXd& g, const std::vector<int>& C,
                      std::set<std::vector<int>>& seen, std::vector<std::vector<int>>& out,
                      size_t cap) {
  if (!seen.insert(C).second || out.size() >= cap) return;
  if (feasible(E, g, C)) {
    out.push_back(C);
    return;
  }
  for (size_t i = 0; i < C.size(); ++i) {
    std::vector<int> D = C;
    D.erase(D.begin() + static_cast<std::ptrdiff_t>(i));
    feasible_subsets(E, g, D, seen, out, cap);
  }
}

bool subset_of(const std::vector<int>& a, const std::vector<int>& b) {
  return std::includes(b.begin(), b.end(), a.begin(), a.end());
}

}  // namespace

bool can_be_active_together(const MechanicalModel& m, std::vector<int> J) {
  std::sort(J.begin(), J.end());
  return feasible(MatrixXd(m.E), m.g, J);
}

CoactiveSets coactive_sets(const MechanicalModel& m, size_t max_sets) {
  CoactiveSets out;
  const int k = m.num_constraints();
  const MatrixXd E(m.E);
  std::vector<int> single;
  for (int i = 0; i < k; ++i) {
    if (feasible(E, m.g, {i}))
      single.push_back(i);
    else
      out.never_active.push_back(i);
  }
  std::vector<std::vector<bool>> adj(k, std::vector<bool>(k, false));
  for (size_t a = 0; a < single.size(); ++a)
    for (size_t b = a + 1; b < single.size(); ++b) {
      const int i = single[a], j = single[b];
      if (feasible(E, m.g, {i, j}))
        adj[i][j] = adj[j][i] = true;
      else
        out.exclusive_pairs.emplace_back(i, j);
    }
  std::vector<std::vector<int>> cl;
  cliques(adj, {}, single, {}, cl, max_sets, out.complete);
  std::set<std::vector<int>> seen;
  std::vector<std::vector<int>> sets;
  for (const auto& C : cl) feasible_subsets(E, m.g, C, seen, sets, max_sets);
  if (sets.size() >= max_sets) out.complete = false;
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

CoactiveWellPosedness coactive_well_posedness(const MechanicalModel& m, const CoactiveSets& s) {
  CoactiveWellPosedness out;
  const lcs::Lcs sys = to_lcs(m);
  const MatrixXd W = delassus(m);
  const MatrixXd E(m.E);
  for (const auto& J : s.maximal) {
    CoactiveWellPosedness::Set r;
    r.indices = J;
    const auto n = static_cast<Eigen::Index>(J.size());
    MatrixXd WJ(n, n);
    for (Eigen::Index a = 0; a < n; ++a)
      for (Eigen::Index b = 0; b < n; ++b) WJ(a, b) = W(J[a], J[b]);
    r.rank = n ? lcs::numerical_rank(rows_of(E, J)) : 0;
    r.delassus_p_matrix = n == 0 || lcp::is_p_matrix(WJ);
    lcs::Lcs sub;
    sub.A = sys.A;
    sub.B.resize(sys.n(), n);
    sub.C.resize(n, sys.n());
    sub.D.resize(n, n);
    for (Eigen::Index a = 0; a < n; ++a) {
      sub.B.col(a) = sys.B.col(J[a]);
      sub.C.row(a) = sys.C.row(J[a]);
      for (Eigen::Index b = 0; b < n; ++b) sub.D(a, b) = sys.D(J[a], J[b]);
    }
    const std::vector<int> rho = lcs::leading_row_indices(sub);
    const std::vector<int> eta = lcs::leading_column_indices(sub);
    const auto finite = [](const std::vector<int>& v) {
      return std::none_of(v.begin(), v.end(), [](int i) { return i == lcs::kInfiniteIndex; });
    };
    r.row_p_matrix =
        n == 0 || (finite(rho) && lcp::is_p_matrix(lcs::leading_row_coefficients(sub)));
    r.column_p_matrix =
        n == 0 || (finite(eta) && lcp::is_p_matrix(lcs::leading_column_coefficients(sub)));
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

}  // namespace lcsim::mech
