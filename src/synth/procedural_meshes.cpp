// The demo's objects, built from lathes, prisms, boxes and cylinders (procedural_meshes.hpp).
#include "synth/procedural_meshes.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "synth/scene.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace procedural {

namespace {
constexpr float kTwoPi = 2.f * std::numbers::pi_v<float>;

int addVertex(Mesh& m, const Eigen::Vector3f& p, const Eigen::Vector3f& n, const Eigen::Vector3f& rgb) {
  m.vertices.push_back(p);
  m.normals.push_back(n);
  m.colours.push_back(rgb);
  return static_cast<int>(m.vertices.size()) - 1;
}

/// A tube of radius `tube` along an arc in the xz plane (centre (cx, cz), radius `arc`, from
/// angle a0 to a1 radians, measured from +x towards +z). Open ends: they sit inside the body.
Mesh arcTube(const Eigen::Vector2f& centre, float arc, float a0, float a1, float tube, int steps, int segments,
             const Eigen::Vector3f& rgb) {
  Mesh m;
  for (int i = 0; i <= steps; ++i) {
    const float a = a0 + (a1 - a0) * static_cast<float>(i) / static_cast<float>(steps);
    const Eigen::Vector3f radial(std::cos(a), 0.f, std::sin(a));
    const Eigen::Vector3f on_arc = Eigen::Vector3f(centre.x(), 0.f, centre.y()) + arc * radial;
    for (int j = 0; j < segments; ++j) {
      const float phi = kTwoPi * static_cast<float>(j) / static_cast<float>(segments);
      const Eigen::Vector3f n = std::cos(phi) * radial + std::sin(phi) * Eigen::Vector3f::UnitY();
      addVertex(m, on_arc + tube * n, n, rgb);
    }
  }
  for (int i = 0; i < steps; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = i * segments + (j + 1) % segments;
      const int c = a + segments, d = b + segments;
      // Outward winding: (around the tube) x (along the arc) is the outward normal.
      m.faces.emplace_back(a, b, d);
      m.faces.emplace_back(a, d, c);
    }
  return m;
}
}  // namespace

Mesh lathe(const std::vector<Eigen::Vector2f>& profile, int segments, const Eigen::Vector3f& rgb) {
  if (profile.size() < 2 || segments < 3) throw InputError("a lathe needs 2 or more profile points and 3 segments");
  Mesh m;
  for (std::size_t k = 0; k + 1 < profile.size(); ++k) {
    const Eigen::Vector2f p0 = profile[k], p1 = profile[k + 1];
    const Eigen::Vector2f d = p1 - p0;
    if (d.norm() <= 0.f) continue;
    const Eigen::Vector2f n2 = Eigen::Vector2f(d.y(), -d.x()).normalized();  // (radial, z), outwards
    const int base = static_cast<int>(m.vertices.size());
    for (int j = 0; j < segments; ++j) {
      const float theta = kTwoPi * static_cast<float>(j) / static_cast<float>(segments);
      const float c = std::cos(theta), s = std::sin(theta);
      const Eigen::Vector3f n(n2.x() * c, n2.x() * s, n2.y());
      addVertex(m, {p0.x() * c, p0.x() * s, p0.y()}, n, rgb);
      addVertex(m, {p1.x() * c, p1.x() * s, p1.y()}, n, rgb);
    }
    for (int j = 0; j < segments; ++j) {
      const int a0 = base + 2 * j, a1 = a0 + 1;
      const int b0 = base + 2 * ((j + 1) % segments), b1 = b0 + 1;
      // tangent x profile direction points outwards; a point on the axis makes one of the two
      // triangles degenerate, so it is left out.
      if (p0.x() > 0.f) m.faces.emplace_back(a0, b0, b1);
      if (p1.x() > 0.f) m.faces.emplace_back(a0, b1, a1);
    }
  }
  finishMesh(m);
  return m;
}

Mesh prism(const std::vector<Eigen::Vector2f>& polygon, float depth, const Eigen::Vector3f& rgb) {
  if (polygon.size() < 3 || !(depth > 0.f)) throw InputError("a prism needs a polygon of 3 or more points and a depth");
  Mesh m;
  const float h = 0.5f * depth;
  for (const float sign : {-1.f, 1.f}) {  // the two polygon faces, fan-triangulated
    const int base = static_cast<int>(m.vertices.size());
    for (const auto& p : polygon) addVertex(m, {p.x(), p.y(), sign * h}, {0.f, 0.f, sign}, rgb);
    for (int i = 1; i + 1 < static_cast<int>(polygon.size()); ++i)
      if (sign > 0.f) m.faces.emplace_back(base, base + i, base + i + 1);
      else m.faces.emplace_back(base, base + i + 1, base + i);
  }
  for (std::size_t i = 0; i < polygon.size(); ++i) {  // the sides, one flat quad per edge
    const Eigen::Vector2f a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    const Eigen::Vector2f e = (b - a).normalized();
    const Eigen::Vector3f n(e.y(), -e.x(), 0.f);  // outwards for a counter-clockwise polygon
    const int v0 = addVertex(m, {a.x(), a.y(), -h}, n, rgb), v1 = addVertex(m, {b.x(), b.y(), -h}, n, rgb);
    const int v2 = addVertex(m, {b.x(), b.y(), h}, n, rgb), v3 = addVertex(m, {a.x(), a.y(), h}, n, rgb);
    m.faces.emplace_back(v0, v1, v2);
    m.faces.emplace_back(v0, v2, v3);
  }
  finishMesh(m);
  return m;
}

void append(Mesh& into, const Mesh& part, const Eigen::Matrix3f& R, const Eigen::Vector3f& t) {
  const int base = static_cast<int>(into.vertices.size());
  for (std::size_t i = 0; i < part.vertices.size(); ++i) {
    into.vertices.push_back(R * part.vertices[i] + t);
    into.normals.push_back(i < part.normals.size() ? Eigen::Vector3f(R * part.normals[i]) : Eigen::Vector3f::Zero());
    into.colours.push_back(i < part.colours.size() ? part.colours[i] : Eigen::Vector3f::Constant(0.7f));
  }
  for (const auto& f : part.faces) into.faces.push_back(f + Eigen::Vector3i::Constant(base));
}

}  // namespace procedural

using procedural::append;

Mesh liddedCupMesh() {
  const Eigen::Vector3f white(0.93f, 0.92f, 0.88f), blue(0.12f, 0.32f, 0.78f);
  Mesh cup;
  // Body: a slightly tapered wall under the lid.
  append(cup, procedural::lathe({{0.f, 0.f}, {0.031f, 0.f}, {0.034f, 0.004f}, {0.040f, 0.094f}, {0.f, 0.094f}}, 48,
                                white));
  // Lid: a rim wider than the cup, a shallow dome and a knob.
  append(cup, procedural::lathe({{0.f, 0.093f},
                                 {0.043f, 0.093f},
                                 {0.043f, 0.101f},
                                 {0.030f, 0.106f},
                                 {0.011f, 0.107f},
                                 {0.011f, 0.115f},
                                 {0.f, 0.115f}},
                                48, blue));
  // Handle: a ring segment whose ends sink into the wall.
  append(cup, procedural::arcTube({0.037f, 0.049f}, 0.027f, -1.8f, 1.8f, 0.0055f, 24, 12, white));
  cup.name = "lidded_cup";
  finishMesh(cup);
  return cup;
}

Mesh gableCartonMesh() {
  const Eigen::Vector3f red(0.80f, 0.14f, 0.10f), white(0.94f, 0.94f, 0.92f), blue(0.10f, 0.25f, 0.70f);
  const float w = 0.070f;
  Mesh carton;
  append(carton, cuboidMesh({w, w, 0.105f}, red), Eigen::Matrix3f::Identity(), {0.f, 0.f, 0.0525f});
  append(carton, cuboidMesh({w, w, 0.045f}, white), Eigen::Matrix3f::Identity(), {0.f, 0.f, 0.1275f});
  // Gable roof: a triangle in the yz plane extruded along x (the ridge runs along x).
  Eigen::Matrix3f along_x;  // prism axis z -> world x; polygon x -> world y, polygon y -> world z
  along_x << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  append(carton, procedural::prism({{-0.5f * w, 0.f}, {0.5f * w, 0.f}, {0.f, 0.028f}}, w, white), along_x,
         {0.f, 0.f, 0.150f});
  // The sealed fin along the ridge.
  append(carton, cuboidMesh({w, 0.004f, 0.013f}, white), Eigen::Matrix3f::Identity(), {0.f, 0.f, 0.1845f});
  // A screw cap standing on the +y slope, its axis along the slope's normal.
  const float slope = std::atan2(0.028f, 0.5f * w);
  const Eigen::Matrix3f tilt = Eigen::AngleAxisf(-slope, Eigen::Vector3f::UnitX()).toRotationMatrix();
  const Eigen::Vector3f on_slope(0.012f, 0.5f * 0.5f * w, 0.150f + 0.5f * 0.028f);
  append(carton, cylinderMesh(0.011f, 0.010f, blue, 32), tilt, on_slope + tilt * Eigen::Vector3f(0.f, 0.f, 0.004f));
  carton.name = "gable_carton";
  finishMesh(carton);
  return carton;
}

Mesh angleBracketMesh() {
  const Eigen::Vector3f steel(0.56f, 0.58f, 0.62f), dark(0.30f, 0.31f, 0.34f);
  Mesh part;
  const float plate = 0.012f;
  append(part, cuboidMesh({0.100f, 0.060f, plate}, steel), Eigen::Matrix3f::Identity(), {0.f, 0.f, 0.5f * plate});
  append(part, cuboidMesh({plate, 0.060f, 0.070f}, steel), Eigen::Matrix3f::Identity(),
         {-0.050f + 0.5f * plate, 0.f, 0.035f});
  // Gusset: a right triangle in the xz plane between the two plates, off centre along y.
  Eigen::Matrix3f in_xz;  // prism axis z -> world y; polygon x -> world x, polygon y -> world z
  in_xz << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  append(part, procedural::prism({{-0.038f, plate}, {0.008f, plate}, {-0.038f, 0.058f}}, 0.008f, steel), in_xz,
         {0.f, 0.016f, 0.f});
  // A boss with a dark bore on the base plate.
  append(part, cylinderMesh(0.013f, 0.016f, steel, 40), Eigen::Matrix3f::Identity(), {0.026f, -0.008f, plate + 0.008f});
  append(part, cylinderMesh(0.006f, 0.0015f, dark, 24), Eigen::Matrix3f::Identity(),
         {0.026f, -0.008f, plate + 0.016f});
  part.name = "angle_bracket";
  finishMesh(part);
  return part;
}

std::vector<Mesh> demoMeshes() { return {liddedCupMesh(), gableCartonMesh(), angleBracketMesh()}; }

namespace {
const Eigen::Vector3f kSteel(0.62f, 0.63f, 0.66f);
/// A (radius, z) profile in millimetres, as lathe takes it in metres.
std::vector<Eigen::Vector2f> millimetres(std::vector<Eigen::Vector2f> profile) {
  for (auto& p : profile) p *= 1e-3f;
  return profile;
}
}  // namespace

Mesh hexNutMesh() {
  // Six trapezoids between the outer hexagon and the bore's, each a convex prism.
  const float outer = 0.005f / std::cos(std::numbers::pi_v<float> / 6.f), bore = 0.0032f, height = 0.005f;
  const auto corner = [](float radius, int k) {
    const float a = std::numbers::pi_v<float> / 3.f * static_cast<float>(k);
    return Eigen::Vector2f(radius * std::cos(a), radius * std::sin(a));
  };
  Mesh nut;
  for (int k = 0; k < 6; ++k)
    append(nut, procedural::prism({corner(outer, k), corner(outer, k + 1), corner(bore, k + 1), corner(bore, k)}, height, kSteel),
           Eigen::Matrix3f::Identity(), {0.f, 0.f, 0.5f * height});
  nut.name = "hex_nut";
  finishMesh(nut);
  return nut;
}

Mesh capScrewMesh() {
  Mesh screw = procedural::lathe(
      millimetres({{0.f, 0.f}, {2.75f, 0.f}, {2.75f, 3.f}, {1.5f, 3.f}, {1.5f, 47.6f}, {1.1f, 48.f}, {0.f, 48.f}}), 24,
      kSteel);
  screw.name = "cap_screw";
  finishMesh(screw);
  return screw;
}

Mesh nozzleMesh() {
  Mesh nozzle = procedural::lathe(millimetres({{0.f, 0.f},
                                               {7.f, 0.f},
                                               {7.f, 8.f},
                                               {10.f, 8.f},
                                               {10.f, 12.f},
                                               {6.5f, 12.f},
                                               {6.5f, 45.f},
                                               {3.f, 58.f},
                                               {0.f, 58.f}}),
                                  32, kSteel);
  nozzle.name = "nozzle";
  finishMesh(nozzle);
  return nozzle;
}

Mesh sparkPlugKeyMesh() {
  Mesh key = procedural::lathe(millimetres({{0.f, 0.f}, {11.f, 0.f}, {11.f, 70.f}, {8.f, 75.f}, {8.f, 95.f}, {0.f, 95.f}}),
                               32, kSteel);
  // The T-bar: a rod along x through the top of the neck.
  Eigen::Matrix3f along_x;  // lathe axis z -> world x
  along_x << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  append(key, procedural::lathe(millimetres({{0.f, -85.f}, {5.f, -85.f}, {5.f, 85.f}, {0.f, 85.f}}), 24, kSteel),
         along_x, {0.f, 0.f, 0.088f});
  key.name = "spark_plug_key";
  finishMesh(key);
  return key;
}

std::vector<Mesh> partMeshes() { return {hexNutMesh(), capScrewMesh(), nozzleMesh(), sparkPlugKeyMesh()}; }

}  // namespace vkpose
