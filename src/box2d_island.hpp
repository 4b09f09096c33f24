#pragma once
// Internal: shared by the swim (physics.cpp) and development (development.cpp) worlds.
#include <vector>

class b2World;
class b2Body;

namespace animat {

/// Puts a and b in the same Box2D island with a friction joint of zero maximum force and torque.
void link_bodies(b2World& world, b2Body* a, b2Body* b);

/// Joins the bodies into one Box2D island with a chain of zero-force friction joints, so that
/// Box2D pays its per-island cost once per step instead of once per cell. The joints apply no
/// impulse: velocities and positions are bitwise those of unlinked bodies (tests/cpp/test_physics).
void link_into_one_island(b2World& world, const std::vector<b2Body*>& bodies);

}  // namespace animat
