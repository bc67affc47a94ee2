#include <lcsim/mech/mech.hpp>
#include <stdexcept>
#include <vector>

namespace lcsim::mech {

Model model_of(MechanicalModel m, const std::string& name) {
  fill_defaults(m);
  Model model;
  model.name = name;
  model.mechanical = std::move(m);
  return model;
}

Model spring_stop_model(double k, double s, double e) {
  MechanicalModel m;
  m.M.resize(1, 1);
  m.M.insert(0, 0) = 1.0;
  m.K.resize(1, 1);
  if (k != 0.0) m.K.insert(0, 0) = k;
  m.E = m.M;
  m.g = VectorXd::Constant(1, s);
  m.restitution = VectorXd::Constant(1, e);
  return model_of(std::move(m), "spring_stop");
}

Model ball_model(double e, double g) {
  MechanicalModel m;
  m.M.resize(1, 1);
  m.M.insert(0, 0) = 1.0;
  m.E = m.M;
  m.f = VectorXd::Constant(1, -g);
  m.restitution = VectorXd::Constant(1, e);
  return model_of(std::move(m), "ball");
}

namespace {
// The §3.7 carts without constraints: unit masses, K = [2 -1; -1 1].
MechanicalModel two_carts() {
  MechanicalModel m;
  m.M.resize(2, 2);
  m.M.setIdentity();
  const Eigen::Matrix2d K{{2.0, -1.0}, {-1.0, 1.0}};
  m.K = K.sparseView();
  m.coordinates = {"x1", "x2"};
  return m;
}
}  // namespace

Model two_carts_model(bool hook) {
  MechanicalModel m = two_carts();
  const Eigen::MatrixXd E = hook ? Eigen::MatrixXd{{1.0, 0.0}, {1.0, -1.0}}  // stop, hook
                                 : Eigen::MatrixXd{{1.0, 0.0}};              // stop
  m.E = E.sparseView();
  m.constraints =
      hook ? std::vector<std::string>{"stop", "hook"} : std::vector<std::string>{"stop"};
  fill_defaults(m);
  Model model;
  model.name = hook ? "two_carts_hook" : "two_carts";
  model.source = "generated two carts";
  model.mechanical = std::move(m);
  return model;
}

Model two_carts_model(const Eigen::MatrixXd& E, const Eigen::VectorXd& g) {
  if (E.cols() != 2) throw std::invalid_argument("two_carts_model: E needs 2 columns");
  MechanicalModel m = two_carts();
  m.E = E.sparseView();
  m.g = g;
  Model model = model_of(std::move(m), "two_carts_rows");
  model.source = "generated two carts";
  return model;
}

Model chain_model(const ChainSpec& spec) {
  const int n = spec.n;
  if (n < 1) throw std::invalid_argument("chain_model: n must be >= 1");
  using T = Eigen::Triplet<double>;
  MechanicalModel m;
  m.M.resize(n, n);
  m.M.setIdentity();
  std::vector<T> k;
  k.reserve(3 * static_cast<std::size_t>(n));
  if (spec.wall_spring) k.emplace_back(0, 0, 1.0);
  for (int i = 0; i + 1 < n; ++i) {  // summed by setFromTriplets
    k.emplace_back(i, i, 1.0);
    k.emplace_back(i + 1, i + 1, 1.0);
    k.emplace_back(i, i + 1, -1.0);
    k.emplace_back(i + 1, i, -1.0);
  }
  m.K.resize(n, n);
  m.K.setFromTriplets(k.begin(), k.end());
  m.K.prune(0.0);  // n = 1 without a wall: nothing
  const int rows = (spec.stops ? n : 0) + (spec.hooks ? n - 1 : 0);
  std::vector<T> e;
  m.g.resize(rows);
  int r = 0;
  if (spec.stops)
    for (int i = 0; i < n; ++i, ++r) {
      e.emplace_back(r, i, 1.0);
      m.g(r) = 1.0;
      m.constraints.push_back("stop" + std::to_string(i));
    }
  if (spec.hooks)
    for (int i = 0; i + 1 < n; ++i, ++r) {
      e.emplace_back(r, i, 1.0);
      e.emplace_back(r, i + 1, -1.0);
      m.g(r) = kChainHookGap;
      m.constraints.push_back("hook" + std::to_string(i));
    }
  m.E.resize(rows, n);
  m.E.setFromTriplets(e.begin(), e.end());
  fill_defaults(m);

  Model model;
  model.name = "chain" + std::to_string(n);
  model.source = "generated chain";
  model.initial.resize(2 * n);
  for (int i = 0; i < n; ++i) {
    model.initial(i) = 0.1 * (i % 3);
    model.initial(n + i) = -1.0;
  }
  model.t_end = 10.0;
  model.mechanical = std::move(m);
  return model;
}

}  // namespace lcsim::mech
