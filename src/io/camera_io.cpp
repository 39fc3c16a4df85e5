#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {
double number(const nlohmann::json& j, const char* key, const std::string& path) {
  if (!j.contains(key) || !j[key].is_number()) throw InputError(fmt::format("{}: missing or non-numeric '{}'", path, key));
  return j[key].get<double>();
}
}  // namespace

Camera loadCamera(const std::string& path, const std::string& entry) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the camera file", path));
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not valid JSON ({})", path, e.what()));
  }
  if (!doc.is_object()) throw InputError(fmt::format("{}: expected a JSON object", path));
  nlohmann::json j = doc;
  // scene_camera.json: {"<image id>": {"cam_K": ..., "depth_scale": ...}, ...}
  if (!doc.contains("cam_K") && !doc.contains("fx")) {
    if (!entry.empty()) {
      if (!doc.contains(entry)) throw InputError(fmt::format("{}: no entry '{}'", path, entry));
      j = doc[entry];
    } else if (!doc.empty() && doc.begin()->is_object()) {
      j = *doc.begin();
    }
  }
  if (!j.is_object()) throw InputError(fmt::format("{}: expected camera fields", path));
  Camera c;
  try {
    if (j.contains("cam_K")) {
      const auto& k = j["cam_K"];
      if (!k.is_array() || k.size() != 9) throw InputError(fmt::format("{}: cam_K must hold 9 numbers", path));
      for (const auto& v : k)
        if (!v.is_number()) throw InputError(fmt::format("{}: cam_K must hold 9 numbers", path));
      c.fx = k[0].get<double>();
      c.cx = k[2].get<double>();
      c.fy = k[4].get<double>();
      c.cy = k[5].get<double>();
    } else {
      c.fx = number(j, "fx", path);
      c.fy = number(j, "fy", path);
      c.cx = number(j, "cx", path);
      c.cy = number(j, "cy", path);
    }
    // Checked before the cast: a double past the int range cast to int is undefined.
    const auto pixels = [&](const char* key) {
      const double v = number(j, key, path);
      if (!(v >= 1 && v <= 16384)) throw InputError(fmt::format("{}: {} {} is outside 1..16384", path, key, v));
      return static_cast<int>(v);
    };
    if (j.contains("width")) c.width = pixels("width");
    if (j.contains("height")) c.height = pixels("height");
    if (j.contains("depth_scale")) c.depth_scale = number(j, "depth_scale", path);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: {}", path, e.what()));
  }
  validateCamera(c, path);
  return c;
}

}  // namespace vkpose
