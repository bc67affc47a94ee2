// A scene's floating base and its contacts against world planes in Bullet's
// btMultiBody (multibody_world.cpp builds the world; this file maps the
// floating base's coordinates and makes the contact colliders).
//
// The floating base. lcsim's six coordinates are the root link origin p
// (m, world) and a rotation vector r (rad, world axes) with orientation
// exp([r]x) R0; the angular velocity is omega = J_l(r) r', J_l the left
// Jacobian of SO(3) (docs/contacts.md). Bullet's base is the root body at its
// centre of mass c in principal axes (UrdfMultiBody::root_to_base), with the
// world-frame velocity of c and omega. So v_c = p' + omega x (c - p).
//
// The contacts. Each contact point of the scene (scene::ContactFrame: a point
// in its link's frame with a radius) is a sphere of that radius in a
// btCompoundShape on the Bullet link that carries the URDF link: a box's
// corners are spheres of radius 0 (points), a sphere primitive its sphere, a
// capsule its two cap spheres, a cylinder its 16 rim points, explicit points
// as given. Against a plane these are exactly the geometry lcsim's rows
// describe (a convex box touches a plane first at a corner; docs/contacts.md
// states the cylinder's rim approximation), so Bullet and lcsim model the
// same contacts and differ only in the dynamics (nonlinear rigid bodies,
// Bullet's step) and in Bullet's contact solver.
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/scene/so3.hpp>
#include <map>
#include <stdexcept>
#include <string>

#include "bullet/multibody_scene.hpp"
#include "bullet/urdf_multibody.hpp"

namespace lcsim::bullet {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;

btVector3 bt(const Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
Vector3d eig(const btVector3& v) { return Vector3d(v.x(), v.y(), v.z()); }

btMatrix3x3 bt(const Matrix3d& R) {
  return btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1),
                     R(2, 2));
}
Matrix3d eig(const btMatrix3x3& R) {
  Matrix3d out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = R[i][j];
  return out;
}

// A dispatcher whose manifolds keep their points up to `threshold` apart.
class ThresholdDispatcher : public btCollisionDispatcher {
 public:
  ThresholdDispatcher(btCollisionConfiguration* config, double threshold)
      : btCollisionDispatcher(config), threshold_(threshold) {}
  btPersistentManifold* getNewManifold(const btCollisionObject* b0,
                                       const btCollisionObject* b1) override {
    btPersistentManifold* m = btCollisionDispatcher::getNewManifold(b0, b1);
    m->setContactBreakingThreshold(threshold_);
    return m;
  }

 private:
  double threshold_;
};

}  // namespace

void set_floating_base(btMultiBody& b, const UrdfMultiBody& mb, const scene::BasePose& base,
                       const Vector6d& q, const Vector6d& v) {
  const Vector3d p = q.head<3>(), r = q.tail<3>();
  const Matrix3d R = scene::exp_so3(r) * base.pose.linear();
  const btTransform Tb = btTransform(bt(R), bt(p)) * mb.root_to_base;
  const Vector3d omega = scene::left_jacobian(r) * v.tail<3>();
  const Vector3d c = eig(Tb.getOrigin());
  b.setBaseWorldTransform(Tb);
  b.setBaseVel(bt(Vector3d(v.head<3>() + omega.cross(c - p))));
  b.setBaseOmega(bt(omega));
}

void get_floating_base(const btMultiBody& b, const UrdfMultiBody& mb, const scene::BasePose& base,
                       Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v) {
  const btTransform Tb = b.getBaseWorldTransform();
  const btTransform Troot = Tb * mb.root_to_base.inverse();
  const Vector3d p = eig(Troot.getOrigin()), c = eig(Tb.getOrigin());
  const Vector3d r = scene::log_so3(eig(Troot.getBasis()) * base.pose.linear().transpose());
  const Vector3d omega = eig(b.getBaseOmega());
  q.head<3>() = p;
  q.tail<3>() = r;
  v.head<3>() = eig(b.getBaseVel()) + omega.cross(p - c);
  v.tail<3>() = scene::left_jacobian(r).lu().solve(omega);
}

void add_floating_base_force(btMultiBody& b, const UrdfMultiBody& mb, const scene::BasePose& base,
                             const Vector6d& q, const Vector6d& Q) {
  (void)base;
  const Vector3d p = q.head<3>();
  const Vector3d F = Q.head<3>();
  const Vector3d tau = scene::left_jacobian(q.tail<3>()).transpose().lu().solve(Q.tail<3>());
  const Vector3d c = eig(b.getBaseWorldTransform().getOrigin());
  (void)mb;
  b.addBaseForce(bt(F));
  b.addBaseTorque(bt(Vector3d(tau + (p - c).cross(F))));
}

namespace {

// Each contact row's mu (0 without friction) and whether any has friction.
std::vector<double> row_friction(const mech::MechanicalModel& m, bool& any) {
  std::vector<double> mu(static_cast<std::size_t>(m.num_constraints()), 0.0);
  any = m.has_friction();
  for (const mech::FrictionalContact& f : m.friction)
    mu[static_cast<std::size_t>(f.contact)] = f.mu;
  return mu;
}

}  // namespace

std::string link_friction_error(const scene::Scene& setup, const mech::MechanicalModel& m) {
  bool any = false;
  const std::vector<double> mu_of_row = row_friction(m, any);
  std::map<std::string, const scene::ContactFrame*> first_of;  // URDF link -> its first contact
  for (const scene::ContactFrame& cf : setup.contacts) {
    const auto [first, fresh] = first_of.emplace(cf.point.link, &cf);
    const double mu = mu_of_row[static_cast<std::size_t>(cf.row)];
    const double mu0 = mu_of_row[static_cast<std::size_t>(first->second->row)];
    if (!fresh && mu != mu0)
      return "contact '" + cf.point.name + "' has friction mu = " + short_number(mu) +
             " but contact '" + first->second->point.name + "' of the same link '" + cf.point.link +
             "' has mu = " + short_number(mu0) +
             ": Bullet's friction is per collider (one mu per link)";
  }
  return "";
}

ContactColliders make_contact_colliders(const scene::Scene& setup, const UrdfMultiBody& mb,
                                        const mech::MechanicalModel& m) {
  ContactColliders out;
  const std::vector<double> mu_of_row = row_friction(m, out.friction);
  std::map<int, std::string> first_of;  // Bullet link -> its first contact's name
  for (const scene::ContactFrame& cf : setup.contacts) {
    const auto own = mb.owner.find(cf.point.link);
    if (own == mb.owner.end())
      throw std::invalid_argument("bullet: contact '" + cf.point.name + "': link '" +
                                  cf.point.link + "' is not in Bullet's multibody");
    auto& shape = out.shape_of[own->second];
    if (!shape) {
      auto compound = std::make_unique<btCompoundShape>(/*enableDynamicAabbTree=*/false);
      compound->setMargin(0.0);
      shape = compound.get();
      out.shapes.push_back(std::move(compound));
    }
    auto sphere = std::make_unique<btSphereShape>(cf.point.radius);
    const btTransform at = mb.link_in_body.at(cf.point.link) *
                           btTransform(btMatrix3x3::getIdentity(), bt(Vector3d(cf.point.local)));
    auto& compound = static_cast<btCompoundShape&>(*shape);
    out.row_of[{own->second, compound.getNumChildShapes()}] = static_cast<int>(cf.row);
    out.t1_of[static_cast<int>(cf.row)] = cf.tangent1;
    out.t2_of[static_cast<int>(cf.row)] = cf.tangent2;
    compound.addChildShape(at, sphere.get());
    out.shapes.push_back(std::move(sphere));
    double& e = out.restitution_of[own->second];
    e = std::max(e, m.restitution(static_cast<int>(cf.row)));
    const double mu = mu_of_row[static_cast<std::size_t>(cf.row)];
    if (const auto [first, fresh] = first_of.emplace(own->second, cf.point.name); fresh)
      out.friction_of[own->second] = mu;
    else if (out.friction_of[own->second] != mu)
      throw std::invalid_argument("bullet: contact '" + cf.point.name +
                                  "' has friction mu = " + short_number(mu) + " but contact '" +
                                  first->second + "' of the same link '" + cf.point.link +
                                  "' has mu = " + short_number(out.friction_of[own->second]) +
                                  ": Bullet's friction is per collider (one mu per link)");
    ++out.rows;
  }
  for (const scene::Plane& pl : setup.planes) {
    auto shape = std::make_unique<btStaticPlaneShape>(bt(pl.normal), pl.normal.dot(pl.point));
    auto obj = std::make_unique<btCollisionObject>();
    obj->setCollisionShape(shape.get());
    obj->setRestitution(1.0);                    // Bullet multiplies it with the link's
    obj->setFriction(out.friction ? 1.0 : 0.0);  // so does it the friction
    obj->setRollingFriction(0.0);
    obj->setSpinningFriction(0.0);
    out.shapes.push_back(std::move(shape));
    out.planes.push_back(std::move(obj));
  }
  return out;
}

namespace {

// Calls visit(row, pt, sign) for each contact point of the dispatcher's
// manifolds between one link collider and another object that is a row of
// E in c (by the link's compound child), manifold by manifold: sign is 1
// when the link is the manifold's body A, -1 when it is body B.
template <class Visit>
void for_each_contact_row(btCollisionDispatcher& d, const ContactColliders& c, Visit visit) {
  for (int i = 0; i < d.getNumManifolds(); ++i) {
    const btPersistentManifold* pm = d.getManifoldByIndexInternal(i);
    const auto* l0 = btMultiBodyLinkCollider::upcast(pm->getBody0());
    const auto* l1 = btMultiBodyLinkCollider::upcast(pm->getBody1());
    const btMultiBodyLinkCollider* link = l0 ? l0 : l1;
    if (!link || (l0 && l1)) continue;
    for (int j = 0; j < pm->getNumContacts(); ++j) {
      const btManifoldPoint& pt = pm->getContactPoint(j);
      const auto row = c.row_of.find({link->m_link, l0 ? pt.m_index0 : pt.m_index1});
      if (row != c.row_of.end()) visit(row->second, pt, l0 ? 1.0 : -1.0);
    }
  }
}

}  // namespace

void contact_impulses(btCollisionDispatcher& d, const ContactColliders& c,
                      Eigen::VectorXd& impulse) {
  for_each_contact_row(d, c, [&](int row, const btManifoldPoint& pt, double /*sign*/) {
    impulse(row) += pt.m_appliedImpulse;
  });
}

void contact_friction_impulses(btCollisionDispatcher& d, const ContactColliders& c,
                               Eigen::VectorXd& t1, Eigen::VectorXd& t2) {
  t1.setZero();
  t2.setZero();
  for_each_contact_row(d, c, [&](int row, const btManifoldPoint& pt, double sign) {
    const Vector3d f = sign * (pt.m_appliedImpulseLateral1 * eig(pt.m_lateralFrictionDir1) +
                               pt.m_appliedImpulseLateral2 * eig(pt.m_lateralFrictionDir2));
    t1(row) += c.t1_of.at(row).dot(f);
    t2(row) += c.t2_of.at(row).dot(f);
  });
}

std::unique_ptr<btCollisionDispatcher> make_dispatcher(btCollisionConfiguration* config,
                                                       double threshold) {
  return std::make_unique<ThresholdDispatcher>(config, threshold);
}

}  // namespace lcsim::bullet
