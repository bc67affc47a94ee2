// Exact equality of two mechanical models' data (M, D, K, E, g, f,
// restitution), for tests whose two models must agree to the last bit: a
// YAML round trip (numbers written in shortest round-trip form) and a URDF
// scene against the YAML model it reproduces.
#pragma once

#include <gtest/gtest.h>

#include <lcsim/mech/mech.hpp>

namespace lcsim::test_support {

inline void expect_same_matrices(const mech::MechanicalModel& a, const mech::MechanicalModel& b) {
  EXPECT_EQ(a.M.toDense(), b.M.toDense());
  EXPECT_EQ(a.D.toDense(), b.D.toDense());
  EXPECT_EQ(a.K.toDense(), b.K.toDense());
  EXPECT_EQ(a.E.toDense(), b.E.toDense());
  EXPECT_EQ(a.g, b.g);
  EXPECT_EQ(a.f, b.f);
  EXPECT_EQ(a.restitution, b.restitution);
}

}  // namespace lcsim::test_support
