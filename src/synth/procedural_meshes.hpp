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

/// Small bare-metal parts of a pile, as issue 51's real frames held (`vkpose demo
/// --write-parts`, assets/parts/): +z up as each stands, base at z = 0, steel grey.
/// An M6 hex nut: 10 mm across the flats, 5 mm high, a hexagonal bore (12.5 mm across).
Mesh hexNutMesh();
/// A long thin screw: an M3 shank 45 mm long under a 5.5 mm cap head (48 mm long).
Mesh capScrewMesh();
/// A nozzle: a 14 mm spigot, a 20 mm collar, a 13 mm body and a conical tip (58 mm long).
Mesh nozzleMesh();
/// A spark-plug key: a 22 mm socket tube 95 mm long with a 170 mm T-bar through its top
/// (170 mm across).
Mesh sparkPlugKeyMesh();

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
