// Internal to src/bullet: the Featherstone btMultiBody of a URDF
// (multibody.cpp), shared by the mass-matrix cross-check and the multibody
// scene (multibody_world.cpp).
#pragma once

#include <BulletDynamics/Featherstone/btMultiBody.h>

#include <lcsim/scene/urdf.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace urdf {
class ModelInterface;
}

namespace lcsim::bullet {

struct UrdfMultiBody {
  std::unique_ptr<btMultiBody> body;
  std::vector<int> coordinate;  // Bullet link i -> its joint's index in `joints`
  std::vector<int> link;        // index in `joints` -> Bullet link
  // Bullet's base frame in the root link's frame: the identity for a fixed
  // base; a floating base's centre of mass in principal axes.
  btTransform root_to_base = btTransform::getIdentity();
  std::map<std::string, int> owner;                 // URDF link -> Bullet link (-1: the base)
  std::map<std::string, btTransform> link_in_body;  // URDF link frame in its Bullet link's frame
};

// A fixed-base btMultiBody (base at the URDF root, identity pose) with one
// link per simulated joint in `joints` (prismatic, else revolute: continuous
// joints too), every other joint frozen at q0 (positions by joint name; a
// mimic not named at a q_leader + b; 0 otherwise) and its child merged into
// the parent body (mass, centre of mass and inertia combined, principal axes
// by Bullet's Jacobi diagonalisation). Links sit at the COM in principal
// axes; a body without mass gets a 1e-9 speck at its pivot
// (give_massless_bodies_a_speck in multibody.cpp). Joint positions set to
// q0, velocities 0, damping 0; everything else at Bullet's defaults.
// std::invalid_argument if a simulated joint is not in the tree, or no
// simulated body has mass.
// `base` places the root: fixed at base.pose (the identity by default, the
// tree as above), or floating: Bullet's base is then the root link with every
// link fixed or frozen to it (its mass and inertia, at its centre of mass in
// principal axes: root_to_base), at base.pose; std::invalid_argument when
// that body has no mass.
UrdfMultiBody build_urdf_multibody(const urdf::ModelInterface& model,
                                   const std::vector<std::string>& joints,
                                   const std::map<std::string, double>& q0,
                                   const scene::BasePose& base = {});

}  // namespace lcsim::bullet
