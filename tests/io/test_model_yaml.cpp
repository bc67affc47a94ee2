// Model files: the shipped models load with their exact matrices, and every
// class of malformed model is refused with one message naming the file, the
// key and the offending value (DESIGN.md: bad input gets a clear error).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "support/model_error.hpp"
#include "support/same_model.hpp"

namespace lcsim::io {
namespace {

// Any model file, as every command reads it (matrix models and scenes).
using scene::load_model;
using scene::parse_model;

using Eigen::MatrixXd;
using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

std::string error_of(const std::string& yaml) { return test_support::model_error(yaml); }

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

// A zero row of E constrains nothing; it used to pass loading and fail at
// t = 0 with "leading row indices (inf)". Refused at load, naming the row.
TEST(ModelFileErrors, ZeroRowOfE) {
  EXPECT_EQ(error_of(kHead + "  M: [[1, 0], [0, 1]]\n  E: [[1, 0], [0, 0]]\n"),
            "bad.yaml: mechanical.E[1]: constraint 'c2' has an all-zero row (it constrains no "
            "coordinate)");
  EXPECT_EQ(error_of(kHead + "  M: [[1, 0], [0, 1]]\n  E: {rows: 2, cols: 2, entries: [[0, 1, "
                             "2]]}\n"),
            "bad.yaml: mechanical.E[1]: constraint 'c2' has an all-zero row (it constrains no "
            "coordinate)");
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

// ---- Sparse spellings (docs/model-format.md) and io::model_yaml ------------
// The three spellings of a matrix give the same model, their errors name the
// key and the value, and io::model_yaml writes any mechanical model so that
// parse_model reads it back exactly, in O(nnz) bytes.

TEST(SparseModelFile, ThreeSpellingsGiveOneModel) {
  const std::string tail =
      "  E: {rows: 2, cols: 3, entries: [[0, 0, 1], [1, 0, 1], [1, 1, -1]]}\n  g: [1, 0.5]\n";
  const mech::Model dense = parse_model(
      "name: a\nmechanical:\n  M: [[2, 0, 0], [0, 3, 0], [0, 0, 4]]\n"
      "  K: [[2, -1, 0], [-1, 2, -1], [0, -1, 1]]\n  E: [[1, 0, 0], [1, -1, 0]]\n  g: [1, 0.5]\n",
      "a.yaml");
  const mech::Model sparse = parse_model(
      "name: b\nmechanical:\n  M: {diagonal: [2, 3, 4]}\n"
      "  K: {rows: 3, cols: 3, entries: [[0, 0, 2], [0, 1, -1], [1, 0, -1], [1, 1, 2], "
      "[1, 2, -1], [2, 1, -1], [2, 2, 1]]}\n" +
          tail,
      "b.yaml");
  const mech::MechanicalModel &a = *dense.mechanical, &b = *sparse.mechanical;
  // Exact: the same integers, read by the same number parser.
  EXPECT_EQ(a.M.toDense(), b.M.toDense());
  EXPECT_EQ(a.K.toDense(), b.K.toDense());
  EXPECT_EQ(a.E.toDense(), b.E.toDense());
  EXPECT_EQ(a.g, b.g);
  // Only the non-zeros are stored, whatever the spelling.
  EXPECT_EQ(a.M.nonZeros(), 3);
  EXPECT_EQ(b.K.nonZeros(), 7);
  EXPECT_EQ(a.E.nonZeros(), 3);
  EXPECT_EQ(b.D.nonZeros(), 0);
}

TEST(SparseModelFile, ErrorsNameKeyAndValue) {
  const std::string head = "name: t\nmechanical:\n";
  EXPECT_EQ(error_of(head + "  M: {rows: 2, cols: 2, entries: [[0, 0, 1], [2, 1, 1]]}\n"),
            "bad.yaml: mechanical.M.entries[1][0]: expected a whole number in [0, 2) (got '2')");
  EXPECT_EQ(error_of(head + "  M: {rows: 1, cols: 1, entries: [[0, 0, 1], [0, 0, 1]]}\n"),
            "bad.yaml: mechanical.M.entries[1]: position (0, 0) given twice");
  EXPECT_EQ(error_of(head + "  M: {rows: 1, cols: 1, entries: [[0, 0]]}\n"),
            "bad.yaml: mechanical.M.entries[0]: expected [row, col, value] (got a list of 2 "
            "entries)");
  EXPECT_EQ(error_of(head + "  M: {rows: 1, entries: [[0, 0, 1]]}\n"),
            "bad.yaml: mechanical.M.cols: missing (a sparse matrix is {rows: R, cols: C, "
            "entries: [[row, col, value], ...]})");
  EXPECT_EQ(error_of(head + "  M: {diagonal: [1, 1], rows: 2}\n"),
            "bad.yaml: mechanical.M: a {diagonal: [...]} matrix takes no other keys (rows, cols, "
            "entries)");
  EXPECT_EQ(error_of(head + "  M: {diagonal: [1, .nan]}\n"),
            "bad.yaml: mechanical.M.diagonal[1]: not finite (got '.nan')");
  EXPECT_EQ(error_of(head + "  M: {rows: 1.5, cols: 1, entries: []}\n"),
            "bad.yaml: mechanical.M.rows: expected a whole number in [0, 1e+09) (got '1.5')");
  EXPECT_EQ(error_of(head + "  M: {diag: [1]}\n"),
            "bad.yaml: mechanical.M.diag: unknown key (expected one of rows, cols, entries, "
            "diagonal)");
  // The checks on the model itself hold for every spelling.
  EXPECT_EQ(error_of(head + "  M: {rows: 2, cols: 2, entries: [[0, 0, 1], [1, 1, 1], [0, 1, "
                            "0.5]]}\n"),
            "bad.yaml: mechanical.M: not symmetric (M[0][1] = 0.5 but M[1][0] = 0)");
  EXPECT_EQ(error_of(head + "  M: {diagonal: [1, 0]}\n"),
            "bad.yaml: mechanical.M: not positive definite (smallest eigenvalue 0, largest 1)");
  EXPECT_EQ(error_of(head + "  M: {diagonal: [1, 1]}\n  E: {rows: 1, cols: 3, entries: []}\n"),
            "bad.yaml: mechanical.E: expected 2 columns (N = 2 coordinates, from M) (got 1 x 3)");
}

// Above 1000 coordinates M is checked by sparse LDL' instead of eigenvalues.
TEST(SparseModelFile, LargeIndefiniteMassIsRefusedByItsPivots) {
  std::string yaml = "name: t\nmechanical:\n  M: {diagonal: [";
  for (int i = 0; i < 1500; ++i) yaml += std::string(i ? ", " : "") + (i == 700 ? "-1" : "1");
  yaml += "]}\n";
  EXPECT_EQ(error_of(yaml),
            "bad.yaml: mechanical.M: not positive definite (smallest LDL' pivot -1, largest 1)");
}

void expect_round_trip(const mech::Model& model) {
  const std::string text = model_yaml(model, "a header\nof two lines");
  const mech::Model back = parse_model(text, "round.yaml");
  const mech::MechanicalModel &a = *model.mechanical, &b = *back.mechanical;
  EXPECT_EQ(back.name, model.name);
  // Exact: numbers are written in shortest round-trip form.
  test_support::expect_same_matrices(a, b);
  EXPECT_EQ(a.coordinates, b.coordinates);
  EXPECT_EQ(a.constraints, b.constraints);
  EXPECT_EQ(back.initial, model.initial);
  if (std::isnan(model.t_end))  // no horizon in the model: none in the file
    EXPECT_TRUE(std::isnan(back.t_end));
  else
    EXPECT_EQ(back.t_end, model.t_end);
  EXPECT_EQ(text.rfind("# a header\n# of two lines\n", 0), 0u) << text.substr(0, 80);
}

TEST(ModelYaml, RoundTrips) {
  expect_round_trip(mech::two_carts_model(true));
  expect_round_trip(mech::chain_model({40, true, true, true}));
  // Non-integer values, damping, force, restitution, names that need quotes.
  mech::Model m = mech::two_carts_model(false);
  m.mechanical->D = (MatrixXd(2, 2) << 0.1, 0, 0, 1.0 / 3).finished().sparseView();
  m.mechanical->f = Eigen::Vector2d(-9.81, 1e-300);
  m.mechanical->restitution = Eigen::VectorXd::Constant(1, 0.7);
  m.mechanical->coordinates = {"x: one", "x #2"};
  m.initial = Eigen::Vector4d(0.1, -0.2, 1.0 / 7, 0);
  m.t_end = 2.5;
  expect_round_trip(m);
}

// The chain's file grows as its non-zeros: N = 2000 carts with stops and
// hooks in a few hundred kB (a dense file would hold 4 N^2 = 16 million
// numbers), and it loads back as the same model.
TEST(ModelYaml, ChainFileIsLinearInN) {
  const mech::Model chain = mech::chain_model({2000, true, true, true});
  const std::string text = model_yaml(chain);
  EXPECT_LT(text.size(), 200u * 2000u) << "bytes";
  const mech::Model back = parse_model(text, "chain.yaml");
  EXPECT_EQ(back.mechanical->K.nonZeros(), chain.mechanical->K.nonZeros());
  EXPECT_EQ(back.mechanical->E.nonZeros(), 2000 + 2 * 1999);
  EXPECT_EQ((back.mechanical->K - chain.mechanical->K).norm(), 0.0);
  EXPECT_EQ((back.mechanical->E - chain.mechanical->E).norm(), 0.0);
}

}  // namespace
}  // namespace lcsim::io
