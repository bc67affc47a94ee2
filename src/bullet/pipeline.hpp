// Internal to src/bullet: the parts every Bullet scene owns (the rigid
// bodies of world.cpp, the multibody of multibody_world.cpp, the scene of
// bodies of bodies_world.cpp, the box of friction_box.cpp): its collision
// configuration, dispatcher, broadphase, constraint solver and dynamics
// world, the base of each scene's world.
#pragma once

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionDispatch/btDefaultCollisionConfiguration.h>
#include <BulletDynamics/MLCPSolvers/btMLCPSolverInterface.h>

#include <memory>

namespace lcsim::bullet {

// Members in construction order: a scene's own members (bodies,
// constraints, colliders), destroyed first, then the world -> solver ->
// (the MLCP solver's) -> broadphase -> dispatcher -> config.
template <class Solver, class DynamicsWorld>
struct Pipeline {
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btMLCPSolverInterface> mlcp;  // the solver's own, when it is an MLCP's
  std::unique_ptr<Solver> solver;
  std::unique_ptr<DynamicsWorld> world;
};

}  // namespace lcsim::bullet
