// A scene's `base:` key: where the URDF's root link sits in the world,
// fixed (at a pose) or floating (six coordinates about a reference pose).
#include <urdf_model/model.h>

#include <Eigen/Geometry>
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::describe;
using io::yaml::fail;

namespace {

// `pose: {xyz: [x, y, z], rpy: [roll, pitch, yaw]}` (m, rad; URDF's rpy:
// R = Rz(yaw) Ry(pitch) Rx(roll)); each part defaults to zeros.
Eigen::Isometry3d read_pose(const YAML::Node& n, const std::string& source,
                            const std::string& key) {
  const Keys pk = io::yaml::mapping(n, source, key, {"xyz", "rpy"});
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  if (pk.count("xyz")) X.translation() = vector3(pk.at("xyz"), source, key + ".xyz", "m");
  if (pk.count("rpy")) {
    const Eigen::Vector3d r = vector3(pk.at("rpy"), source, key + ".rpy", "rad");
    X.linear() = (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
  }
  return X;
}

}  // namespace

BasePose read_base(const Keys& keys, const std::string& source, const SceneUrdf& urdf) {
  BasePose base;
  base.name = urdf.model->getName();
  if (!keys.count("base")) return base;
  const YAML::Node& n = keys.at("base");
  std::string type;
  if (n.IsScalar()) {
    type = n.Scalar();
  } else {
    const Keys bk = io::yaml::mapping(n, source, "base", {"type", "pose", "name"});
    if (!bk.count("type")) fail(source, "base.type", "missing (fixed or floating)");
    type = name_of(bk.at("type"), source, "base.type");
    if (bk.count("pose")) base.pose = read_pose(bk.at("pose"), source, "base.pose");
    if (bk.count("name")) base.name = name_of(bk.at("name"), source, "base.name");
  }
  if (type != "fixed" && type != "floating")
    fail(source, n.IsScalar() ? "base" : "base.type",
         "expected fixed or floating (got " + describe(n.IsScalar() ? n : n["type"]) + ")");
  base.floating = type == "floating";
  if (base.floating && base.name.empty())
    fail(source, "base.name", "the URDF's robot has no name: give the base one");
  for (const std::string& c : base_coordinates(base))
    if (urdf.model->getJoint(c))
      fail(source, "base",
           "coordinate '" + c + "' is also the name of a joint in " + urdf.path +
               " (give the base another name: base.name)");
  return base;
}

}  // namespace lcsim::scene
