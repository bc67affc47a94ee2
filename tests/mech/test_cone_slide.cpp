// The sliding block on a polyhedral friction cone (issue 27): the closed form
// of mech::cone_slide against an independent integration (backward Euler on
// the velocity, the friction force of maximal dissipation over the polygon
// found by enumerating its vertices and faces), at every kind of heading
// (on an edge, on a bisector, between, negative, beyond 2 pi) and d = 1 .. 16,
// and its limits against the circular cone.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <lcsim/mech/cone_slide.hpp>
#include <random>
#include <vector>

namespace lcsim::mech {
namespace {

const double kPi = std::acos(-1.0);

// The unit polygon of 2d vertices D_j = (cos, sin)(pi j/d) and its faces'
// outward normals b_j at pi (j + 1/2)/d.
struct Polygon {
  int d;
  std::vector<Eigen::Vector2d> D, b;
  explicit Polygon(int dd) : d(dd) {
    for (int j = 0; j < 2 * d; ++j) {
      D.emplace_back(std::cos(kPi * j / d), std::sin(kPi * j / d));
      b.emplace_back(std::cos(kPi * (j + 0.5) / d), std::sin(kPi * (j + 0.5) / d));
    }
  }
};

// One backward Euler step u+ = u + c F, F in the unit polygon, F.u+ minimal
// (c = h mu g): u+ = 0 when -u/c is in the polygon; else the vertex j with
// -u+ strictly in its region; else the face (j, j+1), u+ = -sigma b_j.
Eigen::Vector2d implicit_step(const Eigen::Vector2d& u, double c, const Polygon& P) {
  const double half = kPi / (2 * P.d), ch = std::cos(half), sh = std::sin(half);
  bool inside = true;
  for (int j = 0; j < 2 * P.d && inside; ++j)
    inside = -u.dot(P.D[j]) <= c && -u.dot(P.b[j]) <= c * ch + 1e-15 * u.norm();
  if (inside) return Eigen::Vector2d::Zero();
  for (int j = 0; j < 2 * P.d; ++j) {
    const Eigen::Vector2d up = u + c * P.D[j];
    if (-up.dot(P.D[j]) > up.norm() * ch) return up;
  }
  for (int j = 0; j < 2 * P.d; ++j) {
    const double sigma = -u.dot(P.b[j]) - c * ch;
    // Across the face: within its half-length, to rounding.
    if (sigma > 0 && std::abs(u.x() * -P.b[j].y() + u.y() * P.b[j].x()) <= c * sh * (1 + 1e-9))
      return -sigma * P.b[j];
  }
  ADD_FAILURE() << "no case of the step holds";
  return Eigen::Vector2d::Zero();
}

struct Integrated {
  double t_stop = -1, x = 0, y = 0, path = 0, heading = 0;
};

Integrated integrate(double s0, double psi, double mu, double g, int d, double h, double t_max) {
  Integrated out;
  Eigen::Vector2d u(s0 * std::cos(psi), s0 * std::sin(psi));
  const Polygon P(d);
  for (long n = 1; n * h <= t_max; ++n) {
    const Eigen::Vector2d next = implicit_step(u, h * mu * g, P);
    if (next.isZero(0.0)) {
      out.t_stop = n * h;
      out.heading = std::atan2(u.y(), u.x());
      return out;
    }
    u = next;
    out.x += h * u.x();
    out.y += h * u.y();
    out.path += h * u.norm();
  }
  out.heading = std::atan2(u.y(), u.x());
  return out;
}

// The heading difference folded to (-pi, pi].
double angle_gap(double a, double b) { return std::remainder(a - b, 2 * kPi); }

// The worst gaps between the closed form and the integration at step h.
struct Gaps {
  double t = 0, x = 0, path = 0, heading = 0;
};

Gaps gaps_at(double h, int* cases) {
  const double mu = 0.4, g = 9.81, s0 = 2.0;
  std::mt19937_64 rng(27);
  std::uniform_real_distribution<double> angle(-7.0, 7.0);
  Gaps w;
  for (const int d : {2, 3, 4, 5, 8, 16}) {
    const double delta = kPi / d;
    std::vector<double> psis = {0.0,         delta,     -delta,       delta / 2,     -delta / 2,
                                2.5 * delta, delta / 4, -0.3 * delta, 2 * kPi + 0.1, 7 * delta / 2};
    for (int i = 0; i < 4; ++i) psis.push_back(angle(rng));
    for (const double psi : psis) {
      SCOPED_TRACE("d " + std::to_string(d) + " psi " + std::to_string(psi));
      const ConeSlide c = cone_slide(s0, psi, mu, g, d);
      const Integrated n = integrate(s0, psi, mu, g, d, h, 2.0);
      w.t = std::max(w.t, std::abs(n.t_stop - c.t_stop));
      w.x = std::max({w.x, std::abs(n.x - c.x), std::abs(n.y - c.y)});
      w.path = std::max(w.path, std::abs(n.path - c.path));
      w.heading = std::max(w.heading, std::abs(angle_gap(n.heading, c.heading)));
      // Backward Euler is first order: it stops within a step or two of the
      // closed form (the last step may end up to h/cos(pi/(2d)) late); its
      // positions lag by s0 h/2 (each step moves with the velocity at its
      // end) plus O(h^2), so s0 h bounds them; the heading of the last step
      // is the bisector's exactly (the face step keeps it) or the edge's.
      EXPECT_NEAR(n.t_stop, c.t_stop, 3 * h);
      EXPECT_NEAR(n.x, c.x, s0 * h);
      EXPECT_NEAR(n.y, c.y, s0 * h);
      EXPECT_NEAR(n.path, c.path, s0 * h);
      EXPECT_NEAR(angle_gap(n.heading, c.heading), 0.0, 1e-6);
      // Against the circular cone: never shorter, at most 1/cos(pi/(2d)) longer.
      const double worst = 1.0 / std::cos(kPi / (2 * d));
      EXPECT_GE(c.t_stop, c.circular_t_stop * (1 - 1e-15));
      EXPECT_LE(c.t_stop, c.circular_t_stop * worst * (1 + 1e-15));
      EXPECT_GE(c.path, c.circular_distance * (1 - 1e-15));
      EXPECT_LE(c.path, c.circular_distance * worst * (1 + 1e-15));
      ++*cases;
    }
  }
  std::printf(
      "cone_slide against backward Euler at h = %g: worst stop time %.3g s, "
      "displacement %.3g m, path %.3g m, heading %.3g rad\n",
      h, w.t, w.x, w.path, w.heading);
  return w;
}

TEST(ConeSlide, MatchesAnIndependentIntegrationAtEveryHeading) {
  int cases = 0;
  const Gaps a = gaps_at(2e-5, &cases), b = gaps_at(1e-5, &cases);
  EXPECT_EQ(cases, 2 * 6 * 14);
  // First order towards the closed form (not towards another limit): halving
  // h halves the positions' gaps (0.6 leaves room for the O(h^2) terms).
  EXPECT_LE(b.x, 0.6 * a.x);
  EXPECT_LE(b.path, 0.6 * a.path);
}

TEST(ConeSlide, EdgeAndBisectorAreTheCircularStopAndTheWorstCase) {
  const double mu = 0.5, g = 10.0, s0 = 3.0;
  for (const int d : {1, 2, 4, 7}) {
    const double delta = kPi / d;
    // On an edge: straight, exactly the circular cone (to rounding of psi).
    const ConeSlide e = cone_slide(s0, 3 * delta, mu, g, d);
    EXPECT_NEAR(e.t_stop, s0 / (mu * g), 1e-15);
    EXPECT_NEAR(e.path, s0 * s0 / (2 * mu * g), 1e-15);
    EXPECT_NEAR(angle_gap(e.heading, 3 * delta), 0.0, 1e-15);
    if (d == 1) continue;
    // On a bisector: straight, at mu g cos(pi/(2d)).
    const double c = std::cos(kPi / (2 * d));
    const ConeSlide b = cone_slide(s0, 1.5 * delta, mu, g, d);
    EXPECT_NEAR(b.t_turn, 0.0, 1e-15);
    EXPECT_NEAR(b.t_stop, s0 / (mu * g * c), 1e-14);
    EXPECT_NEAR(b.path, s0 * s0 / (2 * mu * g * c), 1e-14);
    EXPECT_NEAR(std::hypot(b.x, b.y), b.path, 1e-14);
    EXPECT_NEAR(angle_gap(b.heading, 1.5 * delta), 0.0, 1e-15);
  }
  // d = 1 across its edge pair: no friction across, it never stops.
  EXPECT_TRUE(std::isinf(cone_slide(s0, 1.0, mu, g, 1).t_stop));
  EXPECT_THROW(cone_slide(s0, 0.0, mu, g, 0), std::invalid_argument);
  EXPECT_THROW(cone_slide(-1.0, 0.0, mu, g, 4), std::invalid_argument);
}

}  // namespace
}  // namespace lcsim::mech
