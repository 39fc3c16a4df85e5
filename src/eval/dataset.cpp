// BOP dataset readers (docs/bop_datasets_format.md of bop_toolkit). Every field is checked at
// this boundary; nlohmann's own exceptions never leave this file.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "eval/checks.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

json readJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the file", path));
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(fmt::format("{}: not valid JSON ({})", path, e.what()));
  }
}

/// The top level of a BOP per-image file: an object keyed by image ids ("3", "12", ...).
const json& imageMap(const json& doc, const std::string& path) {
  if (!doc.is_object())
    throw InputError(fmt::format("{}: expected an object keyed by image id, found {}", path, doc.type_name()));
  return doc;
}

int idKey(const std::string& key, const std::string& path, const char* what) {
  int id = -1;
  const auto [end, ec] = std::from_chars(key.data(), key.data() + key.size(), id);
  if (key.empty() || ec != std::errc() || end != key.data() + key.size() || id < 0)
    throw InputError(fmt::format("{}: key '{}' is not {} (a non-negative integer)", path, key, what));
  return id;
}

const json& field(const json& obj, const char* key, const std::string& where) {
  if (!obj.is_object()) throw InputError(fmt::format("{}: expected an object, found {}", where, obj.type_name()));
  const auto it = obj.find(key);
  if (it == obj.end()) throw InputError(fmt::format("{}: missing field '{}'", where, key));
  return *it;
}

double number(const json& obj, const char* key, const std::string& where) {
  const json& v = field(obj, key, where);
  if (!v.is_number())
    throw InputError(fmt::format("{}: field '{}' must be a number, found {}", where, key, v.type_name()));
  return v.get<double>();
}

int integer(const json& obj, const char* key, const std::string& where) {
  const json& v = field(obj, key, where);
  if (!v.is_number_integer() || v.get<int64_t>() < std::numeric_limits<int>::min() ||
      v.get<int64_t>() > std::numeric_limits<int>::max())
    throw InputError(fmt::format("{}: field '{}' must be an integer, found {}", where, key, v.dump()));
  return static_cast<int>(v.get<int64_t>());
}

std::vector<double> numbers(const json& obj, const char* key, std::size_t count, const std::string& where) {
  const json& v = field(obj, key, where);
  if (!v.is_array() || v.size() != count)
    throw InputError(fmt::format("{}: field '{}' must be an array of {} numbers, found {}", where, key, count,
                                 v.is_array() ? fmt::format("{} values", v.size()) : v.type_name()));
  std::vector<double> out;
  for (const auto& x : v) {
    if (!x.is_number())
      throw InputError(fmt::format("{}: field '{}' must hold numbers, found {}", where, key, x.dump()));
    out.push_back(x.get<double>());
  }
  return out;
}

cv::Rect box(const json& obj, const char* key, const std::string& where) {
  const auto b = numbers(obj, key, 4, where);
  // Checked before the cast: a double past the int range cast to int is undefined.
  for (const double v : b)
    if (!(std::abs(v) <= 1e6))
      throw InputError(fmt::format("{}: field '{}' holds {}, not a pixel coordinate", where, key, v));
  return {static_cast<int>(b[0]), static_cast<int>(b[1]), static_cast<int>(b[2]), static_cast<int>(b[3])};
}

GroundTruthPose gtPose(const json& j, const std::string& where) {
  GroundTruthPose g;
  g.obj_id = integer(j, "obj_id", where);
  const auto r = numbers(j, "cam_R_m2c", 9, where);
  const auto t = numbers(j, "cam_t_m2c", 3, where);
  const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
  if (const auto problem = eval::rotationProblem(R))
    throw InputError(fmt::format("{}: field 'cam_R_m2c': {}", where, *problem));
  g.R = R.cast<float>();
  g.t = (Eigen::Vector3d(t[0], t[1], t[2]) * 0.001).cast<float>();
  return g;
}

GroundTruthInfo gtInfo(const json& j, const std::string& where) {
  GroundTruthInfo g;
  g.bbox_obj = box(j, "bbox_obj", where);
  g.bbox_visib = box(j, "bbox_visib", where);
  g.px_count_all = integer(j, "px_count_all", where);
  g.px_count_valid = integer(j, "px_count_valid", where);
  g.px_count_visib = integer(j, "px_count_visib", where);
  const double v = number(j, "visib_fract", where);
  if (!(v >= 0 && v <= 1)) throw InputError(fmt::format("{}: field 'visib_fract' {} is outside 0..1", where, v));
  g.visib_fract = static_cast<float>(v);
  return g;
}

/// Reads a per-image file whose values are lists of instances.
template <typename T, typename Parse>
std::map<int, std::vector<T>> perImageLists(const std::string& path, Parse parse) {
  const json doc = readJson(path);
  std::map<int, std::vector<T>> out;
  for (const auto& [key, list] : imageMap(doc, path).items()) {
    const int im_id = idKey(key, path, "an image id");
    const std::string where = fmt::format("{}: image {}", path, key);
    if (!list.is_array())
      throw InputError(fmt::format("{}: expected a list of instances, found {}", where, list.type_name()));
    auto& items = out[im_id];
    for (std::size_t i = 0; i < list.size(); ++i)
      items.push_back(parse(list[i], fmt::format("{}, instance {}", where, i)));
  }
  return out;
}

bool isFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

std::string requireFile(const fs::path& p, const std::string& what) {
  if (!isFile(p)) throw InputError(fmt::format("{}: missing {}", p.string(), what));
  return p.string();
}

/// Scene folders of a split: six-digit names, sorted.
std::vector<int> sceneIds(const fs::path& split_dir) {
  std::error_code ec;
  if (!fs::is_directory(split_dir, ec)) throw InputError(fmt::format("{}: no such split folder", split_dir.string()));
  std::vector<int> ids;
  for (fs::directory_iterator it(split_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() == 6 && std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
        it->is_directory(ec))
      ids.push_back(std::stoi(name));
  }
  if (ec) throw InputError(fmt::format("{}: cannot list the split folder ({})", split_dir.string(), ec.message()));
  if (ids.empty()) throw InputError(fmt::format("{}: no scene folders (000000, 000001, ...)", split_dir.string()));
  std::sort(ids.begin(), ids.end());
  return ids;
}

/// scene_dir/folder/%06d.<ext> for the first extension that exists.
std::string imageFile(const fs::path& scene_dir, const char* folder, int im_id, const std::vector<std::string>& exts) {
  std::string tried;
  for (const auto& ext : exts) {
    const fs::path p = scene_dir / folder / fmt::format("{:06d}.{}", im_id, ext);
    if (isFile(p)) return p.string();
    tried += (tried.empty() ? "" : " or ") + p.filename().string();
  }
  throw InputError(fmt::format("{}: missing image {} ({})", (scene_dir / folder).string(), im_id, tried));
}

}  // namespace

std::map<int, std::vector<GroundTruthPose>> loadSceneGt(const std::string& path) {
  return perImageLists<GroundTruthPose>(path, gtPose);
}

std::map<int, std::vector<GroundTruthInfo>> loadSceneGtInfo(const std::string& path) {
  return perImageLists<GroundTruthInfo>(path, gtInfo);
}

std::map<int, Camera> loadSceneCamera(const std::string& path, const Camera& base) {
  const json doc = readJson(path);
  std::map<int, Camera> out;
  for (const auto& [key, entry] : imageMap(doc, path).items()) {
    const int im_id = idKey(key, path, "an image id");
    const std::string where = fmt::format("{}: image {}", path, key);
    const auto k = numbers(entry, "cam_K", 9, where);
    Camera c = base;
    c.fx = k[0];
    c.cx = k[2];
    c.fy = k[4];
    c.cy = k[5];
    if (entry.contains("depth_scale")) c.depth_scale = number(entry, "depth_scale", where);
    validateCamera(c, where);
    out[im_id] = c;
  }
  return out;
}

std::map<int, ModelInfo> loadModelsInfo(const std::string& path) {
  const json doc = readJson(path);
  if (!doc.is_object())
    throw InputError(fmt::format("{}: expected an object keyed by obj_id, found {}", path, doc.type_name()));
  std::map<int, ModelInfo> out;
  for (const auto& [key, j] : doc.items()) {
    ModelInfo m;
    m.obj_id = idKey(key, path, "an obj_id");
    const std::string where = fmt::format("{}: object {}", path, key);
    const double d = number(j, "diameter", where);
    if (!(d > 0) || !std::isfinite(d))
      throw InputError(fmt::format("{}: field 'diameter' {} must be positive", where, d));
    m.diameter = static_cast<float>(d * 0.001);
    const char* mins[] = {"min_x", "min_y", "min_z"};
    const char* sizes[] = {"size_x", "size_y", "size_z"};
    for (int a = 0; a < 3; ++a) {
      // The box is informative only; older files may lack it.
      if (j.contains(mins[a])) m.bbox_min[a] = static_cast<float>(number(j, mins[a], where) * 0.001);
      if (j.contains(sizes[a])) m.bbox_size[a] = static_cast<float>(number(j, sizes[a], where) * 0.001);
    }
    for (const char* key_sym : {"symmetries_discrete", "symmetries_continuous"}) {
      if (!j.contains(key_sym)) continue;
      const json& s = j[key_sym];
      if (!s.is_array())
        throw InputError(fmt::format("{}: field '{}' must be a list, found {}", where, key_sym, s.type_name()));
      if (!s.empty()) m.symmetric = true;
    }
    out[m.obj_id] = m;
  }
  return out;
}

std::string BopDataset::modelPath(int obj_id) const {
  return (fs::path(root) / "models" / fmt::format("obj_{:06d}.ply", obj_id)).string();
}

std::string BopDataset::evalModelPath(int obj_id) const {
  const fs::path p = fs::path(root) / "models_eval" / fmt::format("obj_{:06d}.ply", obj_id);
  return isFile(p) ? p.string() : modelPath(obj_id);
}

BopDataset loadBopDataset(const std::string& root, const std::string& split) {
  BopDataset ds;
  ds.root = root;
  ds.split = split;
  const fs::path r(root);
  ds.camera = loadCamera(requireFile(r / "camera.json", "BOP camera file"));
  ds.models = loadModelsInfo(requireFile(r / "models" / "models_info.json", "BOP models info"));
  for (const int scene_id : sceneIds(r / split)) {
    const fs::path scene = r / split / fmt::format("{:06d}", scene_id);
    const std::string gt_path = requireFile(scene / "scene_gt.json", "ground truth");
    const auto gt = loadSceneGt(gt_path);
    const auto cameras = loadSceneCamera(requireFile(scene / "scene_camera.json", "scene cameras"), ds.camera);
    std::map<int, std::vector<GroundTruthInfo>> info;
    const fs::path info_path = scene / "scene_gt_info.json";
    if (isFile(info_path)) info = loadSceneGtInfo(info_path.string());
    for (const auto& [im_id, poses] : gt) {
      BopImage im;
      im.scene_id = scene_id;
      im.image_id = im_id;
      const auto cam = cameras.find(im_id);
      if (cam == cameras.end())
        throw InputError(fmt::format("{}: no entry for image {}", (scene / "scene_camera.json").string(), im_id));
      im.camera = cam->second;
      im.rgb_path = imageFile(scene, "rgb", im_id, {"png", "jpg"});
      im.depth_path = imageFile(scene, "depth", im_id, {"png"});
      im.gt = poses;
      for (std::size_t i = 0; i < im.gt.size(); ++i)
        if (!ds.models.count(im.gt[i].obj_id))
          throw InputError(fmt::format("{}: image {}, instance {}: obj_id {} is not in {}", gt_path, im_id, i,
                                       im.gt[i].obj_id, (r / "models" / "models_info.json").string()));
      if (!info.empty()) {
        const auto it = info.find(im_id);
        if (it == info.end() || it->second.size() != im.gt.size())
          throw InputError(fmt::format("{}: image {} has {} entries, scene_gt.json has {}", info_path.string(), im_id,
                                       it == info.end() ? 0 : it->second.size(), im.gt.size()));
        im.gt_info = it->second;
        for (std::size_t i = 0; i < im.gt.size(); ++i) im.gt[i].visib_fract = im.gt_info[i].visib_fract;
      }
      ds.images.push_back(std::move(im));
    }
  }
  return ds;
}

}  // namespace vkpose
