// The P-matrix test of a normal matrix on contacts whose rows may be
// redundant (issue 27: a box's four coplanar corners), kept out of lcp.hpp so
// that only its two users (the cone impact and the exact method's
// Painlevé test) include it.
#pragma once

#include <Eigen/Dense>

namespace lcsim::lcp {

// True when every principal minor of Ns over an index set J whose W_JJ is
// nonsingular is positive; W is the Gram matrix E M^-1 E' of the rows that
// Ns = E M^-1 G' is formed from. A set J of dependent rows (y' E_J = 0 for
// some y != 0) has y' Ns_JJ = 0, so its minor vanishes whatever G: it says
// nothing about G (friction pressing contacts shut) and is skipped. Both
// determinants are judged as is_p_matrix does (positive when above rel_tol
// times their Hadamard bound); with W_JJ nonsingular for every J this is
// is_p_matrix(Ns). k = Ns.rows() <= 20.
bool is_p_matrix_on_independent_rows(const Eigen::MatrixXd& Ns, const Eigen::MatrixXd& W,
                                     double rel_tol = 1e-12);

}  // namespace lcsim::lcp
