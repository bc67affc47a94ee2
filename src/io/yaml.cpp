// The YAML reading helpers shared by the model, LCP and scene readers
// (lcsim/io/yaml.hpp).
#include <algorithm>
#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>

namespace lcsim::io::yaml {

void fail(const std::string& source, const std::string& key, const std::string& what) {
  throw InputError(one_line(source + ": " + key + ": " + what));
}

std::string describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Scalar:
      return "'" + one_line(n.Scalar(), 80) + "'";
    case YAML::NodeType::Sequence:
      return "a list of " + std::to_string(n.size()) + " entries";
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Null:
      return "nothing";
    default:
      return "an undefined value";
  }
}

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

YAML::Node load(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    // yaml-cpp marks are 0-based; editors count from 1.
    throw InputError(one_line(source + ": malformed YAML at line " +
                              std::to_string(e.mark.line + 1) + ", column " +
                              std::to_string(e.mark.column + 1) + ": " + e.msg));
  }
}

Keys mapping(const YAML::Node& node, const std::string& source, const std::string& key,
             const std::vector<std::string>& allowed) {
  const std::string where = key.empty() ? "top level" : key;
  if (!node.IsMap()) fail(source, where, "expected a mapping of keys (got " + describe(node) + ")");
  Keys out;
  for (const auto& kv : node) {
    if (!kv.first.IsScalar())
      fail(source, where, "keys must be plain names (got " + describe(kv.first) + ")");
    const std::string name = kv.first.Scalar();
    const std::string full = key.empty() ? name : key + "." + name;
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), name) == allowed.end())
      fail(source, full, "unknown key (expected one of " + join(allowed) + ")");
    if (out.count(name)) fail(source, full, "duplicate key");
    out.emplace(name, kv.second);
  }
  return out;
}

double number(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (!n.IsScalar()) fail(source, key, "expected a number (got " + describe(n) + ")");
  double x = 0.0;
  try {
    x = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(source, key, "not a number (got '" + one_line(n.Scalar(), 80) + "')");
  }
  if (!std::isfinite(x)) fail(source, key, "not finite (got '" + one_line(n.Scalar(), 80) + "')");
  return x;
}

Eigen::VectorXd vector(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (!n.IsSequence()) fail(source, key, "expected a list of numbers (got " + describe(n) + ")");
  Eigen::VectorXd v(static_cast<Eigen::Index>(n.size()));
  for (std::size_t i = 0; i < n.size(); ++i)
    v(static_cast<Eigen::Index>(i)) = number(n[i], source, key + "[" + std::to_string(i) + "]");
  return v;
}

Eigen::MatrixXd matrix(const YAML::Node& n, const std::string& source, const std::string& key,
                       Eigen::Index cols_if_empty) {
  if (!n.IsSequence())
    fail(source, key, "expected a matrix as a list of rows (got " + describe(n) + ")");
  const auto rows = static_cast<Eigen::Index>(n.size());
  if (rows == 0) return Eigen::MatrixXd::Zero(0, cols_if_empty);
  Eigen::Index cols = -1;
  Eigen::MatrixXd m;
  for (Eigen::Index i = 0; i < rows; ++i) {
    const YAML::Node row = n[static_cast<std::size_t>(i)];
    const std::string rkey = key + "[" + std::to_string(i) + "]";
    if (!row.IsSequence())
      fail(source, rkey,
           "expected a matrix row as a list of numbers (got " + describe(row) +
               "); write a matrix as a list of rows, e.g. [[1, 0], [0, 1]]");
    const auto c = static_cast<Eigen::Index>(row.size());
    if (cols < 0) {
      cols = c;
      m.resize(rows, cols);
    } else if (c != cols) {
      fail(source, key,
           "rows differ in length (row " + std::to_string(i) + " has " + std::to_string(c) +
               " entries but row 0 has " + std::to_string(cols) + ")");
    }
    for (Eigen::Index j = 0; j < c; ++j)
      m(i, j) =
          number(row[static_cast<std::size_t>(j)], source, rkey + "[" + std::to_string(j) + "]");
  }
  return m;
}

void expect_size(const Eigen::VectorXd& v, Eigen::Index size, const std::string& source,
                 const std::string& key, const std::string& why) {
  if (v.size() != size)
    fail(source, key,
         "expected " + std::to_string(size) + " entries " + why + " (got " +
             std::to_string(v.size()) + ")");
}

}  // namespace lcsim::io::yaml
