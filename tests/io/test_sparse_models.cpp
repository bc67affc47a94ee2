// Sparse model files (docs/model-format.md): the three spellings of a matrix
// give the same model, their errors name the key and the value, and
// io::model_yaml writes any mechanical model so that parse_model reads it
// back exactly, in O(nnz) bytes.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "io/io.hpp"

namespace lcsim::io {
namespace {

using Eigen::MatrixXd;

std::string error_of(const std::string& yaml) {
  try {
    parse_model(yaml, "bad.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

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
  EXPECT_EQ(a.M.toDense(), b.M.toDense());
  EXPECT_EQ(a.D.toDense(), b.D.toDense());
  EXPECT_EQ(a.K.toDense(), b.K.toDense());
  EXPECT_EQ(a.E.toDense(), b.E.toDense());
  EXPECT_EQ(a.g, b.g);
  EXPECT_EQ(a.f, b.f);
  EXPECT_EQ(a.restitution, b.restitution);
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
