// The factored Moreau–Jean iteration matrix W = M + h theta D + h^2 theta^2 K
// (MjIteration, step_kernels.hpp): dense LLT or sparse LDLT, and the columns
// W^{-1} E_i' (and W^{-1} t_f') computed on first use, by a local solve where W is sparse.
#include <algorithm>
#include <cmath>
#include <utility>

#include "sim/stepping/step_kernels.hpp"

namespace lcsim::sim::detail {

bool MjIteration::factor(const MjOperators& ops, double h, double theta) {
  sparse_ = ops.sparse();
  if (sparse_) {
    W_ = ops.W_sparse(h, theta);
    stamp_.clear();
    local_.assign(W_.rows(), 0);
    ldlt_.compute(W_);
    ok_ = ldlt_.info() == Eigen::Success && (ldlt_.vectorD().array() > 0.0).all();
  } else {
    llt_.compute(ops.W_dense(h, theta));
    ok_ = llt_.info() == Eigen::Success;
  }
  if (!ok_) {
    message_ = "iteration matrix M + h theta D + h^2 theta^2 K is not positive definite at h = " +
               short_number(h) + " (D or K indefinite?)";
    return false;
  }
  Et_ = ops.rows_transposed();  // column i = E_i', then the tangent rows
  cols_.assign(static_cast<size_t>(Et_.cols()), SparseCol());
  have_.assign(static_cast<size_t>(Et_.cols()), 0);
  return true;
}

bool MjIteration::compute_column(int i) {
  VectorXd c;
  std::vector<int> rows;
  if (!(sparse_ && local_column(i, rows, c))) {
    c = solve(VectorXd(Et_.col(i)));
    rows.resize(c.size());
    for (int r = 0; r < c.size(); ++r) rows[r] = r;
  }
  if (!c.allFinite()) return false;
  const double cut = kPruneRelative * c.cwiseAbs().maxCoeff();
  std::vector<std::pair<int, double>> kept;
  for (int a = 0; a < c.size(); ++a)
    if (std::abs(c(a)) > cut) kept.emplace_back(rows[a], c(a));
  std::sort(kept.begin(), kept.end());
  SparseCol s(Et_.rows(), 1);
  s.reserve(static_cast<Eigen::Index>(kept.size()));
  for (const auto& [r, x] : kept) s.insert(r, 0) = x;
  s.makeCompressed();
  cols_[i] = std::move(s);
  have_[i] = 1;
  return true;
}

// W^{-1} E_i' by a local solve: W restricted to the coordinates within r
// hops (in the graph of W) of E_i's support, zero outside, r grown until the
// outermost ring holds only entries below kPruneRelative of the largest.
// Then the neglected coupling W_{out,S} x_S is below that level too, so the
// column equals the full solve to the pruning level. Gives up (false) when
// the neighbourhood exceeds kLocalColumnMax coordinates (slow decay: large
// h or stiff K); the caller then does the full solve.
bool MjIteration::local_column(int i, std::vector<int>& nodes, VectorXd& c) {
  if (stamp_.empty()) stamp_.assign(W_.rows(), -1);
  nodes.clear();
  for (SparseCol::InnerIterator it(Et_, i); it; ++it) {
    nodes.push_back(static_cast<int>(it.row()));
    stamp_[it.row()] = i;
  }
  size_t ring_begin = 0;
  for (int hops = 1;; ++hops) {
    const size_t ring_end = nodes.size();
    for (size_t a = ring_begin; a < ring_end; ++a)
      for (SparseCol::InnerIterator it(W_, nodes[a]); it; ++it)
        if (stamp_[it.row()] != i) {
          stamp_[it.row()] = i;
          nodes.push_back(static_cast<int>(it.row()));
        }
    ring_begin = ring_end;
    if (nodes.size() > kLocalColumnMax) break;
    if (hops < 2 && ring_begin < nodes.size()) continue;
    const int ns = static_cast<int>(nodes.size());
    MatrixXd Ws = MatrixXd::Zero(ns, ns);
    VectorXd rhs = VectorXd::Zero(ns);
    for (int b = 0; b < ns; ++b) local_[nodes[b]] = b;
    for (int b = 0; b < ns; ++b)
      for (SparseCol::InnerIterator it(W_, nodes[b]); it; ++it)
        if (stamp_[it.row()] == i) Ws(local_[it.row()], b) = it.value();
    for (SparseCol::InnerIterator it(Et_, i); it; ++it) rhs(local_[it.row()]) = it.value();
    const Eigen::LLT<MatrixXd> llt(Ws);
    if (llt.info() != Eigen::Success) break;
    c = llt.solve(rhs);
    const double top = c.cwiseAbs().maxCoeff();
    double ring = 0.0;
    for (int b = static_cast<int>(ring_begin); b < ns; ++b) ring = std::max(ring, std::abs(c(b)));
    if (ring <= kPruneRelative * top || ring_begin == nodes.size()) return true;
  }
  for (int r : nodes) stamp_[r] = -1;
  return false;
}

}  // namespace lcsim::sim::detail
