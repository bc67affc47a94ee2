// SO(3) helpers (include/lcsim/scene/so3.hpp).
#include <Eigen/Geometry>
#include <cmath>
#include <lcsim/scene/so3.hpp>

namespace lcsim::scene {

using Eigen::Matrix3d;
using Eigen::Vector3d;

Matrix3d skew(const Vector3d& v) {
  Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

Matrix3d exp_so3(const Vector3d& r) {
  const double th = r.norm();
  return th > 0.0 ? Eigen::AngleAxisd(th, r / th).toRotationMatrix() : Matrix3d::Identity();
}

Vector3d log_so3(const Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Matrix3d left_jacobian(const Vector3d& r) {
  const double th = r.norm(), t2 = th * th;
  double a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0, b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  if (th >= 1e-2) {
    const double s = std::sin(0.5 * th);
    a = 2.0 * s * s / t2;  // 1 - cos th = 2 sin^2(th/2), without cancellation
    b = (th - std::sin(th)) / (t2 * th);
  }
  const Matrix3d K = skew(r);
  return Matrix3d::Identity() + a * K + b * K * K;
}

}  // namespace lcsim::scene
