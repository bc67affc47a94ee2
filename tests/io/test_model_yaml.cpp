// Model files: the shipped models load with their exact matrices, and every
// class of malformed model is refused with one message naming the file, the
// key and the offending value (DESIGN.md: bad input gets a clear error).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "io/io.hpp"

namespace lcsim::io {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

// The message of the InputError parse_model throws, or "(accepted)".
std::string error_of(const std::string& yaml) {
  try {
    parse_model(yaml, "bad.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A valid two-coordinate mechanical model; tests replace one line of it.
const std::string kHead = "name: t\nmechanical:\n";
std::string two_dof(const std::string& extra) {
  return kHead + "  M: [[1, 0], [0, 1]]\n  E: [[1, 0]]\n" + extra;
}

TEST(ShippedModels, TwoCartsMatchEq31) {
  const mech::Model model = load_model(kRobots + "two_carts.yaml");
  ASSERT_TRUE(model.is_mechanical());
  const mech::MechanicalModel& m = *model.mechanical;
  EXPECT_EQ(model.name, "two_carts");
  // Integers read from YAML are exact doubles: compare exactly.
  EXPECT_EQ(m.M.toDense(), MatrixXd::Identity(2, 2));
  EXPECT_EQ(m.K.toDense(), (MatrixXd(2, 2) << 2, -1, -1, 1).finished());
  EXPECT_EQ(m.D.toDense(), MatrixXd::Zero(2, 2));
  EXPECT_EQ(m.E.toDense(), (MatrixXd(1, 2) << 1, 0).finished());
  EXPECT_EQ(m.g, VectorXd::Zero(1));
  EXPECT_EQ(m.f, VectorXd::Zero(2));
  EXPECT_EQ(m.restitution, VectorXd::Zero(1));
  EXPECT_EQ(m.coordinates, (std::vector<std::string>{"x1", "x2"}));
  EXPECT_EQ(m.constraints, (std::vector<std::string>{"stop"}));
  EXPECT_EQ(model.t_end, 3.0);
  ASSERT_EQ(model.initial.size(), 4);

  // The thesis's rounded values (§3.7), to their 4 printed decimals.
  const VectorXd rounded = (VectorXd(4) << 0.3202, -0.4335, 0.3716, -1.0915).finished();
  EXPECT_LT((model.initial - rounded).cwiseAbs().maxCoeff(), 0.5e-4);

  // The file holds e^{-A}(0,-1,-1,0), so the free motion e^{A} maps it back to
  // (0,-1,-1,0). Tolerance 1e-14: the stored entries are within 1.5 ulp of the
  // exact values (~2.5e-16 absolute); e^{A} is orthogonal in the energy norm
  // (A has imaginary eigenvalues), so ||e^{A}||_2 <= sqrt(cond(K)) ≈ 2.62
  // amplifies that to ~7e-16, and computing e^{A} adds a few eps of |x| ≈ 1.2.
  // Together a few 1e-15; 1e-14 leaves a margin of a few, while an error in
  // the 13th significant digit of the file (e.g. a mistyped entry) fails.
  const MatrixXd A = mech::to_lcs(m).A.topLeftCorner(4, 4);
  const Eigen::Matrix4d A4 = A;
  const Eigen::Matrix4d eA = A4.exp();
  const Eigen::Vector4d x1 = eA * Eigen::Vector4d(model.initial);
  const Eigen::Vector4d expected(0, -1, -1, 0);
  EXPECT_LT((x1 - expected).cwiseAbs().maxCoeff(), 1e-14) << x1.transpose();
}

TEST(ShippedModels, TwoCartsHookIsExample383) {
  const mech::Model model = load_model(kRobots + "two_carts_hook.yaml");
  ASSERT_TRUE(model.is_mechanical());
  const mech::MechanicalModel& m = *model.mechanical;
  EXPECT_EQ(m.M.toDense(), MatrixXd::Identity(2, 2));
  EXPECT_EQ(m.K.toDense(), (MatrixXd(2, 2) << 2, -1, -1, 1).finished());
  EXPECT_EQ(m.E.toDense(), (MatrixXd(2, 2) << 1, 0, 1, -1).finished());
  EXPECT_EQ(m.g, VectorXd::Zero(2));
  EXPECT_EQ(m.constraints, (std::vector<std::string>{"stop", "hook"}));
  EXPECT_EQ(model.initial, (VectorXd(4) << 0, 0, -1, 2).finished());
  EXPECT_EQ(model.t_end, 3.0);
  // Independent constraints, feasible start: nothing about E in the notes.
  for (const auto& note : model_notes(model)) EXPECT_FALSE(contains(note, "dependent")) << note;
}

TEST(ShippedModels, Ball) {
  const mech::Model model = load_model(kRobots + "ball.yaml");
  ASSERT_TRUE(model.is_mechanical());
  const mech::MechanicalModel& m = *model.mechanical;
  EXPECT_EQ(m.M.toDense(), MatrixXd::Ones(1, 1));
  EXPECT_EQ(m.E.toDense(), MatrixXd::Ones(1, 1));
  EXPECT_EQ(m.f(0), -9.81);  // the same literal parsed the same way: exact
  EXPECT_EQ(m.restitution(0), 0.5);
  EXPECT_EQ(m.K.toDense(), MatrixXd::Zero(1, 1));
  EXPECT_EQ(model.initial, (VectorXd(2) << 1, 0).finished());
  EXPECT_EQ(model.t_end, 3.0);
}

TEST(ShippedModels, TripleIntegratorIsExample733) {
  const mech::Model model = load_model(kRobots + "triple_integrator.yaml");
  ASSERT_FALSE(model.is_mechanical());
  ASSERT_TRUE(model.lcs.has_value());
  const lcs::Lcs& s = *model.lcs;
  EXPECT_EQ(s.A, (MatrixXd(3, 3) << 0, 1, 0, 0, 0, 1, 0, 0, 0).finished());
  EXPECT_EQ(s.B, (MatrixXd(3, 1) << 0, 0, 1).finished());
  EXPECT_EQ(s.C, (MatrixXd(1, 3) << 1, 0, 0).finished());
  EXPECT_EQ(s.D, MatrixXd::Zero(1, 1));
  EXPECT_EQ(model.initial, (VectorXd(3) << 0, -1, 0).finished());
  EXPECT_EQ(model.t_end, 1.0);
  EXPECT_EQ(model.state_size(), 3);
  EXPECT_EQ(model.num_constraints(), 1);
}

TEST(ShippedModels, LcpExample) {
  const LcpProblem p = load_lcp(kRobots + "lcp_example.yaml");
  EXPECT_EQ(p.M, (MatrixXd(3, 3) << 4, 1, 0, 1, 4, 1, 0, 1, 4).finished());
  EXPECT_EQ(p.q, (VectorXd(3) << -8, -1, -4).finished());
  // The solution derived by hand in the file: z = (2, 0, 1), w = (0, 2, 0),
  // checked here in exact (integer) arithmetic.
  const VectorXd z = (VectorXd(3) << 2, 0, 1).finished();
  EXPECT_EQ(p.M * z + p.q, (VectorXd(3) << 0, 2, 0).finished());
}

TEST(ModelFile, DefaultsAndNames) {
  const mech::Model model = parse_model(two_dof(""), "ok.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  EXPECT_EQ(m.D.toDense(), MatrixXd::Zero(2, 2));
  EXPECT_EQ(m.K.toDense(), MatrixXd::Zero(2, 2));
  EXPECT_EQ(m.g, VectorXd::Zero(1));
  EXPECT_EQ(m.f, VectorXd::Zero(2));
  EXPECT_EQ(m.restitution, VectorXd::Zero(1));
  EXPECT_EQ(m.coordinates, (std::vector<std::string>{"q1", "q2"}));
  EXPECT_EQ(m.constraints, (std::vector<std::string>{"c1"}));
  EXPECT_EQ(model.initial.size(), 0);
  EXPECT_TRUE(std::isnan(model.t_end));
  EXPECT_EQ(model.source, "ok.yaml");
}

TEST(ModelFile, NameDefaultsToFileStem) {
  const mech::Model model = parse_model("mechanical:\n  M: [[2]]\n", "robots/my_model.yaml");
  EXPECT_EQ(model.name, "my_model");
}

TEST(ModelFile, NoConstraints) {
  for (const std::string e : {"", "  E: []\n"}) {
    const mech::Model model = parse_model(kHead + "  M: [[1, 0], [0, 1]]\n" + e, "free.yaml");
    const mech::MechanicalModel& m = *model.mechanical;
    EXPECT_EQ(m.num_constraints(), 0);
    EXPECT_EQ(m.E.rows(), 0);
    EXPECT_EQ(m.E.cols(), 2);
    EXPECT_EQ(m.g.size(), 0);
    EXPECT_EQ(m.restitution.size(), 0);
    EXPECT_TRUE(m.constraints.empty());
    EXPECT_EQ(mech::to_lcs(m).B.cols(), 0);
  }
}

TEST(ModelFile, DependentConstraintsAreAcceptedAndNoted) {
  // §4.6.1: E without full row rank is legal (impulses are not unique).
  const mech::Model model =
      parse_model(kHead + "  M: [[1, 0], [0, 1]]\n  E: [[1, 0], [2, 0], [0, 1]]\n", "dep.yaml");
  EXPECT_EQ(model.mechanical->num_constraints(), 3);
  bool noted = false;
  for (const auto& note : model_notes(model))
    if (contains(note, "dependent constraints") && contains(note, "rank 2 < 3")) noted = true;
  EXPECT_TRUE(noted);
}

TEST(ModelFile, InfeasibleInitialStateIsNoted) {
  const mech::Model model = parse_model(two_dof("initial: [-0.5, 0, 0, 0]\n"), "infeasible.yaml");
  bool noted = false;
  for (const auto& note : model_notes(model))
    if (contains(note, "violates constraint c1") && contains(note, "-0.5")) noted = true;
  EXPECT_TRUE(noted);
}

TEST(ModelFileErrors, NotSymmetric) {
  EXPECT_EQ(error_of(kHead + "  M: [[1, 2], [1, 3]]\n"),
            "bad.yaml: mechanical.M: not symmetric (M[0][1] = 2 but M[1][0] = 1)");
}

TEST(ModelFileErrors, NotPositiveDefinite) {
  // Eigenvalues 3 and -1.
  const std::string e = error_of(kHead + "  M: [[1, 2], [2, 1]]\n");
  EXPECT_EQ(e, "bad.yaml: mechanical.M: not positive definite (smallest eigenvalue -1, largest 3)");
  // Singular: Cholesky may pass on rounding, the eigenvalue test does not.
  const std::string s = error_of(kHead + "  M: [[0.1, 0.3], [0.3, 0.9]]\n");
  EXPECT_TRUE(contains(s, "mechanical.M: not positive definite")) << s;
  EXPECT_TRUE(contains(error_of(kHead + "  M: [[0]]\n"), "mechanical.M: not positive definite"));
}

TEST(ModelFileErrors, WrongDimensions) {
  EXPECT_EQ(error_of(two_dof("  K: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n")),
            "bad.yaml: mechanical.K: expected 2 x 2 (N = 2 coordinates, from M) (got 3 x 3)");
  EXPECT_EQ(error_of(kHead + "  M: [[1, 0], [0, 1]]\n  E: [[1, 0, 0]]\n"),
            "bad.yaml: mechanical.E: expected 2 columns (N = 2 coordinates, from M) (got 1 x 3)");
  EXPECT_EQ(error_of(two_dof("  g: [0, 0]\n")),
            "bad.yaml: mechanical.g: expected 1 entries (k = 1 constraints, from the rows of E) "
            "(got 2)");
  EXPECT_TRUE(contains(error_of(two_dof("  f: [1]\n")), "mechanical.f: expected 2 entries"));
  EXPECT_TRUE(contains(error_of(two_dof("  coordinates: [a]\n")),
                       "mechanical.coordinates: expected 2 names"));
  EXPECT_EQ(error_of(kHead + "  M: [[1, 0], [0]]\n"),
            "bad.yaml: mechanical.M: rows differ in length (row 1 has 1 entries but row 0 has 2)");
  EXPECT_EQ(error_of(kHead + "  M: [[1, 0]]\n"),
            "bad.yaml: mechanical.M: expected a square matrix (got 1 x 2)");
  EXPECT_TRUE(contains(error_of(kHead + "  M: [1, 2]\n"),
                       "bad.yaml: mechanical.M[0]: expected a matrix row as a list of numbers "
                       "(got '1')"));
  EXPECT_TRUE(contains(error_of("lcs:\n  A: [[0, 1], [0, 0]]\n  B: [[0], [1]]\n  C: [[1, 0, 0]]\n"),
                       "bad.yaml: lcs.C: expected 1 x 2"));
  EXPECT_TRUE(contains(error_of("lcs:\n  A: [[0, 1], [0, 0]]\n  B: [[1]]\n  C: [[1, 0]]\n"),
                       "bad.yaml: lcs.B: expected 2 rows"));
}

TEST(ModelFileErrors, NonFiniteAndNonNumeric) {
  EXPECT_EQ(error_of(kHead + "  M: [[.nan]]\n"),
            "bad.yaml: mechanical.M[0][0]: not finite (got '.nan')");
  EXPECT_EQ(error_of(two_dof("  f: [0, -.inf]\n")),
            "bad.yaml: mechanical.f[1]: not finite (got '-.inf')");
  EXPECT_EQ(error_of(two_dof("  K: [[1, 0], [0, .Inf]]\n")),
            "bad.yaml: mechanical.K[1][1]: not finite (got '.Inf')");
  EXPECT_EQ(error_of(two_dof("  g: [abc]\n")),
            "bad.yaml: mechanical.g[0]: not a number (got 'abc')");
  EXPECT_EQ(error_of(two_dof("t_end: .nan\n")), "bad.yaml: t_end: not finite (got '.nan')");
  EXPECT_EQ(error_of(two_dof("initial: [0, 0, nan, 0]\n")),
            "bad.yaml: initial[2]: not a number (got 'nan')");
}

TEST(ModelFileErrors, RestitutionOutsideUnitInterval) {
  EXPECT_EQ(error_of(two_dof("  restitution: [1.5]\n")),
            "bad.yaml: mechanical.restitution[0]: outside [0, 1] (got 1.5)");
  EXPECT_EQ(error_of(two_dof("  restitution: [-0.25]\n")),
            "bad.yaml: mechanical.restitution[0]: outside [0, 1] (got -0.25)");
  EXPECT_EQ(error_of(two_dof("  restitution: [1]\n")), "(accepted)");  // the bounds are legal
  EXPECT_EQ(error_of(two_dof("  restitution: [0]\n")), "(accepted)");
}

TEST(ModelFileErrors, NonPositiveHorizon) {
  EXPECT_EQ(error_of(two_dof("t_end: 0\n")), "bad.yaml: t_end: must be > 0 (got 0)");
  EXPECT_EQ(error_of(two_dof("t_end: -2.5\n")), "bad.yaml: t_end: must be > 0 (got -2.5)");
}

TEST(ModelFileErrors, WrongInitialSize) {
  EXPECT_EQ(error_of(two_dof("initial: [0, 0, 1]\n")),
            "bad.yaml: initial: expected 4 entries (the state: 2 positions q then 2 velocities "
            "v) (got 3)");
  EXPECT_TRUE(contains(error_of("lcs:\n  A: [[0]]\n  B: [[1]]\n  C: [[1]]\ninitial: [1, 2]\n"),
                       "bad.yaml: initial: expected 1 entries (the state x, n = 1) (got 2)"));
}

TEST(ModelFileErrors, UnknownKeys) {
  EXPECT_TRUE(contains(error_of(two_dof("t_ned: 3\n")),
                       "bad.yaml: t_ned: unknown key (expected one of name, mechanical, lcs, "
                       "initial, t_end)"));
  EXPECT_TRUE(contains(error_of(two_dof("  restitutoin: [0.5]\n")),
                       "bad.yaml: mechanical.restitutoin: unknown key"));
  EXPECT_TRUE(contains(error_of("lcs:\n  A: [[0]]\n  B: [[1]]\n  C: [[1]]\n  E: [[1]]\n"),
                       "bad.yaml: lcs.E: unknown key (expected one of A, B, C, D)"));
  EXPECT_EQ(error_of(two_dof("  M: [[2, 0], [0, 2]]\n")), "bad.yaml: mechanical.M: duplicate key");
}

TEST(ModelFileErrors, StructureErrors) {
  EXPECT_TRUE(contains(error_of("name: x\n"), "bad.yaml: mechanical: missing"));
  EXPECT_TRUE(contains(error_of("mechanical:\n  K: [[1]]\n"), "bad.yaml: mechanical.M: missing"));
  EXPECT_TRUE(
      contains(error_of("mechanical:\n  M: [[1]]\nlcs:\n  A: [[0]]\n  B: [[1]]\n  C: [[1]]\n"),
               "bad.yaml: mechanical, lcs: "));
  EXPECT_TRUE(contains(error_of("- 1\n- 2\n"), "bad.yaml: top level: expected a mapping"));
  EXPECT_TRUE(contains(error_of(""), "bad.yaml: empty file"));
  EXPECT_TRUE(contains(error_of("mechanical: 3\n"),
                       "bad.yaml: mechanical: expected a mapping of keys (got '3')"));
}

TEST(ModelFileErrors, MalformedYamlGivesLineAndColumn) {
  const std::string e = error_of("name: x\nmechanical:\n  M: [[1, 0], [0, 1]\n");
  EXPECT_TRUE(contains(e, "bad.yaml: malformed YAML at line ")) << e;
  EXPECT_TRUE(contains(e, ", column ")) << e;
  // Line 4 (1-based) is indented by one space, neither a key of `mechanical`
  // nor a top-level key: yaml-cpp reports it there.
  const std::string f = error_of("name: x\nmechanical:\n  M: [[1]]\n E: [[1]]\n");
  EXPECT_TRUE(contains(f, "bad.yaml: malformed YAML at line 4, column ")) << f;
}

TEST(ModelFileErrors, MissingFileNamesThePath) {
  try {
    load_model("/nonexistent/dir/model.yaml");
    FAIL() << "accepted a missing file";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/dir/model.yaml: cannot open: no such file");
  }
  EXPECT_THROW(load_lcp("/nonexistent/lcp.yaml"), InputError);
}

TEST(LcpFile, Errors) {
  const std::string dir = ::testing::TempDir();
  const auto lcp_error = [&](const std::string& text) -> std::string {
    const std::string path = dir + "/lcsim_test_lcp.yaml";
    write_file_atomic(path, text);
    try {
      load_lcp(path);
    } catch (const InputError& e) {
      return std::string(e.what()).substr(path.size());
    }
    return "(accepted)";
  };
  EXPECT_EQ(lcp_error("M: [[1, 0], [0, 1]]\nq: [1]\n"),
            ": q: expected 2 entries (k, from M) (got 1)");
  EXPECT_EQ(lcp_error("M: [[1, 0]]\nq: [1]\n"), ": M: expected a square matrix (got 1 x 2)");
  EXPECT_EQ(lcp_error("M: [[1]]\n"), ": q: missing (an LCP file gives M and q)");
  EXPECT_EQ(lcp_error("M: [[1]]\nq: [.inf]\n"), ": q[0]: not finite (got '.inf')");
  EXPECT_EQ(lcp_error("M: [[1]]\nq: [1]\nz: [0]\n"),
            ": z: unknown key (expected one of name, M, q)");
  EXPECT_EQ(lcp_error("M: [[1]]\nq: [1]\n"), "(accepted)");
}

TEST(ParseVector, ParsesCommaSeparatedNumbers) {
  const VectorXd v = parse_vector(" 1, 2.5,-3e-2 ,+4", "--x0");
  EXPECT_EQ(v, (VectorXd(4) << 1, 2.5, -3e-2, 4).finished());  // same literals: exact
  EXPECT_EQ(parse_vector("0.1", "x").size(), 1);
}

TEST(ParseVector, ErrorsNameWhatAndToken) {
  const auto err = [](const std::string& text) -> std::string {
    try {
      parse_vector(text, "--x0");
    } catch (const InputError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  EXPECT_EQ(err("1,abc,3"), "--x0: entry 1 of '1,abc,3': not a number (got 'abc')");
  EXPECT_EQ(err("1,,3"), "--x0: entry 1 of '1,,3': empty (expected comma-separated numbers)");
  EXPECT_EQ(err("1,2,"), "--x0: entry 2 of '1,2,': empty (expected comma-separated numbers)");
  EXPECT_EQ(err(""), "--x0: entry 0 of '': empty (expected comma-separated numbers)");
  EXPECT_EQ(err("nan"), "--x0: entry 0 of 'nan': not finite (got 'nan')");
  EXPECT_EQ(err("1,-inf"), "--x0: entry 1 of '1,-inf': not finite (got '-inf')");
  EXPECT_EQ(err("1.5x"), "--x0: entry 0 of '1.5x': not a number (got '1.5x')");
  EXPECT_EQ(err("1e999"), "--x0: entry 0 of '1e999': not a number (got '1e999')");
}

}  // namespace
}  // namespace lcsim::io
