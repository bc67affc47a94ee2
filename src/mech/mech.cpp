#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseQR>
#include <algorithm>
#include <lcsim/mech/mech.hpp>
#include <limits>
#include <stdexcept>

namespace lcsim::mech {

void fill_defaults(MechanicalModel& m) {
  const int n = m.dofs();
  const int k = m.num_constraints();
  if (m.D.size() == 0) m.D = SparseMatrix(n, n);
  if (m.K.size() == 0) m.K = SparseMatrix(n, n);
  if (m.E.size() == 0) m.E = SparseMatrix(0, n);
  if (m.g.size() == 0) m.g = VectorXd::Zero(k);
  if (m.f.size() == 0) m.f = VectorXd::Zero(n);
  if (m.restitution.size() == 0) m.restitution = VectorXd::Zero(k);
  if (m.coordinates.empty())
    for (int i = 0; i < n; ++i) m.coordinates.push_back("q" + std::to_string(i + 1));
  if (m.constraints.empty())
    for (int i = 0; i < k; ++i) m.constraints.push_back("c" + std::to_string(i + 1));
}

bool MechanicalModel::has_friction_3d() const {
  return std::any_of(friction.begin(), friction.end(),
                     [](const FrictionalContact& c) { return c.is_3d(); });
}

namespace {
int exosystem_size(const MechanicalModel& m) {
  int e = 0;
  for (const Input& in : m.inputs) e += in.exo_size();
  return e;
}

// The first state of each input's exosystem in the augmented state.
std::vector<int> exosystem_offsets(const MechanicalModel& m) {
  std::vector<int> at;
  int next = 2 * m.dofs() + 1;
  for (const Input& in : m.inputs) {
    at.push_back(next);
    next += in.exo_size();
  }
  return at;
}

// The exosystems in A, their outputs in the v rows (forces) and in C (gaps).
void add_inputs(const MechanicalModel& m, const Eigen::LLT<MatrixXd>& llt, lcs::Lcs& s) {
  const int n = m.dofs();
  const std::vector<int> at = exosystem_offsets(m);
  for (std::size_t j = 0; j < m.inputs.size(); ++j) {
    const int d = m.inputs[j].exo_size();
    s.A.block(at[j], at[j], d, d) = m.inputs[j].exo_matrix();
  }
  for (const InputUse& use : m.force_inputs) {
    const Input& in = m.inputs[static_cast<std::size_t>(use.input)];
    s.A.block(n, at[static_cast<std::size_t>(use.input)], n, in.exo_size()) +=
        llt.solve(use.gain) * in.exo_output();
  }
  for (const InputUse& use : m.gap_inputs) {
    const Input& in = m.inputs[static_cast<std::size_t>(use.input)];
    s.C.block(0, at[static_cast<std::size_t>(use.input)], m.num_constraints(), in.exo_size()) +=
        use.gain * in.exo_output();
  }
}
}  // namespace

VectorXd exosystem_states(const std::vector<Input>& inputs, double t) {
  int size = 0;
  for (const Input& in : inputs) size += in.exo_size();
  VectorXd w(size);
  int at = 0;
  for (const Input& in : inputs) {
    w.segment(at, in.exo_size()) = in.exo_state(t);
    at += in.exo_size();
  }
  return w;
}

double next_breakpoint(const std::vector<Input>& inputs, double t) {
  double next = std::numeric_limits<double>::infinity();
  for (const Input& in : inputs) next = std::min(next, in.next_breakpoint(t));
  return next;
}

VectorXd exosystem_states(const MechanicalModel& m, double t) {
  return exosystem_states(m.inputs, t);
}

double next_breakpoint(const MechanicalModel& m, double t) { return next_breakpoint(m.inputs, t); }

VectorXd force_at(const MechanicalModel& m, double t) {
  VectorXd f = m.f;
  for (const InputUse& use : m.force_inputs)
    f += use.gain * m.inputs[static_cast<std::size_t>(use.input)].value(t);
  return f;
}

VectorXd gap_at(const MechanicalModel& m, double t) {
  VectorXd g = m.g;
  for (const InputUse& use : m.gap_inputs)
    g += use.gain * m.inputs[static_cast<std::size_t>(use.input)].value(t);
  return g;
}

lcs::Lcs to_lcs(const MechanicalModel& m) {
  const int n = m.dofs();
  const int k = m.num_constraints();
  const Eigen::LLT<MatrixXd> llt(m.M.toDense());
  const int na = 2 * n + 1 + exosystem_size(m);
  lcs::Lcs s;
  s.A = MatrixXd::Zero(na, na);
  s.A.block(0, n, n, n) = MatrixXd::Identity(n, n);
  s.A.block(n, 0, n, n) = -llt.solve(m.K.toDense());
  s.A.block(n, n, n, n) = -llt.solve(m.D.toDense());
  s.A.block(n, 2 * n, n, 1) = llt.solve(m.f);
  s.B = MatrixXd::Zero(na, k);
  s.C = MatrixXd::Zero(k, na);
  if (k > 0) {  // an empty block at a non-zero offset is UB in Eigen (found by UBSan)
    const MatrixXd E = m.E.toDense();
    s.B.block(n, 0, n, k) = llt.solve(E.transpose());
    s.C.block(0, 0, k, n) = E;
    s.C.col(2 * n) = m.g;
  }
  s.D = MatrixXd::Zero(k, k);
  if (m.has_inputs()) add_inputs(m, llt, s);
  return s;
}

double kinetic_energy(const MechanicalModel& m, const VectorXd& v) { return 0.5 * v.dot(m.M * v); }

double potential_energy(const MechanicalModel& m, const VectorXd& q) {
  return 0.5 * q.dot(m.K * q) - m.f.dot(q);
}

double total_energy(const MechanicalModel& m, const VectorXd& q, const VectorXd& v) {
  return kinetic_energy(m, v) + potential_energy(m, q);
}

VectorXd gaps(const MechanicalModel& m, const VectorXd& q) { return m.E * q + m.g; }

double worst_violation(const MechanicalModel& m, const VectorXd& q) {
  if (m.num_constraints() == 0) return 0.0;
  return std::min(0.0, gaps(m, q).minCoeff());
}

VectorXd project_feasible(const MechanicalModel& m, const VectorXd& q) {
  const int k = m.num_constraints();
  if (k == 0) return q;
  const Eigen::SimplicialLDLT<SparseMatrix> ldlt(m.M);
  const SparseMatrix Et = m.E.transpose();
  const auto violated = [&](const VectorXd& p, std::vector<int>& rows) {
    const VectorXd gap = gaps(m, p);
    const VectorXd scale = gap_scale(m.E, p, m.g);
    bool added = false;
    for (int i = 0; i < k; ++i)
      if (projection_violates(gap(i), scale(i)) &&
          std::find(rows.begin(), rows.end(), i) == rows.end()) {
        rows.push_back(i);
        added = true;
      }
    return added;
  };
  const VectorXd y = gaps(m, q);  // the LCP's constant term, row by row
  std::vector<int> rows;
  VectorXd p = q;
  const auto solver = lcp::make_solver("pivot");
  for (int round = 0; round <= k && violated(p, rows); ++round) {
    const auto a = static_cast<Eigen::Index>(rows.size());
    MatrixXd MinvEt(q.size(), a);  // M^{-1} E_A'
    VectorXd ya(a);
    for (Eigen::Index j = 0; j < a; ++j) {
      MinvEt.col(j) = ldlt.solve(VectorXd(Et.col(rows[j])));
      ya(j) = y(rows[j]);
    }
    MatrixXd W(a, a);
    for (Eigen::Index i = 0; i < a; ++i) W.row(i) = (m.E.row(rows[i]) * MinvEt);
    const lcp::Result r = lcp::solve_scaled(*solver, W, ya, lcp::Options{});
    if (!r.ok())
      throw std::invalid_argument(
          "cannot project the initial state onto E q + g >= 0: the constraints " +
          std::string("admit no configuration (LCP ") +
          std::string(lcp::to_string(r.status, "solved")) + ")");
    p = q + MinvEt * r.z;
  }
  return p;
}

int constraint_rank(const MechanicalModel& m) {
  if (m.E.size() == 0) return 0;
  constexpr double kDenseEntries = 1e6;
  if (static_cast<double>(m.E.rows()) * static_cast<double>(m.E.cols()) <= kDenseEntries) {
    return lcs::numerical_rank(m.E.toDense());
  }
  const SparseMatrix Et = m.E.transpose();
  Eigen::SparseQR<SparseMatrix, Eigen::COLAMDOrdering<int>> qr;
  const double scale = m.E.norm() > 0.0 ? m.E.norm() : 1.0;
  qr.setPivotThreshold(static_cast<double>(std::max(Et.rows(), Et.cols())) * 1e-12 * scale);
  qr.compute(Et);
  return static_cast<int>(qr.rank());
}

MatrixXd delassus(const MechanicalModel& m) {
  const MatrixXd Et = m.E.transpose().toDense();
  return m.E * Eigen::LLT<MatrixXd>(m.M.toDense()).solve(Et);
}

int Model::state_size() const {
  if (mechanical) return 2 * mechanical->dofs();
  if (lcs) return lcs->n();
  return 0;
}

std::size_t Model::interval_at(double t) const {
  return static_cast<std::size_t>(std::upper_bound(switch_times.begin(), switch_times.end(), t) -
                                  switch_times.begin());
}

const std::vector<Input>& Model::scheduled_inputs() const {
  return mechanical ? mechanical->inputs : inputs;
}

VectorXd Model::full_state(const VectorXd& x) const {
  const int n = state_size();
  if (exo_states <= 0 || x.size() != n - exo_states) return x;
  VectorXd full(n);
  full << x, exo_initial;
  return full;
}

int Model::num_constraints() const {
  if (mechanical) return mechanical->num_constraints();
  if (lcs) return lcs->k();
  return 0;
}

int Model::lcs_state_size() const {
  if (mechanical) return 2 * mechanical->dofs() + 1 + exosystem_size(*mechanical);
  if (lcs) return lcs->n();
  return 0;
}

lcs::Lcs Model::as_lcs() const {
  if (lcs_state_size() > kMaxDenseLcsState)
    throw std::invalid_argument(
        "the model's LCS has " + std::to_string(lcs_state_size()) + " states, more than the " +
        std::to_string(kMaxDenseLcsState) +
        " that dense methods take (event-driven, euler, analyze); simulate models this large "
        "with the moreau-jean method");
  if (mechanical) return to_lcs(*mechanical);
  if (lcs) return *lcs;
  throw std::logic_error("Model::as_lcs: empty model");
}

}  // namespace lcsim::mech
