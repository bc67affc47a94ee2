// The mechanical layer: M q'' + D q' + K q = f + E' u, 0 <= y = E q + g ⟂ u >= 0.
//
// Public face of src/mech: the model value type, its LCS (3.65) with the affine
// terms f and g carried exactly by one extra constant state, energy and
// feasibility. Units are the user's (SI in the shipped models: m, kg, s, N).
#pragma once

#include <Eigen/Dense>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "lcs/lcs.hpp"

namespace lcsim::mech {

using Eigen::MatrixXd;
using Eigen::VectorXd;

struct MechanicalModel {
  MatrixXd M;              // mass matrix, symmetric positive definite (N x N)
  MatrixXd D;              // damping (N x N), zero if omitted
  MatrixXd K;              // stiffness (N x N), zero if omitted
  MatrixXd E;              // constraint rows (k x N): E q + g >= 0
  VectorXd g;              // gaps at q = 0 (k), zero if omitted
  VectorXd f;              // constant generalised force (N), e.g. gravity
  VectorXd restitution;    // per-constraint Newton coefficient in [0, 1] (k)
  std::vector<std::string> coordinates;  // names (N); "q1".. if omitted
  std::vector<std::string> constraints;  // names (k); "c1".. if omitted
  int dofs() const { return static_cast<int>(M.rows()); }
  int num_constraints() const { return static_cast<int>(E.rows()); }
};

// Fills omitted (empty) D, K, g, f, restitution with zeros and names with
// defaults. Dimensions must already agree.
void fill_defaults(MechanicalModel& m);

// LCS of eq. (3.65) on the augmented state (q, v, 1) of size 2N + 1:
// A = [0 I 0; -M^{-1}K -M^{-1}D M^{-1}f; 0 0 0], B = [0; M^{-1}E'; 0],
// C = [E 0 g], D = 0.
lcs::Lcs to_lcs(const MechanicalModel& m);

// Energies (J): T = ½ v'Mv, V = ½ q'Kq - f'q, total = T + V.
double kinetic_energy(const MechanicalModel& m, const VectorXd& v);
double potential_energy(const MechanicalModel& m, const VectorXd& q);
double total_energy(const MechanicalModel& m, const VectorXd& q, const VectorXd& v);

VectorXd gaps(const MechanicalModel& m, const VectorXd& q);  // E q + g
// Most negative gap (0 if all are >= 0).
double worst_violation(const MechanicalModel& m, const VectorXd& q);

// Delassus matrix E M^{-1} E' (the script M = script N of §3.8).
MatrixXd delassus(const MechanicalModel& m);

// A model file holds either a mechanical model or a general LCS, with an
// optional default initial state and horizon.
struct Model {
  std::string name;
  std::string source;  // where it was loaded from (for messages)
  std::optional<MechanicalModel> mechanical;
  std::optional<lcs::Lcs> lcs;  // set for `lcs:` models
  VectorXd initial;             // full state (q then v for mechanical); empty if unset
  double t_end = std::numeric_limits<double>::quiet_NaN();  // NaN if unset
  bool is_mechanical() const { return mechanical.has_value(); }
  int state_size() const;  // 2N for mechanical, n for LCS
  int num_constraints() const;
  // The LCS to simulate: to_lcs(mechanical) (augmented) or the LCS itself.
  lcs::Lcs as_lcs() const;
};

}  // namespace lcsim::mech
