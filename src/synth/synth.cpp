// `vkpose synth`: synthetic BOP datasets. Every random choice of an image comes from one
// generator seeded with (seed, image index), so images do not depend on each other and the
// same arguments give the same bytes.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <deque>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "synth/placement.hpp"
#include "synth/scene.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/picking.hpp"
#include "vkpose/synth.hpp"

namespace vkpose {

namespace {

namespace fs = std::filesystem;
constexpr float kPi = std::numbers::pi_v<float>;

/// Albedos (RGB) for meshes without colours, one per obj_id in turn (the shared STLs have none).
const Eigen::Vector3f kAlbedos[] = {{0.86f, 0.85f, 0.80f}, {0.95f, 0.55f, 0.15f}, {0.25f, 0.45f, 0.80f},
                                    {0.80f, 0.22f, 0.20f}, {0.30f, 0.65f, 0.35f}, {0.78f, 0.72f, 0.30f}};

int uniformInt(std::mt19937& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<uint32_t>(hi - lo + 1));
}

Eigen::Vector3f randomColour(std::mt19937& rng, float lo, float hi) {
  return {uniform(rng, lo, hi), uniform(rng, lo, hi), uniform(rng, lo, hi)};
}

/// "Juice_Carton" and "juicecarton" name the same object.
std::string normalisedName(const std::string& s) {
  std::string out;
  for (const char c : s)
    if (c != '_' && c != '-' && c != ' ') out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// N of posesN.txt, or -1 for any other name.
long poseFileNumber(const fs::path& p) {
  const std::string name = p.filename().string();
  if (name.size() <= 9 || name.rfind("poses", 0) != 0 || name.substr(name.size() - 4) != ".txt") return -1;
  const std::string digits = name.substr(5, name.size() - 9);
  if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }) || digits.size() > 9)
    return -1;
  return std::stol(digits);
}

std::vector<std::string> poseFilesIn(const fs::path& dir) {
  std::vector<std::pair<long, std::string>> files;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (const long n = poseFileNumber(it->path()); n >= 0 && it->is_regular_file(ec))
      files.emplace_back(n, it->path().string());
  std::sort(files.begin(), files.end());
  std::vector<std::string> out;
  for (auto& f : files) out.push_back(std::move(f.second));
  return out;
}

/// Refuses a non-empty out_dir without overwrite; with it, removes what synth writes there.
void prepareOutput(const fs::path& out, bool overwrite) {
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec)) throw InputError(fmt::format("{} exists and is not a folder", out.string()));
    if (!fs::is_empty(out, ec)) {
      if (!overwrite) throw InputError(fmt::format("{} exists and is not empty; pass --force to overwrite it", out.string()));
      for (const fs::path& p : {out / "models", out / "test" / "000001", out / "camera.json"}) fs::remove_all(p, ec);
    }
  }
  for (const fs::path& p : {out / "models", out / "test" / "000001" / "rgb", out / "test" / "000001" / "depth"}) {
    fs::create_directories(p, ec);
    if (ec) throw InputError(fmt::format("cannot create {} ({})", p.string(), ec.message()));
  }
}

/// One image's scene: ground-truth instances first, then what is not in the ground truth.
struct ImageScene {
  std::vector<SceneObject> objects;
  std::vector<int> obj_ids;  ///< of the first obj_ids.size() objects: the ground truth
  int left_out = 0;
  std::deque<Mesh> owned;    ///< table, bin and clutter meshes (a deque: pointers stay valid)
  Pose camera_T_world;
  std::optional<BinBox> bin;  ///< the bin layout's bin (its frame is the world's)
  /// Scaled copies of the parts (SynthParams::scaled_copies): the objects right after the
  /// ground truth, in this order.
  std::vector<ScaledCopy> copies;
  std::size_t partsEnd() const { return obj_ids.size() + copies.size(); }

  void add(Mesh mesh, const Pose& world_T_object) {
    owned.push_back(std::move(mesh));
    objects.push_back({&owned.back(), compose(camera_T_world, world_T_object)});
  }
};

/// A table under everything the camera sees (a plane of 5 cm tiles at height z), up to 8 m across.
void addTable(ImageScene& s, const Camera& camera, float z, std::mt19937& rng) {
  const Pose world_T_camera = invert(s.camera_T_world);
  float reach = 0.f;
  for (const auto& [u, v] : {std::pair{0, 0}, {camera.width, 0}, {0, camera.height}, {camera.width, camera.height}}) {
    const Eigen::Vector3f ray = world_T_camera.R * camera.ray(u, v);
    const Eigen::Vector3f& o = world_T_camera.t;
    if (ray.z() >= -1e-3f) {
      reach = 4.f;
      break;
    }
    const Eigen::Vector3f hit = o + ((z - o.z()) / ray.z()) * ray;
    reach = std::max({reach, std::abs(hit.x()), std::abs(hit.y())});
  }
  Mesh table = planeMesh(std::min(8.f, 2.f * reach + 0.2f));
  const float grey = uniform(rng, 0.3f, 0.75f);
  table.colours.assign(table.vertices.size(), grey * Eigen::Vector3f(uniform(rng, 0.9f, 1.1f), 1.f, uniform(rng, 0.8f, 1.f)));
  Pose at;
  at.t.z() = z;
  s.add(std::move(table), at);
}

/// Bin walls and floor are made of tiles this large (see cuboidMesh).
constexpr float kBinTileM = 0.05f;

/// A box or a cylinder of a random size and colour: things on a table that are not the objects,
/// `scale` times the size of things that stand among 10-30 cm objects.
Mesh clutterMesh(std::mt19937& rng, float scale) {
  const Eigen::Vector3f colour = randomColour(rng, 0.1f, 0.9f);
  if (rng() % 2)
    // Braces: the three draws in order, as before there was a scale.
    return cuboidMesh(
        scale * Eigen::Vector3f{uniform(rng, 0.03f, 0.14f), uniform(rng, 0.03f, 0.14f), uniform(rng, 0.02f, 0.12f)},
        colour);
  // The same expression shape as before there was a scale, so the compiler draws in the same order.
  return cylinderMesh(scale * uniform(rng, 0.02f, 0.05f), scale * uniform(rng, 0.04f, 0.15f), colour);
}

/// Places clutter clear of `obstacles`, and adds it to the scene.
void addClutter(ImageScene& s, const SynthParams& p, const PlacementParams& placement,
                const std::vector<OrientedBox>& obstacles, float scale, std::mt19937& rng) {
  std::vector<Mesh> meshes;
  for (int i = 0; i < p.clutter; ++i) meshes.push_back(clutterMesh(rng, scale));
  std::vector<const Mesh*> pointers;
  for (const auto& m : meshes) pointers.push_back(&m);
  const auto poses = placeObjects(pointers, obstacles, placement, p.camera, s.camera_T_world, rng);
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (poses[i]) s.add(std::move(meshes[i]), *poses[i]);
}

/// Copies of random parts scaled by 0.8-0.9 or 1.1-1.2, placed clear of `obstacles` (which
/// they join), right after the ground truth.
void addScaledCopies(ImageScene& s, const SynthParams& p, const std::vector<Mesh>& models,
                     const PlacementParams& placement, std::vector<OrientedBox>& obstacles, std::mt19937& rng) {
  std::vector<Mesh> meshes;
  std::vector<ScaledCopy> copies;
  for (int i = 0; i < p.scaled_copies; ++i) {
    const int m = uniformInt(rng, 0, static_cast<int>(models.size()) - 1);
    const float lo = rng() % 2 ? 1.1f : 0.8f;
    const float scale = uniform(rng, lo, lo + 0.1f);
    Mesh copy = models[static_cast<std::size_t>(m)];
    for (auto& v : copy.vertices) v *= scale;
    finishMesh(copy);
    meshes.push_back(std::move(copy));
    copies.push_back({m + 1, scale, {}});
  }
  std::vector<const Mesh*> pointers;
  for (const auto& m : meshes) pointers.push_back(&m);
  const auto poses = placeObjects(pointers, obstacles, placement, p.camera, s.camera_T_world, rng);
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    if (!poses[i]) continue;
    obstacles.push_back(orientedBox(meshes[i], *poses[i]));
    copies[i].pose = compose(s.camera_T_world, *poses[i]);
    s.copies.push_back(copies[i]);
    s.add(std::move(meshes[i]), *poses[i]);
  }
}

std::string scaledCopiesJson(const std::vector<ScaledCopy>& copies) {
  std::string out = "[";
  for (std::size_t i = 0; i < copies.size(); ++i) {
    const ScaledCopy& c = copies[i];
    const Eigen::Matrix3f& R = c.pose.R;
    out += fmt::format(
        "{}\n  {{\"obj_id\": {}, \"scale\": {:.4f}, \"cam_R_m2c\": [{}, {}, {}, {}, {}, {}, {}, {}, {}], "
        "\"cam_t_m2c\": [{}, {}, {}]}}",
        i ? "," : "", c.obj_id, c.scale, R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1),
        R(2, 2), 1e3f * c.pose.t.x(), 1e3f * c.pose.t.y(), 1e3f * c.pose.t.z());
  }
  return out + "\n]\n";
}

ImageScene randomScene(const SynthParams& p, const std::vector<Mesh>& models, std::mt19937& rng) {
  ImageScene s;
  float diameter = 0.f;  // of the largest part
  for (const Mesh& m : models) diameter = std::max(diameter, m.diameter);
  PlacementParams placement = p.placement;
  const CameraRange camera_range = cameraRangeOf(p);
  if (p.placement.layout == Layout::Bin && p.fit_bin_to_parts)
    placement = fitBinToParts(p.placement, diameter, p.camera, camera_range);
  s.camera_T_world = randomCamera(camera_range, rng);
  std::vector<OrientedBox> obstacles;
  if (placement.layout == Layout::Bin) obstacles = binWalls(placement);
  std::vector<int> order;  // model indices, shuffled so no object is always placed first
  for (std::size_t m = 0; m < models.size(); ++m)
    for (int k = uniformInt(rng, p.min_instances, p.max_instances); k > 0; --k) order.push_back(static_cast<int>(m));
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng() % i]);
  std::vector<const Mesh*> meshes;
  for (const int m : order) meshes.push_back(&models[static_cast<std::size_t>(m)]);
  const auto poses = placeObjects(meshes, obstacles, placement, p.camera, s.camera_T_world, rng);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!poses[i]) {
      ++s.left_out;
      continue;
    }
    s.objects.push_back({meshes[i], compose(s.camera_T_world, *poses[i])});
    s.obj_ids.push_back(order[i] + 1);
    obstacles.push_back(orientedBox(*meshes[i], *poses[i]));
  }
  if (p.scaled_copies > 0) addScaledCopies(s, p, models, placement, obstacles, rng);
  // Clutter no larger than the parts when they are small (below 10 cm, where it used to dwarf them).
  addClutter(s, p, placement, obstacles, std::min(1.f, diameter / 0.1f), rng);
  if (placement.layout == Layout::Bin) {
    s.bin = BinBox{s.camera_T_world,
                   {placement.bin_inner_m.x(), placement.bin_inner_m.y(), placement.bin_wall_height_m},
                   placement.bin_wall_thickness_m};
    const Eigen::Vector3f colour = randomColour(rng, 0.2f, 0.7f);
    for (const OrientedBox& wall : binWalls(placement)) {
      Pose at;
      at.t = wall.centre;
      s.add(cuboidMesh(2.f * wall.half, colour, kBinTileM), at);
    }
    const float floor = placement.bin_wall_thickness_m;
    Pose at;
    at.t.z() = -0.5f * floor;
    s.add(cuboidMesh({placement.bin_inner_m.x() + 2 * floor, placement.bin_inner_m.y() + 2 * floor, floor}, colour,
                     kBinTileM),
          at);
    addTable(s, p.camera, -floor - 0.001f, rng);
  } else {
    addTable(s, p.camera, 0.f, rng);
  }
  return s;
}

/// Tejani poses verbatim; the table under them, clutter around them.
ImageScene tejaniScene(const SynthParams& p, const Mesh& model, int obj_id, const std::vector<Pose>& camera_T_object,
                       std::mt19937& rng) {
  ImageScene s;
  std::vector<const Mesh*> meshes(camera_T_object.size(), &model);
  s.camera_T_world = camera_T_object.empty() ? randomCamera(cameraRangeOf(p), rng) : supportFrame(meshes, camera_T_object);
  const Pose world_T_camera = invert(s.camera_T_world);
  std::vector<OrientedBox> obstacles;
  for (const Pose& pose : camera_T_object) {
    s.objects.push_back({&model, pose});
    s.obj_ids.push_back(obj_id);
    obstacles.push_back(orientedBox(model, compose(world_T_camera, pose)));
  }
  PlacementParams table = p.placement;
  table.layout = Layout::Table;
  addClutter(s, p, table, obstacles, std::min(1.f, model.diameter / 0.1f), rng);
  addTable(s, p.camera, 0.f, rng);
  return s;
}

/// A light from above the table at a random elevation and azimuth, random exposure and tint.
Lighting randomLighting(const Pose& camera_T_world, std::mt19937& rng) {
  const float elevation = uniform(rng, 30.f, 90.f) * kPi / 180.f, azimuth = uniform(rng, 0.f, 2.f * kPi);
  const Eigen::Vector3f from(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                             std::sin(elevation));
  Lighting light;
  light.direction = camera_T_world.R * -from;
  light.ambient = uniform(rng, 0.2f, 0.45f);
  light.diffuse = uniform(rng, 0.5f, 0.8f);
  light.specular = uniform(rng, 0.f, 0.25f);
  light.shininess = uniform(rng, 8.f, 40.f);
  const float exposure = uniform(rng, 0.8f, 1.15f);
  light.gain = exposure * randomColour(rng, 0.94f, 1.06f);
  return light;
}

/// The ground-truth entries of one rendered image.
void groundTruth(const ImageScene& s, const SceneRendering& r, const LinemodFrame& frame,
                 std::vector<GroundTruthPose>& gt, std::vector<GroundTruthInfo>& info) {
  for (std::size_t i = 0; i < s.obj_ids.size(); ++i) {
    GroundTruthPose g;
    g.obj_id = s.obj_ids[i];
    g.R = s.objects[i].pose.R;
    g.t = s.objects[i].pose.t;
    gt.push_back(g);
    GroundTruthInfo n;
    const cv::Mat& full = r.full_masks[i];
    const cv::Mat visible = r.instance == static_cast<uint16_t>(i + 1);
    n.px_count_all = r.full_pixels[i];
    n.px_count_visib = r.visible_pixels[i];
    n.px_count_valid = cv::countNonZero(full & (frame.depth_mm > 0));
    n.bbox_obj = n.px_count_all > 0 ? cv::boundingRect(full) : cv::Rect(-1, -1, -1, -1);
    n.bbox_visib = n.px_count_visib > 0 ? cv::boundingRect(visible) : cv::Rect(-1, -1, -1, -1);
    n.visib_fract = r.visibleFraction(i);
    g.visib_fract = n.visib_fract;
    info.push_back(n);
  }
}

}  // namespace

Camera tejaniCamera() {
  Camera c;
  c.fx = 571.9737;
  c.fy = 571.0073;
  c.cx = 319.5;
  c.cy = 239.5;
  c.width = 640;
  c.height = 480;
  c.depth_scale = 1.0;
  return c;
}

DepthNoiseParams synthNoise() {
  DepthNoiseParams n;
  n.grazing_start_deg = 65.f;
  n.grazing_dropout = 0.9f;
  n.holes = 8;
  n.hole_radius_px[0] = 2.f;
  n.hole_radius_px[1] = 10.f;
  n.max_range_m = 4.f;
  return n;
}

DepthNoiseParams synthNoise(const SensorParams& sensor) {
  DepthNoiseParams n = synthNoise();
  n.axial_sigma_at_1m = sensor.axial_sigma_at_1m;
  n.quantization_m = sensor.quantization_m;
  if (sensor.axial_sigma_at_1m == 0.f && sensor.quantization_m == 0.f) {
    n.edge_dropout = 0.f;
    n.grazing_dropout = 0.f;
    n.holes = 0;
  }
  return n;
}

DepthNoiseParams closeRangeNoise() {
  DepthNoiseParams n = synthNoise(sensorProfile("close-range"));
  n.matching_window_px = 9;
  n.edge_dropout = 0.5f;
  n.specular_lobe_deg = 20.f;
  n.specular_dropout = 0.9f;
  n.metal_dropout = 0.15f;
  n.max_range_m = 1.5f;
  return n;
}

DepthNoiseParams synthNoise(const std::string& sensor_name_or_file) {
  return sensor_name_or_file == "close-range" ? closeRangeNoise() : synthNoise(sensorProfile(sensor_name_or_file));
}

namespace {

/// Image `index` of a dataset: its scene, the rendering and the sensor frame, all drawn from
/// one generator seeded with (seed, index).
struct RenderedImage {
  ImageScene scene;
  SceneRendering rendering;
  LinemodFrame frame;
};

RenderedImage renderImage(const GpuContext& ctx, const SynthParams& p, const std::vector<Mesh>& models,
                          const std::vector<Pose>& tejani_poses, int index, const Camera& camera) {
  std::seed_seq seq{p.seed, static_cast<uint32_t>(index), 0x5e7du};
  std::mt19937 rng(seq);
  const std::size_t m = static_cast<std::size_t>(index) % models.size();
  RenderedImage out;
  out.scene = p.poses == "random" ? randomScene(p, models, rng)
                                  : tejaniScene(p, models[m], static_cast<int>(m) + 1, tejani_poses, rng);
  out.rendering = renderScene(ctx, out.scene.objects, camera);
  if (p.metal_parts) markMetal(out.rendering, 0, out.scene.partsEnd());
  applyLighting(out.rendering, randomLighting(out.scene.camera_T_world, rng));
  out.frame = sensorFrame(out.rendering, p.noise, static_cast<uint32_t>(rng()));
  if (p.greyscale) toGreyscale(out.frame);
  return out;
}

}  // namespace

CameraRange cameraAtDistances(float near_m, float far_m) {
  CameraRange r;
  r.min_distance_m = near_m;
  r.max_distance_m = far_m;
  return r;
}

CameraRange binCellCamera() {
  CameraRange r = cameraAtDistances(0.8f, 1.0f);
  r.max_tilt_deg = 15.f;
  return r;
}

CameraRange cameraRangeOf(const SynthParams& params) {
  if (params.camera_range) return *params.camera_range;
  return params.placement.layout == Layout::Bin ? binCellCamera() : CameraRange{};
}

PlacementParams fitBinToParts(const PlacementParams& placement, float diameter, const Camera& camera,
                              const CameraRange& range) {
  const float nearest = range.max_distance_m > 0.f ? range.min_distance_m : range.min_height_m;
  const Eigen::Vector2f view = camera.viewExtent(nearest);
  PlacementParams out = placement;
  for (int i = 0; i < 2; ++i)
    out.bin_inner_m[i] = std::min(placement.bin_inner_m[i], std::max(4.f * diameter, 0.7f * view[i]));
  // Walls shrink with the bin, to 4 cm at the least.
  const float scale = std::min(out.bin_inner_m.x() / placement.bin_inner_m.x(), out.bin_inner_m.y() / placement.bin_inner_m.y());
  if (scale < 1.f) out.bin_wall_height_m = std::max(std::min(0.04f, placement.bin_wall_height_m), scale * placement.bin_wall_height_m);
  return out;
}

void validateSynthParams(const SynthParams& p) {
  if (p.meshes.empty()) throw InputError("synth needs at least one mesh");
  if (p.images < 1) throw InputError(fmt::format("--images must be 1 or more, not {}", p.images));
  if (p.min_instances < 0 || p.max_instances < p.min_instances || p.max_instances > 50)
    throw InputError(fmt::format("instances per mesh {}..{}: need 0 <= min <= max <= 50", p.min_instances,
                                 p.max_instances));
  if (p.clutter < 0 || p.clutter > 50) throw InputError(fmt::format("clutter {} is outside 0..50", p.clutter));
  if (p.scaled_copies < 0 || p.scaled_copies > 50)
    throw InputError(fmt::format("scaled copies {} is outside 0..50", p.scaled_copies));
  if (p.scaled_copies > 0 && p.poses != "random")
    throw InputError("scaled copies are placed among random placements: use them with --poses random");
  const DepthNoiseParams& n = p.noise;
  if (n.matching_window_px < 0 || n.matching_window_px > 31 || !(n.specular_dropout >= 0.f && n.specular_dropout <= 1.f) ||
      !(n.metal_dropout >= 0.f && n.metal_dropout <= 1.f) || !(n.specular_lobe_deg >= 0.f && n.specular_lobe_deg <= 90.f))
    throw InputError("sensor noise: the matching window is 0 to 31 pixels, dropouts are shares of 0 to 1 and the "
                     "specular lobe 0 to 90 degrees");
  for (const int id : p.symmetric)
    if (id < 1 || id > static_cast<int>(p.meshes.size()))
      throw InputError(fmt::format("--symmetric {}: obj_ids are 1..{} (the meshes in order)", id, p.meshes.size()));
  if (p.poses != "random") {
    std::error_code ec;
    if (!fs::is_directory(p.poses, ec))
      throw InputError(fmt::format("--poses {}: neither 'random' nor a folder of pose files", p.poses));
    if (p.placement.layout == Layout::Bin)
      throw InputError("the bin layout places objects itself: use it with --poses random");
  }
  validateCamera(p.camera, "synth camera");
  const CameraRange c = cameraRangeOf(p);
  if (c.max_distance_m > 0.f && !(c.min_distance_m >= 0.1f && c.min_distance_m <= c.max_distance_m &&
                                  c.max_distance_m <= 5.f))
    throw InputError(fmt::format("camera distance {}:{} m: need 0.1 <= FROM <= TO <= 5", c.min_distance_m,
                                 c.max_distance_m));
  const PlacementParams& b = p.placement;
  if (!(b.bin_inner_m.x() >= 0.02f && b.bin_inner_m.y() >= 0.02f && b.bin_inner_m.maxCoeff() <= 3.f &&
        b.bin_wall_height_m >= 0.f && b.bin_wall_height_m <= 1.f))
    throw InputError(fmt::format("bin {} x {} m, walls {} m: need sides of 0.02 to 3 m and walls of 0 to 1 m",
                                 b.bin_inner_m.x(), b.bin_inner_m.y(), b.bin_wall_height_m));
}

std::vector<std::vector<std::string>> tejaniPoseFiles(const std::string& dir,
                                                      const std::vector<std::string>& mesh_names) {
  const fs::path root(dir);
  if (std::vector<std::string> own = poseFilesIn(root); !own.empty()) {
    if (mesh_names.size() != 1)
      throw InputError(fmt::format("{} holds pose files of one object, but {} meshes were given: pass its parent "
                                   "folder, with a folder per mesh",
                                   dir, mesh_names.size()));
    return {own};
  }
  std::vector<fs::path> folders;
  std::error_code ec;
  for (fs::directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_directory(ec)) folders.push_back(it->path());
  std::sort(folders.begin(), folders.end());
  std::vector<std::vector<std::string>> out;
  for (const auto& name : mesh_names) {
    const auto it = std::find_if(folders.begin(), folders.end(), [&](const fs::path& f) {
      return normalisedName(f.filename().string()) == normalisedName(name);
    });
    if (it == folders.end()) {
      std::string have;
      for (const auto& f : folders) have += (have.empty() ? "" : ", ") + f.filename().string();
      throw InputError(fmt::format("{}: no pose files (posesN.txt) and no folder for mesh '{}' (folders: {})", dir,
                                   name, have.empty() ? "none" : have));
    }
    std::vector<std::string> files = poseFilesIn(*it);
    if (files.empty()) throw InputError(fmt::format("{}: no pose files (posesN.txt)", it->string()));
    out.push_back(std::move(files));
  }
  return out;
}

SynthSummary generateSyntheticDataset(const GpuContext& ctx, const SynthParams& p, const std::string& out_dir,
                                      bool overwrite, const std::function<void(int, int)>& progress) {
  validateSynthParams(p);
  SynthSummary summary;
  std::vector<Mesh> models;
  for (std::size_t i = 0; i < p.meshes.size(); ++i) {
    MeshLoadReport report;
    Mesh m = loadMesh(p.meshes[i], p.units, &report);
    // A mesh's own colours are its albedo; an uncoloured one (an STL) gets one of kAlbedos.
    if (m.colours.size() != m.vertices.size()) m.colours.assign(m.vertices.size(), kAlbedos[i % std::size(kAlbedos)]);
    models.push_back(std::move(m));
    summary.mesh_reports.push_back(report);
  }
  // Tejani: every pose file an image needs, read (and so checked) before anything is written.
  std::vector<std::vector<Pose>> tejani(static_cast<std::size_t>(p.images));
  if (p.poses != "random") {
    std::vector<std::string> names;
    for (const auto& m : models) names.push_back(m.name);
    const auto files = tejaniPoseFiles(p.poses, names);
    const std::size_t M = models.size();
    for (std::size_t i = 0; i < tejani.size(); ++i) {
      const auto& list = files[i % M];
      const std::size_t needed = (static_cast<std::size_t>(p.images) - 1 - i % M) / M + 1;
      if (list.size() < needed)
        throw InputError(fmt::format("--images {} needs {} pose files for '{}', {} has {}", p.images, needed,
                                     models[i % M].name, fs::path(list.front()).parent_path().string(), list.size()));
      tejani[i] = loadTejaniPoses(list[i / M]);
    }
  }

  Camera camera = p.camera;
  camera.depth_scale = 1.0;  // the depth PNGs are written in millimetres
  const fs::path out(out_dir), scene_dir = out / "test" / "000001";
  prepareOutput(out, overwrite);
  std::vector<BopModel> bop_models;
  for (std::size_t i = 0; i < models.size(); ++i) {
    const int obj_id = static_cast<int>(i) + 1;
    BopModel bm{obj_id, &models[i], {}};
    if (std::find(p.symmetric.begin(), p.symmetric.end(), obj_id) != p.symmetric.end())
      bm.symmetries.push_back({Eigen::Vector3f::UnitZ(), models[i].bboxCentre()});
    else  // a turn that gives the same picture (the key's half-turn) is no wrong pose: BOP's convention
      for (const NearSymmetry& s : exactSymmetries(models[i], 0.002f * models[i].diameter))
        bm.discrete_symmetries.push_back(s.transform());
    bop_models.push_back(bm);
    writePlyMillimetres(models[i], (out / "models" / fmt::format("obj_{:06d}.ply", obj_id)).string(), false);
  }
  writeTextFile((out / "models" / "models_info.json").string(), modelsInfoJson(bop_models), false);
  writeTextFile((out / "camera.json").string(), cameraJson(camera), false);

  std::map<int, std::vector<GroundTruthPose>> gt;
  std::map<int, std::vector<GroundTruthInfo>> info;
  std::map<int, Camera> cameras;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < p.images; ++i) {
    const RenderedImage image = renderImage(ctx, p, models, tejani[static_cast<std::size_t>(i)], i, camera);
    const ImageScene& s = image.scene;
    const LinemodFrame& frame = image.frame;
    summary.left_out += s.left_out;
    groundTruth(s, image.rendering, frame, gt[i], info[i]);
    cameras[i] = camera;
    summary.instances += static_cast<int>(s.obj_ids.size());
    for (std::size_t k = 0; k < s.obj_ids.size(); ++k) {
      const SceneObject& o = s.objects[k];
      const float d = (o.pose.R * o.mesh->bboxCentre() + o.pose.t).norm();
      summary.nearest_m = summary.nearest_m > 0.f ? std::min(summary.nearest_m, d) : d;
      summary.farthest_m = std::max(summary.farthest_m, d);
    }
    writeImage((scene_dir / "rgb" / fmt::format("{:06d}.png", i)).string(), frame.bgr, false);
    writeImage((scene_dir / "depth" / fmt::format("{:06d}.png", i)).string(), frame.depth_mm, false);
    if (s.bin) {  // where the bin is, for `vkpose detect --bin` (not a BOP file)
      fs::create_directories(scene_dir / "bin");
      writeTextFile((scene_dir / "bin" / fmt::format("{:06d}.json", i)).string(), binJson(*s.bin), false);
    }
    if (p.scaled_copies > 0) {  // where the scaled copies are, for `vkpose eval` (not a BOP file)
      fs::create_directories(scene_dir / "scaled");
      writeTextFile((scene_dir / "scaled" / fmt::format("{:06d}.json", i)).string(), scaledCopiesJson(s.copies),
                    false);
    }
    if (progress) progress(i + 1, p.images);
  }
  writeTextFile((scene_dir / "scene_gt.json").string(), sceneGtJson(gt), false);
  writeTextFile((scene_dir / "scene_gt_info.json").string(), sceneGtInfoJson(info), false);
  writeTextFile((scene_dir / "scene_camera.json").string(), sceneCameraJson(cameras), false);
  summary.images = p.images;
  summary.ms_per_image =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / p.images;
  return summary;
}

std::optional<BinBox> loadSynthBin(const BopImage& image) {
  const fs::path file =
      fs::path(image.rgb_path).parent_path().parent_path() / "bin" / fmt::format("{:06d}.json", image.image_id);
  if (!fs::exists(file)) return std::nullopt;
  return loadBin(file.string());
}

std::vector<ScaledCopy> loadScaledCopies(const BopImage& image) {
  const fs::path file =
      fs::path(image.rgb_path).parent_path().parent_path() / "scaled" / fmt::format("{:06d}.json", image.image_id);
  if (!fs::exists(file)) return {};
  std::ifstream in(file);
  std::vector<ScaledCopy> out;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& c : j) {
      ScaledCopy copy;
      copy.obj_id = c.at("obj_id").get<int>();
      copy.scale = c.at("scale").get<float>();
      const auto R = c.at("cam_R_m2c").get<std::vector<float>>();
      const auto t = c.at("cam_t_m2c").get<std::vector<float>>();
      if (R.size() != 9 || t.size() != 3) throw InputError("cam_R_m2c needs 9 numbers and cam_t_m2c 3");
      for (int k = 0; k < 9; ++k) copy.pose.R(k / 3, k % 3) = R[static_cast<std::size_t>(k)];
      copy.pose.t = 1e-3f * Eigen::Vector3f(t[0], t[1], t[2]);
      out.push_back(copy);
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not a list of scaled copies ({})", file.string(), e.what()));
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", file.string(), e.what()));
  }
  return out;
}

int scaledCopiesReported(const std::vector<ScaledCopy>& copies, const std::vector<Detection>& detections,
                         const std::vector<TemplateBank>& banks, const std::map<int, int>& banks_by_obj_id,
                         float min_score) {
  int reported = 0;
  for (const ScaledCopy& c : copies) {
    const auto it = banks_by_obj_id.find(c.obj_id);
    if (it == banks_by_obj_id.end()) continue;
    const TemplateBank& bank = banks[static_cast<std::size_t>(it->second)];
    const Eigen::Vector3f centre = bank.mesh.bboxCentre();
    const Eigen::Vector3f copy_centre = c.pose.R * (c.scale * centre) + c.pose.t;
    const bool hit = std::any_of(detections.begin(), detections.end(), [&](const Detection& d) {
      return d.bank == it->second && d.score >= min_score &&
             (d.pose.R * centre + d.pose.t - copy_centre).norm() < 0.25f * bank.diameter;
    });
    reported += hit ? 1 : 0;
  }
  return reported;
}

SynthImage synthesizeImage(const GpuContext& ctx, const SynthParams& params, const std::vector<Mesh>& models,
                           int index) {
  if (models.empty()) throw InputError("synthesizeImage needs at least one mesh");
  if (params.poses != "random") throw InputError("synthesizeImage places objects itself: use poses \"random\"");
  SynthParams p = params;
  p.meshes.assign(models.size(), "model");  // validated as given, not read from files
  p.images = std::max(p.images, index + 1);
  validateSynthParams(p);
  std::vector<Mesh> coloured = models;
  for (std::size_t i = 0; i < coloured.size(); ++i)
    if (coloured[i].colours.size() != coloured[i].vertices.size())
      coloured[i].colours.assign(coloured[i].vertices.size(), kAlbedos[i % std::size(kAlbedos)]);
  Camera camera = p.camera;
  camera.depth_scale = 1.0;
  RenderedImage image = renderImage(ctx, p, coloured, {}, index, camera);
  SynthImage out;
  out.frame = std::move(image.frame);
  out.camera = camera;
  out.bin = image.scene.bin;
  for (std::size_t i = 0; i < image.scene.obj_ids.size(); ++i) {
    out.obj_ids.push_back(image.scene.obj_ids[i]);
    out.poses.push_back(image.scene.objects[i].pose);
  }
  return out;
}

}  // namespace vkpose
