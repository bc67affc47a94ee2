// `mechanical.friction` in model files (issue 17): parsed by index or name,
// written back, and every malformed entry refused with one line naming the
// file, the entry and the value.
#include <gtest/gtest.h>

#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

#include "support/model_error.hpp"

namespace lcsim::io {
namespace {

// Any model file, as every command reads it (matrix models and scenes).
using scene::load_model;
using scene::parse_model;

std::string error_of(const std::string& yaml) { return test_support::model_error(yaml); }

// Two coordinates, two constraints named floor and wall.
std::string model(const std::string& friction) {
  return "name: t\nmechanical:\n  M: [[1, 0], [0, 2]]\n  E: [[0, 1], [1, 0]]\n"
         "  constraints: [floor, wall]\n" +
         friction;
}

TEST(FrictionYaml, ByIndexAndByName) {
  const mech::Model m =
      parse_model(model("  friction:\n    - {contact: 1, tangent: [0, 1], mu: 0.5}\n"
                        "    - {contact: floor, tangent: [1, 0.25], mu: 0}\n"),
                  "ok.yaml");
  const auto& f = m.mechanical->friction;
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].contact, 1);
  EXPECT_EQ(Eigen::VectorXd(f[0].tangent), Eigen::Vector2d(0, 1));
  EXPECT_EQ(f[0].mu, 0.5);
  EXPECT_EQ(f[1].contact, 0);
  EXPECT_EQ(Eigen::VectorXd(f[1].tangent), Eigen::Vector2d(1, 0.25));
  EXPECT_EQ(f[1].mu, 0.0);
}

TEST(FrictionYaml, WrittenBackAndReadAgain) {
  const mech::Model m = parse_model(
      model("  friction:\n    - {contact: wall, tangent: [0.1, -3], mu: 0.75}\n"), "ok.yaml");
  const std::string text = model_yaml(m);
  EXPECT_NE(text.find("  friction:\n    - {contact: 1, tangent: [0.1, -3], mu: 0.75}\n"),
            std::string::npos)
      << text;
  const mech::Model back = parse_model(text, "back.yaml");
  ASSERT_EQ(back.mechanical->friction.size(), 1u);
  EXPECT_EQ(back.mechanical->friction[0].contact, 1);
  EXPECT_EQ(Eigen::VectorXd(back.mechanical->friction[0].tangent), Eigen::Vector2d(0.1, -3));
  EXPECT_EQ(back.mechanical->friction[0].mu, 0.75);
}

// A moving surface (a belt): `velocity`, default 0, read and written back.
TEST(FrictionYaml, SurfaceVelocity) {
  const mech::Model m = parse_model(
      model("  friction:\n    - {contact: floor, tangent: [1, 0], mu: 0.1, velocity: -0.5}\n"
            "    - {contact: wall, tangent: [0, 1], mu: 0.1}\n"),
      "ok.yaml");
  EXPECT_EQ(m.mechanical->friction[0].velocity, -0.5);
  EXPECT_EQ(m.mechanical->friction[1].velocity, 0.0);
  // The sliding velocity is relative to the surface.
  EXPECT_EQ(m.mechanical->friction[0].sliding(Eigen::Vector2d(2, 7)), 2.5);
  const std::string text = model_yaml(m);
  EXPECT_NE(text.find("{contact: 0, tangent: [1, 0], mu: 0.1, velocity: -0.5}\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("{contact: 1, tangent: [0, 1], mu: 0.1}\n"), std::string::npos) << text;
  EXPECT_EQ(parse_model(text, "back.yaml").mechanical->friction[0].velocity, -0.5);
  EXPECT_NE(error_of(model("  friction:\n    - {contact: 0, tangent: [1, 0], mu: 0.1, velocity: "
                           ".nan}\n"))
                .find("mechanical.friction[0].velocity"),
            std::string::npos);
}

TEST(FrictionYaml, WithoutFrictionTheWrittenModelIsUnchanged) {
  const mech::Model m = parse_model(model(""), "ok.yaml");
  EXPECT_FALSE(m.mechanical->has_friction());
  EXPECT_EQ(model_yaml(m).find("friction"), std::string::npos);
}

TEST(FrictionYaml, BadEntriesNameTheEntryAndValue) {
  const auto one = [](const std::string& entry) {
    return error_of(model("  friction:\n    - " + entry + "\n"));
  };
  EXPECT_EQ(one("{contact: 0, tangent: [1, 0], mu: -0.1}"),
            "bad.yaml: mechanical.friction[0].mu: must be >= 0 (got -0.1)");
  EXPECT_EQ(one("{contact: 0, tangent: [1, 0, 0], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangent: expected 2 entries (N = 2 coordinates, "
            "from M) (got 3)");
  EXPECT_EQ(one("{contact: 2, tangent: [1, 0], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].contact: expected a whole number in [0, 2) (got "
            "'2')");
  EXPECT_EQ(one("{contact: roof, tangent: [1, 0], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].contact: no constraint named 'roof' (the "
            "constraints: floor, wall)");
  EXPECT_EQ(one("{contact: 0, tangent: [0, 0], mu: 0.1}"),
            "bad.yaml: mechanical.friction[0].tangent: all zero (it measures no sliding)");
  EXPECT_NE(one("{contact: 0, tangent: [1, .nan], mu: 0.1}").find("mechanical.friction[0].tangent"),
            std::string::npos);
  EXPECT_NE(one("{contact: 0, tangent: [1, 0], mu: .inf}").find("mechanical.friction[0].mu"),
            std::string::npos);
  EXPECT_EQ(one("{contact: 0, tangent: [1, 0]}"), "bad.yaml: mechanical.friction[0].mu: missing");
  EXPECT_NE(one("{contact: 0, tangent: [1, 0], mu: 1, muu: 2}").find("muu"), std::string::npos);
  EXPECT_EQ(error_of(model("  friction:\n    - {contact: 0, tangent: [1, 0], mu: 0.1}\n"
                           "    - {contact: floor, tangent: [1, 0], mu: 0.2}\n")),
            "bad.yaml: mechanical.friction[1].contact: contact 0 ('floor') already has friction "
            "(mechanical.friction[0])");
}

// The library's check, for models built in code (sim::check_run calls it).
TEST(FrictionModelCheck, OutOfRangeContactInCode) {
  mech::MechanicalModel m;
  m.M = Eigen::MatrixXd::Identity(2, 2).sparseView();
  m.E = Eigen::MatrixXd::Identity(2, 2).sparseView();
  mech::fill_defaults(m);
  m.friction.push_back({-1, Eigen::Vector2d(1, 0), 0.1});
  const auto p = mech::check_mechanical(m);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->field + ": " + p->what,
            "mechanical.friction[0].contact: contact -1 out of range (k = 2 constraints, 0-based)");
}

}  // namespace
}  // namespace lcsim::io
