// LCP problem files (`lcsim lcp`, lcsim/io/lcp_file.hpp): M and q, through
// the YAML reading helpers (lcsim/io/yaml.hpp).
#include <lcsim/io/lcp_file.hpp>
#include <lcsim/io/yaml.hpp>

namespace lcsim::io {

using yaml::dims;
using yaml::expect_size;
using yaml::fail;
using yaml::Keys;
using yaml::load;
using yaml::mapping;
using yaml::matrix;
using yaml::vector;

LcpProblem load_lcp(const std::filesystem::path& path) {
  const std::string source = path.string();
  const YAML::Node root = load(read_file(path), source);
  if (root.IsNull() || !root.IsDefined())
    throw InputError(source + ": empty file (expected `M` and `q`)");
  const Keys keys = mapping(root, source, "", {"name", "M", "q"});
  for (const char* k : {"M", "q"})
    if (!keys.count(k)) fail(source, k, "missing (an LCP file gives M and q)");
  LcpProblem p;
  p.M = matrix(keys.at("M"), source, "M", 0);
  if (p.M.rows() == 0) fail(source, "M", "empty");
  if (p.M.rows() != p.M.cols())
    fail(source, "M", "expected a square matrix (got " + dims(p.M) + ")");
  p.q = vector(keys.at("q"), source, "q");
  expect_size(p.q, p.M.rows(), source, "q", "(k, from M)");
  return p;
}

}  // namespace lcsim::io
