#pragma once
// Unit primitives, tessellated once and scaled per shape by the renderer.
// Vertices lie on the true surface, so a tessellated curved surface lies at
// most r*(1 - cos(pi/N)) inside the true one (N segments around): with the
// counts below that is 5.4e-4*r for the sphere and 3.0e-4*r for the
// cylinder (0.05 mm and 0.03 mm at r = 0.1 m).
#include "tofguard/robot_model/scene_model.hpp"

namespace tofguard::robot_model {

constexpr int kSphereSegments = 80;    // around the z axis; 40 rings pole to pole
constexpr int kCylinderSegments = 80;  // around the z axis

TriangleMesh unit_box();       // edge 1, centred on the origin
TriangleMesh unit_sphere();    // radius 1, centred on the origin
TriangleMesh unit_cylinder();  // radius 1, length 1 along z, centred, capped

}  // namespace tofguard::robot_model
