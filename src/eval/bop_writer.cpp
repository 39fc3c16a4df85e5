// BOP dataset files from vkpose's structs: JSON documents and binary PLY models in mm.
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {

using json = nlohmann::ordered_json;

/// Fixed decimals: 8 for rotations, 6 for millimetres and pixels; shorter files, stable diffs.
double round(double v, int decimals) {
  const double s = std::pow(10.0, decimals);
  return std::round(v * s) / s;
}

json rectJson(const cv::Rect& r) { return json::array({r.x, r.y, r.width, r.height}); }

template <typename T>
void put(std::string& out, T value) {
  static_assert(std::endian::native == std::endian::little, "the PLY writer assumes a little-endian machine");
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

}  // namespace

void writePlyMillimetres(const Mesh& mesh, const std::string& path, bool overwrite) {
  if (!overwrite && std::filesystem::exists(path)) throw InputError(path + " exists; pass --force to overwrite it");
  const bool colours = mesh.colours.size() == mesh.vertices.size();
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  std::string out = fmt::format("ply\nformat binary_little_endian 1.0\ncomment vkpose synth, millimetres\n"
                                "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
                                mesh.vertices.size());
  if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colours) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += fmt::format("element face {}\nproperty list uchar int vertex_indices\nend_header\n", mesh.faces.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) put(out, mesh.vertices[i][k] * 1000.f);
    if (normals)
      for (int k = 0; k < 3; ++k) put(out, mesh.normals[i][k]);
    if (colours)
      for (int k = 0; k < 3; ++k)
        put(out, static_cast<uint8_t>(std::lround(std::clamp(mesh.colours[i][k], 0.f, 1.f) * 255.f)));
  }
  for (const auto& f : mesh.faces) {
    put(out, uint8_t{3});
    for (int k = 0; k < 3; ++k) put(out, static_cast<int32_t>(f[k]));
  }
  std::ofstream file(path, std::ios::binary);
  if (!file || !file.write(out.data(), static_cast<std::streamsize>(out.size())) || !file.flush())
    throw InputError("cannot write " + path);
}

std::string modelsInfoJson(const std::vector<BopModel>& models) {
  json doc = json::object();
  for (const BopModel& m : models) {
    if (!m.mesh) throw InputError(fmt::format("models_info.json: object {} has no mesh", m.obj_id));
    const Mesh& mesh = *m.mesh;
    json j;
    j["diameter"] = round(mesh.diameter * 1000.0, 6);
    const char* mins[] = {"min_x", "min_y", "min_z"};
    const char* sizes[] = {"size_x", "size_y", "size_z"};
    for (int a = 0; a < 3; ++a) j[mins[a]] = round(mesh.bbox_min[a] * 1000.0, 6);
    for (int a = 0; a < 3; ++a) j[sizes[a]] = round((mesh.bbox_max[a] - mesh.bbox_min[a]) * 1000.0, 6);
    if (!m.symmetries.empty()) {
      json sym = json::array();
      for (const auto& s : m.symmetries) {
        const Eigen::Vector3f axis = s.axis.normalized();
        sym.push_back({{"axis", {round(axis.x(), 8), round(axis.y(), 8), round(axis.z(), 8)}},
                       {"offset",
                        {round(s.offset_m.x() * 1000.0, 6), round(s.offset_m.y() * 1000.0, 6),
                         round(s.offset_m.z() * 1000.0, 6)}}});
      }
      j["symmetries_continuous"] = sym;
    }
    if (!m.discrete_symmetries.empty()) {
      json sym = json::array();
      for (const Pose& s : m.discrete_symmetries) {
        json matrix = json::array();
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) matrix.push_back(round(s.R(r, c), 8));
          matrix.push_back(round(s.t[r] * 1000.0, 6));
        }
        for (const double v : {0.0, 0.0, 0.0, 1.0}) matrix.push_back(v);
        sym.push_back(matrix);
      }
      j["symmetries_discrete"] = sym;
    }
    doc[std::to_string(m.obj_id)] = j;
  }
  return doc.dump(2) + "\n";
}

std::string cameraJson(const Camera& c) {
  json j;
  j["cx"] = c.cx;
  j["cy"] = c.cy;
  j["depth_scale"] = c.depth_scale;
  j["fx"] = c.fx;
  j["fy"] = c.fy;
  j["height"] = c.height;
  j["width"] = c.width;
  return j.dump(2) + "\n";
}

std::string sceneCameraJson(const std::map<int, Camera>& cameras) {
  json doc = json::object();
  for (const auto& [im_id, c] : cameras)
    doc[std::to_string(im_id)] = {{"cam_K", {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0}},
                                  {"depth_scale", c.depth_scale}};
  return doc.dump(2) + "\n";
}

std::string sceneGtJson(const std::map<int, std::vector<GroundTruthPose>>& gt) {
  json doc = json::object();
  for (const auto& [im_id, instances] : gt) {
    json list = json::array();
    for (const GroundTruthPose& g : instances) {
      json R = json::array(), t = json::array();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R.push_back(round(g.R(r, c), 8));
      for (int k = 0; k < 3; ++k) t.push_back(round(g.t[k] * 1000.0, 6));
      list.push_back({{"cam_R_m2c", R}, {"cam_t_m2c", t}, {"obj_id", g.obj_id}});
    }
    doc[std::to_string(im_id)] = list;
  }
  return doc.dump(2) + "\n";
}

std::string sceneGtInfoJson(const std::map<int, std::vector<GroundTruthInfo>>& info) {
  json doc = json::object();
  for (const auto& [im_id, instances] : info) {
    json list = json::array();
    for (const GroundTruthInfo& g : instances)
      list.push_back({{"bbox_obj", rectJson(g.bbox_obj)},
                      {"bbox_visib", rectJson(g.bbox_visib)},
                      {"px_count_all", g.px_count_all},
                      {"px_count_valid", g.px_count_valid},
                      {"px_count_visib", g.px_count_visib},
                      {"visib_fract", round(g.visib_fract, 8)}});
    doc[std::to_string(im_id)] = list;
  }
  return doc.dump(2) + "\n";
}

}  // namespace vkpose
