// SO(3) helpers shared by the scene layer (a floating base's rotation vector,
// docs/contacts.md, "The base") and the peers that map it to their own
// coordinates (src/bullet, src/mujoco).
//
// A floating base's orientation is exp([r]x) R0 with r a rotation vector in
// world axes; its angular velocity is omega = J_l(r) r' (J_l the left
// Jacobian of SO(3)).
#pragma once

#include <Eigen/Dense>

namespace lcsim::scene {

// [v]x, the matrix of v x (.).
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

// exp([r]x): the rotation by |r| about r / |r| (the identity at r = 0).
Eigen::Matrix3d exp_so3(const Eigen::Vector3d& r);

// The rotation vector of R, angle in [0, pi] (Eigen::AngleAxisd's).
Eigen::Vector3d log_so3(const Eigen::Matrix3d& R);

// The left Jacobian of SO(3) at r: d/dt exp([r]x) = [J_l(r) r']x exp([r]x),
// J_l = 1 + a [r]x + b [r]x^2 with a = (1 - cos th)/th^2,
// b = (th - sin th)/th^3 (th = |r|); below th = 1e-2 by their series to th^4
// (the next terms are under 3e-17), where the closed forms lose digits.
Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& r);

}  // namespace lcsim::scene
