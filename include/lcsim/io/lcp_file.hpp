// LCP problem files (`lcsim lcp`): M and q.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <lcsim/io/input_error.hpp>

namespace lcsim::io {

struct LcpProblem {
  Eigen::MatrixXd M;
  Eigen::VectorXd q;
};
// `M` (list of rows) and `q` (list), square and matching, finite.
LcpProblem load_lcp(const std::filesystem::path& path);

}  // namespace lcsim::io
