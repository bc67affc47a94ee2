// The impact map (impact_map.hpp): range and name parsing, the closed set,
// placing q on the named contacts, the grid of impacts, its CSV.
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <lcsim/app/impact_map.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <optional>
#include <sstream>

namespace lcsim::app {

using io::format_number;
using io::InputError;
using io::one_line;
using io::split;

namespace {

std::string vec_text(const Eigen::VectorXd& v) {
  std::string s = "(";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + format_number(v(i));
  return s + ")";
}

// M^{-1} E_J' (N x |J|) and W = E_J M^{-1} E_J'; InputError when W is
// singular (rcond below 1e-12: rows dependent to rounding).
struct ClosedRows {
  Eigen::MatrixXd EJ, MinvEt, W;
};
ClosedRows closed_rows(const mech::MechanicalModel& m, const std::vector<int>& J,
                       const std::string& what) {
  ClosedRows c;
  const Eigen::MatrixXd E(m.E);
  c.EJ.resize(J.size(), m.dofs());
  for (size_t i = 0; i < J.size(); ++i) c.EJ.row(i) = E.row(J[i]);
  const Eigen::SimplicialLDLT<mech::SparseMatrix> ldlt(m.M);
  c.MinvEt = ldlt.solve(Eigen::MatrixXd(c.EJ.transpose()));
  c.W = c.EJ * c.MinvEt;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(c.W);
  const auto& s = svd.singularValues();
  if (s.size() > 0 && !(s(s.size() - 1) > 1e-12 * s(0))) {
    std::string names;
    for (size_t i = 0; i < J.size(); ++i) names += (i ? ", '" : "'") + m.constraints[J[i]] + "'";
    throw InputError(what + ": the rows of " + names +
                     " are dependent (E_J M^-1 E_J' is singular): their approach velocities "
                     "cannot be set apart");
  }
  return c;
}

// Pre-impact velocity of a cell: the base v0 or, with --closed, v0 changed
// least in the kinetic metric to give the rates w.
Eigen::VectorXd cell_velocity(const ClosedRows* c, const Eigen::VectorXd& v0,
                              const Eigen::Vector2d& w) {
  if (!c) return w;
  return v0 + c->MinvEt * c->W.ldlt().solve(w - c->EJ * v0);
}

double grid_point(const MapRange& r, int i) { return r.lo + (r.hi - r.lo) * i / (r.n - 1); }

}  // namespace

MapRange parse_map_range(const std::string& text, const std::string& what) {
  const std::vector<std::string> parts = split(text, ':');
  const std::string w = what + ": range '" + text + "'";
  if (parts.size() < 2 || parts.size() > 3) throw InputError(w + ": expected lo:hi or lo:hi:n");
  MapRange r;
  try {
    size_t pos = 0;
    r.lo = std::stod(parts[0], &pos);
    if (pos != parts[0].size()) throw std::invalid_argument("");
    r.hi = std::stod(parts[1], &pos);
    if (pos != parts[1].size()) throw std::invalid_argument("");
    r.n = parts.size() == 3 ? std::stoi(parts[2], &pos) : 41;
    if (parts.size() == 3 && pos != parts[2].size()) throw std::invalid_argument("");
  } catch (const std::exception&) {
    throw InputError(w + ": not numbers");
  }
  if (!std::isfinite(r.lo) || !std::isfinite(r.hi) || !(r.lo < r.hi))
    throw InputError(w + ": need finite lo < hi");
  if (r.n < 2 || r.n > 2001) throw InputError(w + ": n must lie in [2, 2001]");
  return r;
}

std::vector<int> parse_constraint_list(const mech::MechanicalModel& m, const std::string& text,
                                       const std::string& what) {
  std::vector<int> out;
  const int k = m.num_constraints();
  for (const std::string& tok : split(text, ',')) {
    int idx = -1;
    for (int i = 0; i < k; ++i)
      if (m.constraints[i] == tok) idx = i;
    if (idx < 0 && !tok.empty() && tok.find_first_not_of("0123456789") == std::string::npos) {
      idx = tok.size() <= 9 ? std::stoi(tok) : k;
      if (idx >= k)
        throw InputError(what + ": constraint index " + tok + " out of range (the model has " +
                         std::to_string(k) + " constraints, 0-based)");
    }
    if (idx < 0) {
      std::string known;
      for (int i = 0; i < k; ++i) known += (i ? ", " : "") + m.constraints[i];
      throw InputError(what + ": unknown constraint '" + one_line(tok) + "' (known: " + known +
                       ")");
    }
    if (std::find(out.begin(), out.end(), idx) != out.end())
      throw InputError(what + ": constraint '" + m.constraints[idx] + "' named twice");
    out.push_back(idx);
  }
  return out;
}

impact::IndexSet closed_constraints(const mech::MechanicalModel& m, const Eigen::VectorXd& q,
                                    const std::string& what) {
  const Eigen::VectorXd gap = m.E * q + m.g;
  const Eigen::VectorXd scale = mech::gap_scale(m.E, q, m.g);
  impact::IndexSet closed;
  for (int i = 0; i < m.num_constraints(); ++i) {
    const bool zero = mech::gap_is_zero(gap(i), scale(i));
    if (!zero && gap(i) < 0.0)
      throw InputError(what + ": constraint '" + m.constraints[i] + "' (" + std::to_string(i) +
                       ") is violated at q = " + vec_text(q) + " (gap = " + format_number(gap(i)) +
                       "): E q + g >= 0 must hold before an impact (thesis §3.8)");
    if (zero) closed.push_back(i);
  }
  return closed;
}

Eigen::VectorXd close_contacts(const mech::MechanicalModel& m, const Eigen::VectorXd& q,
                               const std::vector<int>& closed, const std::string& what) {
  const ClosedRows c = closed_rows(m, closed, what);
  Eigen::VectorXd gJ(closed.size());
  for (size_t i = 0; i < closed.size(); ++i) gJ(i) = m.g(closed[i]);
  return q - c.MinvEt * c.W.ldlt().solve(c.EJ * q + gJ);
}

namespace {

// The all-closed spelling: two coordinates, every gap zero at q.
void check_all_closed(const mech::MechanicalModel& m, const ImpactMapSpec& s,
                      const impact::IndexSet& closed) {
  if (m.dofs() != 2)
    throw InputError(
        "impact map: needs a model with two coordinates, or two closed constraints "
        "named as its axes; the model has " +
        std::to_string(m.dofs()));
  if (static_cast<int>(closed.size()) != m.num_constraints())
    throw InputError("impact map: every gap must be zero at q = " + vec_text(s.q) +
                     " (Figure 3.5 is drawn at x1 = x2 = 0); or name two contacts to close");
}

// The named-contacts spelling: exactly the named contacts closed at q.
void check_named_closed(const mech::MechanicalModel& m, const ImpactMapSpec& s,
                        const impact::IndexSet& closed) {
  if (s.closed.size() != 2)
    throw InputError("closed constraints: name two constraints (the map's two axes), got " +
                     std::to_string(s.closed.size()));
  const Eigen::VectorXd gap = m.E * s.q + m.g;
  for (int i : s.closed)
    if (std::find(closed.begin(), closed.end(), i) == closed.end())
      throw InputError("closed constraints: constraint '" + m.constraints[i] + "' (" +
                       std::to_string(i) + ") is open at q = " + vec_text(s.q) +
                       " (gap = " + format_number(gap(i)) + "); give a q that closes it");
  for (int i : closed)
    if (std::find(s.closed.begin(), s.closed.end(), i) == s.closed.end())
      throw InputError("closed constraints: constraint '" + m.constraints[i] + "' (" +
                       std::to_string(i) + ") is also closed at q = " + vec_text(s.q) +
                       " (gap 0) but not named; a map has two axes: name two closed contacts");
}

}  // namespace

ImpactMap impact_map(const mech::MechanicalModel& m, const ImpactMapSpec& s) {
  const int N = m.dofs();
  const std::string what = s.closed.empty() ? "impact map" : "closed constraints";
  if (s.q.size() != N || s.v0.size() != N)
    throw InputError(what + ": q and v need " + std::to_string(N) + " entries each");
  ImpactMap map;
  const impact::IndexSet closed = closed_constraints(m, s.q, what);
  std::optional<ClosedRows> rows;
  if (s.closed.empty()) {
    check_all_closed(m, s, closed);
    map.axes = {"v1", "v2"};
  } else {
    check_named_closed(m, s, closed);
    rows = closed_rows(m, s.closed, what);
    map.axes = {m.constraints[s.closed[0]], m.constraints[s.closed[1]]};
    map.axis_constraints = s.closed;
  }
  map.closed = closed;
  const auto law = impact::make_impact_law(s.law);
  const auto solver = lcp::make_solver("pivot");
  impact::ImpactInput in;
  in.model = &m;
  in.q = s.q;
  in.closed = closed;
  in.restitution = s.restitution;
  for (int i = 0; i < s.axis1.n; ++i)
    for (int j = 0; j < s.axis2.n; ++j) {
      ImpactMapCell cell;
      cell.before << grid_point(s.axis1, i), grid_point(s.axis2, j);
      in.v = cell_velocity(rows ? &*rows : nullptr, s.v0, cell.before);
      const impact::ImpactResult r = law->apply(in, *solver);
      if (!r.ok()) {
        map.failure = s.law + " failed at v = " + vec_text(in.v) + ": " + r.message;
        return map;
      }
      cell.after = rows ? Eigen::Vector2d(rows->EJ * r.v_after) : Eigen::Vector2d(r.v_after);
      cell.mode = r.mode;
      map.cells.push_back(std::move(cell));
    }
  return map;
}

std::string impact_map_csv(const mech::MechanicalModel& m, const ImpactMap& map) {
  std::ostringstream csv;
  csv.precision(10);
  if (map.axis_constraints.empty()) {
    csv << "v1,v2,mode,v1+,v2+\n";
  } else {  // axes named by 0-based index: constraint names may hold commas
    const int a = map.axis_constraints[0], b = map.axis_constraints[1];
    csv << "rate_" << a << ",rate_" << b << ",mode,rate_" << a << "+,rate_" << b << "+\n";
  }
  for (const auto& c : map.cells) {
    std::string mode;
    for (size_t i = 0; i < c.mode.size(); ++i) mode += (i ? "+" : "") + m.constraints[c.mode[i]];
    csv << c.before(0) << "," << c.before(1) << "," << (mode.empty() ? "unconstrained" : mode)
        << "," << c.after(0) << "," << c.after(1) << "\n";
  }
  return csv.str();
}

}  // namespace lcsim::app
