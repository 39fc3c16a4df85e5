#pragma once
// The demo's objects, built in code so that `vkpose demo` needs nothing but the repository:
// a lidded cup, a gable-top carton and an industrial angle bracket. Each is a closed-looking,
// single-coloured-per-part, texture-poor object of 10-20 cm, in metres, +z up as it stands,
// its base at z = 0. None has a rotational symmetry, so ADD applies.
#include <vector>

#include <Eigen/Core>

#include "vkpose/geometry.hpp"

namespace vkpose {

/// A cup with a handle and a lid with a knob (about 13 cm across the handle, 11 cm high).
Mesh liddedCupMesh();

/// A one-litre gable-top carton: a red-banded box, a white gable roof with its sealed fin, and
/// a blue screw cap on one slope (7 x 7 x 19 cm).
Mesh gableCartonMesh();

/// A grey steel angle bracket: base plate, upright plate, a stiffening gusset and a boss
/// (10 x 6 x 7 cm).
Mesh angleBracketMesh();

/// Building blocks, exposed for tests.
namespace procedural {

/// A solid of revolution about +z: `profile` holds (radius, z) points from the axis at the
/// bottom, outwards, up and back to the axis at the top; each profile segment becomes a band
/// of `segments` quads with its own (flat along the profile, smooth around) normals.
Mesh lathe(const std::vector<Eigen::Vector2f>& profile, int segments, const Eigen::Vector3f& rgb);

/// A convex polygon (counter-clockwise in the xy plane) extruded along z from -depth/2 to
/// +depth/2, flat-shaded.
Mesh prism(const std::vector<Eigen::Vector2f>& polygon, float depth, const Eigen::Vector3f& rgb);

/// `part` moved by (R, t) and appended to `into` (vertices, normals, colours, faces).
void append(Mesh& into, const Mesh& part, const Eigen::Matrix3f& R = Eigen::Matrix3f::Identity(),
            const Eigen::Vector3f& t = Eigen::Vector3f::Zero());

}  // namespace procedural
}  // namespace vkpose
