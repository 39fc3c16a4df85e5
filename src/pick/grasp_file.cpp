// Grasp files and bin files (docs/picking.md): JSON read with every value checked, so that a
// mistyped grasp is an error naming the file and the grasp, never a gripper sent somewhere odd.
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vkpose/error.hpp"
#include "vkpose/picking.hpp"

namespace vkpose {
namespace {
using nlohmann::json;

std::string readText(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot read the {}", path, what));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Reads values of one JSON object, naming `where` in every error.
class Reader {
 public:
  Reader(const json& object, std::string where) : j_(object), where_(std::move(where)) {
    if (!j_.is_object()) fail("expected a JSON object");
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(fmt::format("{}: {}", where_, what)); }
  bool has(const char* key) const { return j_.contains(key); }

  float number(const char* key) const {
    if (!has(key)) fail(fmt::format("'{}' is missing", key));
    return numberOf(j_.at(key), key);
  }
  /// A length given as KEY_m (metres) or KEY_mm (millimetres); `fallback` when neither is there
  /// and a fallback is allowed.
  float length(const std::string& key, std::optional<float> fallback = std::nullopt) const {
    const std::string m = key + "_m", mm = key + "_mm";
    if (has(m.c_str()) && has(mm.c_str())) fail(fmt::format("give '{}' or '{}', not both", m, mm));
    float v = 0.f;
    if (has(m.c_str())) v = numberOf(j_.at(m), m);
    else if (has(mm.c_str())) v = numberOf(j_.at(mm), mm) / 1000.f;
    else if (fallback) return *fallback;
    else fail(fmt::format("'{}' (or '{}') is missing", m, mm));
    if (v < 0.f) fail(fmt::format("'{}' is negative", key));
    return v;
  }
  Eigen::Vector3f vector3(const std::string& key, bool unit) const {
    if (!has(key.c_str())) fail(fmt::format("'{}' is missing", key));
    const json& a = j_.at(key);
    if (!a.is_array() || a.size() != 3) fail(fmt::format("'{}' needs 3 numbers", key));
    Eigen::Vector3f v(numberOf(a[0], key), numberOf(a[1], key), numberOf(a[2], key));
    if (unit && std::abs(v.norm() - 1.f) > 0.01f)
      fail(fmt::format("'{}' ({}, {}, {}) is not a unit vector (length {:.4f})", key, v.x(), v.y(), v.z(), v.norm()));
    return v;
  }
  /// A position as KEY_m or KEY_mm (3 numbers).
  Eigen::Vector3f position(const std::string& key) const {
    const std::string m = key + "_m", mm = key + "_mm";
    if (has(m.c_str())) return vector3(m, false);
    if (has(mm.c_str())) return vector3(mm, false) / 1000.f;
    fail(fmt::format("'{}' (or '{}') is missing", m, mm));
  }
  const json& at(const char* key) const { return j_.at(key); }

 private:
  float numberOf(const json& v, const std::string& key) const {
    if (!v.is_number()) fail(fmt::format("'{}' is not a number", key));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(fmt::format("'{}' is not a finite number", key));
    return static_cast<float>(d);
  }
  const json& j_;
  std::string where_;
};

GripperShape gripperOf(const Reader& r, const GripperShape& base) {
  GripperShape g = base;
  if (r.has("shape")) {
    const json& shape = r.at("shape");
    if (!shape.is_string()) r.fail("'shape' must be \"cylinder\" or \"box\"");
    const std::string name = shape.get<std::string>();
    if (name == "cylinder") g.kind = GripperShape::Kind::Cylinder;
    else if (name == "box") g.kind = GripperShape::Kind::Box;
    else r.fail(fmt::format("shape '{}': \"cylinder\" or \"box\"", name));
  }
  g.radius = r.length("radius", g.radius);
  g.size_x = r.length("size_x", g.size_x);
  g.size_y = r.length("size_y", g.size_y);
  g.length = r.length("length", g.length);
  g.finger_length = r.length("finger_length", g.finger_length);
  g.finger_width = r.length("finger_width", g.finger_width);
  g.finger_thickness = r.length("finger_thickness", g.finger_thickness);
  if (g.length <= 0.f) r.fail("the gripper's length must be positive");
  if (g.finger_length >= g.length) r.fail("the fingers must be shorter than the gripper");
  if (g.finger_length > 0.f && (g.finger_width <= 0.f || g.finger_thickness <= 0.f))
    r.fail("fingers need a positive finger_width and finger_thickness");
  if (g.kind == GripperShape::Kind::Cylinder && g.radius <= 0.f) r.fail("a cylinder gripper needs a positive radius");
  if (g.kind == GripperShape::Kind::Box && (g.size_x <= 0.f || g.size_y <= 0.f))
    r.fail("a box gripper needs positive size_x and size_y");
  return g;
}

Grasp graspOf(const Reader& r, const GripperShape& gripper) {
  Grasp g;
  if (!r.has("name") || !r.at("name").is_string() || r.at("name").get<std::string>().empty())
    r.fail("every grasp needs a \"name\"");
  g.name = r.at("name").get<std::string>();
  if (r.has("priority")) {
    if (!r.at("priority").is_number_integer()) r.fail("'priority' must be a whole number");
    g.priority = r.at("priority").get<int>();
  }
  const Eigen::Vector3f z = r.vector3("approach", true).normalized();
  const Eigen::Vector3f x = r.has("x") ? r.vector3("x", true).normalized() : z.unitOrthogonal();
  if (std::abs(x.dot(z)) > 0.01f) r.fail("'x' is not perpendicular to 'approach'");
  const Eigen::Vector3f xo = (x - x.dot(z) * z).normalized();
  g.pose.R.col(0) = xo;
  g.pose.R.col(1) = z.cross(xo);
  g.pose.R.col(2) = z;
  g.pose.t = r.position("position");
  g.approach_m = r.length("approach_distance", 0.1f);
  g.retreat_m = r.length("retreat_distance", 0.1f);
  g.opening_m = r.length("opening", 0.f);
  g.suction_radius_m = r.length("suction_radius", 0.f);
  if (g.opening_m > 0.f && g.suction_radius_m > 0.f) r.fail("a grasp has jaws (opening) or a suction cup, not both");
  if (g.opening_m == 0.f && g.suction_radius_m == 0.f) r.fail("give the jaws' 'opening' or the 'suction_radius'");
  g.gripper = r.has("gripper") ? gripperOf(Reader(r.at("gripper"), "its gripper"), gripper) : gripper;
  if (g.suction_radius_m > 0.f) g.gripper.finger_length = 0.f;  // a suction cup has no fingers
  return g;
}

json parseJson(const std::string& text, const std::string& source) {
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(fmt::format("{}: not JSON ({})", source, e.what()));
  }
}
}  // namespace

GraspSet parseGrasps(const std::string& text, const std::string& source) {
  const json doc = parseJson(text, source);
  const Reader top(doc, source);
  GraspSet set;
  if (!top.has("object") || !top.at("object").is_string() || top.at("object").get<std::string>().empty())
    top.fail("\"object\" (the bank's object name) is missing");
  set.object = top.at("object").get<std::string>();
  const GripperShape gripper = top.has("gripper") ? gripperOf(Reader(top.at("gripper"), source + ": gripper"), {})
                                                  : GripperShape{};
  if (!top.has("grasps") || !top.at("grasps").is_array() || top.at("grasps").empty())
    top.fail("\"grasps\" must list at least one grasp");
  std::size_t i = 0;
  for (const json& g : top.at("grasps")) {
    const std::string name = g.is_object() && g.contains("name") && g["name"].is_string()
                                 ? g["name"].get<std::string>()
                                 : fmt::format("#{}", i + 1);
    set.grasps.push_back(graspOf(Reader(g, fmt::format("{}: grasp '{}'", source, name)), gripper));
    ++i;
  }
  return set;
}

GraspSet loadGrasps(const std::string& path) { return parseGrasps(readText(path, "grasp file"), path); }

std::vector<Grasp> faceSuctionGrasps(const Mesh& mesh, float suction_radius_m, float gripper_radius_m) {
  static const char* names[] = {"-x face", "+x face", "-y face", "+y face", "-z face", "+z face"};
  std::vector<Grasp> out;
  const Eigen::Vector3f centre = mesh.bboxCentre(), half = 0.5f * (mesh.bbox_max - mesh.bbox_min);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const float sign = side ? 1.f : -1.f;
      Grasp g;
      g.name = names[2 * axis + side];
      const Eigen::Vector3f z = -sign * Eigen::Vector3f::Unit(axis);  // into the part
      g.pose.R.col(2) = z;
      g.pose.R.col(0) = z.unitOrthogonal();
      g.pose.R.col(1) = z.cross(g.pose.R.col(0));
      g.pose.t = centre + sign * half[axis] * Eigen::Vector3f::Unit(axis);
      g.suction_radius_m = suction_radius_m;
      g.gripper.radius = gripper_radius_m;
      out.push_back(g);
    }
  return out;
}

std::vector<std::vector<Grasp>> graspsForBanks(const std::vector<std::string>& files,
                                               const std::vector<TemplateBank>& banks, int symmetry_steps) {
  std::vector<std::vector<Grasp>> out(banks.size());
  for (const std::string& file : files) {
    const GraspSet set = loadGrasps(file);
    bool found = false;
    for (std::size_t b = 0; b < banks.size(); ++b)
      if (banks[b].object == set.object) {
        const auto copies = expandBySymmetry(set.grasps, banks[b], symmetry_steps);
        out[b].insert(out[b].end(), copies.begin(), copies.end());
        found = true;
      }
    if (!found) {
      std::string names;
      for (const auto& b : banks) names += (names.empty() ? "" : ", ") + b.object;
      throw InputError(fmt::format("{} holds grasps of '{}', but no bank is for that object (the banks' objects: {})",
                                   file, set.object, names));
    }
  }
  return out;
}

BinBox parseBin(const std::string& text, const std::string& source) {
  const json doc = parseJson(text, source);
  const Reader r(doc, source);
  BinBox bin;
  if (!r.has("R") || !r.at("R").is_array() || r.at("R").size() != 9) r.fail("'R' needs 9 numbers (row-major)");
  for (int i = 0; i < 9; ++i) {
    const json& v = r.at("R")[static_cast<std::size_t>(i)];
    if (!v.is_number() || !std::isfinite(v.get<double>())) r.fail("'R' holds something that is not a finite number");
    bin.pose.R(i / 3, i % 3) = v.get<float>();
  }
  if ((bin.pose.R.transpose() * bin.pose.R - Eigen::Matrix3f::Identity()).cwiseAbs().maxCoeff() > 1e-2f ||
      bin.pose.R.determinant() < 0.f)
    r.fail("'R' is not a rotation");
  bin.pose.t = r.position("t");
  bin.inner = r.position("inner");
  bin.wall_thickness_m = r.length("wall_thickness", 0.01f);
  if ((bin.inner.array() <= 0.f).any()) r.fail("the bin's inner size must be positive");
  return bin;
}

BinBox loadBin(const std::string& path) { return parseBin(readText(path, "bin file"), path); }

std::string binJson(const BinBox& bin) {
  json R = json::array();
  for (int i = 0; i < 9; ++i) R.push_back(bin.pose.R(i / 3, i % 3));
  const json doc = {{"R", R},
                    {"t_m", {bin.pose.t.x(), bin.pose.t.y(), bin.pose.t.z()}},
                    {"inner_m", {bin.inner.x(), bin.inner.y(), bin.inner.z()}},
                    {"wall_thickness_m", bin.wall_thickness_m}};
  return doc.dump(2) + "\n";
}

PickOrder parsePickOrder(const std::string& name) {
  for (PickOrder o : {PickOrder::Combined, PickOrder::Height, PickOrder::Score, PickOrder::Visible})
    if (name == pickOrderName(o)) return o;
  throw InputError(fmt::format("pick order '{}': combined, height, score or visible", name));
}

const char* pickOrderName(PickOrder order) {
  switch (order) {
    case PickOrder::Height: return "height";
    case PickOrder::Score: return "score";
    case PickOrder::Visible: return "visible";
    case PickOrder::Combined: break;
  }
  return "combined";
}

}  // namespace vkpose
