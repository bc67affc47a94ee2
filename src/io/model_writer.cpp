// io::model_yaml: mechanical models as YAML (docs/model-format.md).
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <sstream>
#include <stdexcept>

namespace lcsim::io {

namespace {

constexpr Eigen::Index kDenseEntriesMax = 64;

std::string list(const VectorXd& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + format_number(v(i));
  return s + "]";
}

// Names quoted by yaml-cpp's emitter where YAML needs it.
std::string names(const std::vector<std::string>& v) {
  YAML::Emitter e;
  e << YAML::Flow << v;
  return e.c_str();
}

bool diagonal(const mech::SparseMatrix& m) {
  if (m.rows() != m.cols()) return false;
  for (Eigen::Index j = 0; j < m.outerSize(); ++j)
    for (mech::SparseMatrix::InnerIterator it(m, j); it; ++it)
      if (it.row() != j && it.value() != 0.0) return false;
  return true;
}

void put_matrix(std::ostringstream& out, const char* key, const mech::SparseMatrix& m) {
  out << "  " << key << ":";
  if (m.rows() * m.cols() <= kDenseEntriesMax) {
    const Eigen::MatrixXd d = m.toDense();
    if (d.rows() == 0) {
      out << " []\n";
      return;
    }
    out << "\n";
    for (Eigen::Index i = 0; i < d.rows(); ++i)
      out << "    - " << list(d.row(i).transpose()) << "\n";
    return;
  }
  if (diagonal(m)) {
    out << " {diagonal: " << list(m.diagonal()) << "}\n";
    return;
  }
  out << "\n    rows: " << m.rows() << "\n    cols: " << m.cols() << "\n    entries:\n";
  for (Eigen::Index j = 0; j < m.outerSize(); ++j)
    for (mech::SparseMatrix::InnerIterator it(m, j); it; ++it)
      if (it.value() != 0.0)
        out << "      - [" << it.row() << ", " << j << ", " << format_number(it.value()) << "]\n";
}

}  // namespace

std::string model_yaml(const mech::Model& model, const std::string& header) {
  if (!model.is_mechanical())
    throw std::invalid_argument("io::model_yaml: '" + model.name +
                                "' is an lcs: model; only mechanical models are written");
  const mech::MechanicalModel& m = *model.mechanical;
  if (m.has_inputs())  // not written: a copy without them would be another model
    throw std::invalid_argument(
        "io::model_yaml: '" + model.name +
        "' has inputs (docs/inputs.md); models with inputs are not written");
  std::ostringstream out;
  std::istringstream h(header);
  for (std::string line; std::getline(h, line);) out << "# " << line << "\n";
  out << "name: " << model.name << "\nmechanical:\n";
  put_matrix(out, "M", m.M);
  if (m.D.norm() > 0.0) put_matrix(out, "D", m.D);
  if (m.K.norm() > 0.0) put_matrix(out, "K", m.K);
  if (m.num_constraints() > 0) {
    put_matrix(out, "E", m.E);
    out << "  g: " << list(m.g) << "\n";
    if (!m.restitution.isZero(0.0)) out << "  restitution: " << list(m.restitution) << "\n";
    out << "  constraints: " << names(m.constraints) << "\n";
  }
  if (!m.f.isZero(0.0)) out << "  f: " << list(m.f) << "\n";
  if (m.has_friction()) {
    out << "  friction:\n";
    for (const mech::FrictionalContact& c : m.friction)
      out << "    - {contact: " << c.contact
          << (c.is_3d() ? ", tangents: [" + list(VectorXd(c.tangent)) + ", " +
                              list(VectorXd(c.tangent2)) + "]" +
                              (c.edges > 0 ? ", d: " + std::to_string(c.edges) : std::string())
                        : ", tangent: " + list(VectorXd(c.tangent)))
          << ", mu: " << format_number(c.mu) << (c.world_frame ? ", frame: world" : "")
          << (c.velocity != 0.0 ? ", velocity: " + format_number(c.velocity) : std::string())
          << "}\n";
  }
  if (m.cone_edges != mech::MechanicalModel::kDefaultConeEdges)
    out << "  friction_d: " << m.cone_edges << "\n";
  out << "  coordinates: " << names(m.coordinates) << "\n";
  if (model.initial.size() > 0) out << "initial: " << list(model.initial) << "\n";
  if (std::isfinite(model.t_end)) out << "t_end: " << format_number(model.t_end) << "\n";
  return out.str();
}

}  // namespace lcsim::io
