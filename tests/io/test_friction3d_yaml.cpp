// Three-dimensional contacts in model files (issue 27): `tangents:` with an
// optional `d:` per entry and the model's `friction_d:`, written back, and
// every malformed entry refused with one line naming the file, the entry
// and the value.
#include <gtest/gtest.h>

#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

#include "support/model_error.hpp"

namespace lcsim::io {
namespace {

using scene::parse_model;

std::string error_of(const std::string& yaml) { return test_support::model_error(yaml); }

// A point mass (x, y, z) over the floor z >= 0 and a wall x >= 0.
std::string model(const std::string& friction, const std::string& extra = "") {
  return "name: t\nmechanical:\n  M: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
         "  E: [[0, 0, 1], [1, 0, 0]]\n  constraints: [floor, wall]\n" +
         extra + friction;
}

std::string one(const std::string& entry, const std::string& extra = "") {
  return error_of(model("  friction:\n    - " + entry + "\n", extra));
}

TEST(Friction3dYaml, TangentsAndDAreRead) {
  const mech::Model m =
      parse_model(model("  friction:\n    - {contact: floor, tangents: [[1, 0, 0], [0, 1, 0]], "
                        "mu: 0.5, d: 6}\n    - {contact: wall, tangents: [[0, 2, 0], [0, 0, "
                        "-2]], mu: 0.25}\n    \n",
                        "  friction_d: 3\n"),
                  "ok.yaml");
  const mech::MechanicalModel& mm = *m.mechanical;
  ASSERT_EQ(mm.friction.size(), 2u);
  EXPECT_TRUE(mm.has_friction_3d());
  EXPECT_EQ(Eigen::VectorXd(mm.friction[0].tangent), Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(Eigen::VectorXd(mm.friction[0].tangent2), Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(mm.edges_of(mm.friction[0]), 6);
  EXPECT_EQ(mm.edges_of(mm.friction[1]), 3);  // the model's friction_d
  EXPECT_EQ(mm.cone_edges, 3);
}

TEST(Friction3dYaml, DefaultDIsFour) {
  const mech::Model m = parse_model(
      model("  friction:\n    - {contact: 0, tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.5}\n"),
      "ok.yaml");
  EXPECT_EQ(m.mechanical->edges_of(m.mechanical->friction[0]), 4);
}

TEST(Friction3dYaml, PlanarEntriesAreUnchangedAndD1) {
  const mech::Model m = parse_model(
      model("  friction:\n    - {contact: 0, tangent: [1, 0, 0], mu: 0.5}\n"), "p.yaml");
  EXPECT_FALSE(m.mechanical->has_friction_3d());
  EXPECT_EQ(m.mechanical->edges_of(m.mechanical->friction[0]), 1);
  const std::string text = model_yaml(m);
  EXPECT_NE(text.find("    - {contact: 0, tangent: [1, 0, 0], mu: 0.5}\n"), std::string::npos);
  EXPECT_EQ(text.find("friction_d"), std::string::npos) << text;
}

TEST(Friction3dYaml, WrittenBackAndReadAgain) {
  const mech::Model m = parse_model(
      model("  friction:\n    - {contact: 1, tangents: [[0, 1, 0], [0, 0, 1]], mu: 0.75, d: 2}\n"
            "    - {contact: 0, tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.5}\n",
            "  friction_d: 7\n"),
      "ok.yaml");
  const std::string text = model_yaml(m);
  EXPECT_NE(text.find("{contact: 1, tangents: [[0, 1, 0], [0, 0, 1]], d: 2, mu: 0.75}"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("{contact: 0, tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.5}"), std::string::npos)
      << text;
  EXPECT_NE(text.find("  friction_d: 7\n"), std::string::npos) << text;
  const mech::Model back = parse_model(text, "back.yaml");
  const mech::MechanicalModel& b = *back.mechanical;
  EXPECT_EQ(b.edges_of(b.friction[0]), 2);
  EXPECT_EQ(b.edges_of(b.friction[1]), 7);
  EXPECT_EQ(Eigen::VectorXd(b.friction[0].tangent2), Eigen::Vector3d(0, 0, 1));
}

// Each bad input: one line naming the file, the entry and the value.
TEST(Friction3dYaml, BadEntriesNameTheEntryAndValue) {
  const std::string t = "tangents: [[1, 0, 0], [0, 1, 0]]";
  EXPECT_EQ(one("{contact: 0, " + t + ", mu: -0.1}"),
            "bad.yaml: mechanical.friction[0].mu: must be >= 0 (got -0.1)");
  EXPECT_EQ(one("{contact: 0, " + t + ", mu: 0.1, d: 0}"),
            "bad.yaml: mechanical.friction[0].d: must be a whole number >= 1 and <= 1024 (got "
            "'0')");
  EXPECT_EQ(one("{contact: 0, " + t + ", mu: 0.1, d: 2.5}"),
            "bad.yaml: mechanical.friction[0].d: must be a whole number >= 1 and <= 1024 (got "
            "'2.5')");
  EXPECT_EQ(one("{contact: 0, " + t + ", mu: 0.1}", "  friction_d: -1\n"),
            "bad.yaml: mechanical.friction_d: must be a whole number >= 1 and <= 1024 (got '-1')");
  EXPECT_EQ(one("{contact: 0, tangents: [[1, 0, 0.5], [0, 1, 0]], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangents: tangents[0] and the normal row E[0] are "
            "not orthogonal: cosine 0.447214, more than 1e-09 (Euclidean, in the model's "
            "coordinates)");
  EXPECT_EQ(one("{contact: wall, tangents: [[0, 1, 0], [1, 0, 0]], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangents: tangents[1] and the normal row E[1] are "
            "not orthogonal: cosine 1, more than 1e-09 (Euclidean, in the model's coordinates)");
  EXPECT_EQ(one("{contact: 0, tangents: [[1, 0, 0], [1, 1, 0]], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangents: tangents[0] and tangents[1] are not "
            "orthogonal: cosine 0.707107, more than 1e-09 (Euclidean, in the model's "
            "coordinates)");
  EXPECT_EQ(one("{contact: 0, tangents: [[1, 0, 0], [0, 2, 0]], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangents: tangents[0] and tangents[1] must have "
            "equal lengths (got 1 and 2): the cone's edges are at angles pi i/d");
  EXPECT_EQ(one("{contact: roof, " + t + ", mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].contact: no constraint named 'roof' (the "
            "constraints: floor, wall)");
  EXPECT_EQ(one("{contact: 2, " + t + ", mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].contact: expected a whole number in [0, 2) (got "
            "'2')");
  EXPECT_EQ(one("{contact: 0, tangent: [1, 0, 0], " + t + ", mu: 0.1}"),
            "bad.yaml: mechanical.friction[0]: has both tangent and tangents (one tangent row is "
            "planar, two are 3-D)");
  EXPECT_EQ(one("{contact: 0, tangent: [1, 0, 0], mu: 0.1, d: 2}"),
            "bad.yaml: mechanical.friction[0].d: applies to an entry with tangents: (a planar "
            "contact is d = 1)");
  EXPECT_EQ(one("{contact: 0, tangents: [[1, 0, 0]], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangents: expected two tangent rows [[...], [...]] "
            "(got a list of 1 entries)");
  EXPECT_EQ(one("{contact: 0, tangents: [[1, 0, 0], [0, 0, 0]], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangents[1]: all zero (it measures no sliding)");
  EXPECT_EQ(one("{contact: 0, " + t + ", mu: 0.1, velocity: 1}"),
            "bad.yaml: mechanical.friction[0].velocity: a moving surface is planar only (got 1 "
            "with two tangents)");
  EXPECT_EQ(one("{contact: 0, mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangent: missing (tangent: one row, or tangents: "
            "two rows)");
  for (const std::string& e :
       {one("{contact: 0, " + t + ", mu: -0.1}"), one("{contact: 0, " + t + ", mu: 1, d: 0}")})
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;  // one line
}

// Built in code: d < 0 and a tangent of the wrong length are the model
// check's (edges = 0 is the model's default).
TEST(Friction3dModelCheck, InCode) {
  mech::Model m = parse_model(
      model("  friction:\n    - {contact: 0, tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.5}\n"),
      "ok.yaml");
  m.mechanical->friction[0].edges = -2;
  auto p = mech::check_model(m);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->field + ": " + p->what, "mechanical.friction[0].d: must be >= 1 (got -2)");
  m.mechanical->friction[0].edges = 0;
  m.mechanical->friction[0].tangent2 = Eigen::Vector2d(0, 1).sparseView();
  p = mech::check_model(m);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->field + ": " + p->what,
            "mechanical.friction[0].tangents[1]: expected 3 entries (N = 3 coordinates, from M) "
            "(got 2)");
}

}  // namespace
}  // namespace lcsim::io
