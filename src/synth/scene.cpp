// Synthetic multi-object scenes and sensor noise.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "render/render.hpp"
#include "synth/scene.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {

bool touchesBorder(const cv::Mat& mask) {
  const int w = mask.cols, h = mask.rows;
  return cv::countNonZero(mask.row(0)) > 0 || cv::countNonZero(mask.row(h - 1)) > 0 ||
         cv::countNonZero(mask.col(0)) > 0 || cv::countNonZero(mask.col(w - 1)) > 0;
}

}  // namespace

SceneRendering renderScene(const GpuContext& ctx, const std::vector<SceneObject>& objects, const Camera& camera) {
  validateCamera(camera);
  const cv::Size size(camera.width, camera.height);
  SceneRendering out;
  out.camera = camera;
  out.depth = cv::Mat::zeros(size, CV_32FC1);
  out.normals = cv::Mat::zeros(size, CV_32FC3);
  out.bgr = cv::Mat::zeros(size, CV_8UC3);
  out.instance = cv::Mat::zeros(size, CV_16UC1);
  out.visible_pixels.assign(objects.size(), 0);
  out.full_pixels.assign(objects.size(), 0);
  out.full_masks.assign(objects.size(), cv::Mat());
  if (objects.size() > 65535) throw InputError("a scene holds at most 65535 objects");

  // One renderer per distinct mesh, all of its poses in one call. Meshes go in the order they
  // first appear, not by address: where two surfaces are at the same depth the earlier object
  // wins, the same in every run.
  std::vector<std::pair<const Mesh*, std::vector<std::size_t>>> by_mesh;
  std::map<const Mesh*, std::size_t> group;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (!objects[i].mesh) throw InputError("scene object " + std::to_string(i) + " has no mesh");
    const auto [it, added] = group.emplace(objects[i].mesh, by_mesh.size());
    if (added) by_mesh.push_back({objects[i].mesh, {}});
    by_mesh[it->second].second.push_back(i);
  }
  for (const auto& [mesh, indices] : by_mesh) {
    MeshRenderer renderer(ctx, *mesh);
    std::vector<Pose> poses;
    for (std::size_t i : indices) poses.push_back(objects[i].pose);
    const std::vector<Rendering> views = renderer.render(camera, poses);
    std::vector<std::size_t> cut_off;  // objects the image's border cuts
    for (std::size_t k = 0; k < indices.size(); ++k) {
      const Rendering& r = views[k];
      const auto label = static_cast<uint16_t>(indices[k] + 1);
      out.full_masks[indices[k]] = r.mask();
      out.full_pixels[indices[k]] = cv::countNonZero(out.full_masks[indices[k]]);
      if (touchesBorder(out.full_masks[indices[k]])) cut_off.push_back(indices[k]);
      for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
          const float z = r.depth.at<float>(y, x);
          float& best = out.depth.at<float>(y, x);
          if (z > 0.f && (best == 0.f || z < best)) {
            best = z;
            out.bgr.at<cv::Vec3b>(y, x) = r.bgr.at<cv::Vec3b>(y, x);
            out.normals.at<cv::Vec3f>(y, x) = r.normals.at<cv::Vec3f>(y, x);
            out.instance.at<uint16_t>(y, x) = label;
          }
        }
    }
    // What the object would cover alone counts the part the border cuts off as well, as BOP's
    // px_count_all does (its calc_gt_info renders into an image three times as wide and high):
    // an instance half out of the image is half visible, not wholly.
    if (!cut_off.empty()) {
      Camera wide = camera;
      wide.width = 3 * camera.width;
      wide.height = 3 * camera.height;
      wide.cx += camera.width;
      wide.cy += camera.height;
      std::vector<Pose> cut_poses;
      for (std::size_t i : cut_off) cut_poses.push_back(objects[i].pose);
      const std::vector<Rendering> whole = renderer.render(wide, cut_poses);
      for (std::size_t k = 0; k < cut_off.size(); ++k)
        out.full_pixels[cut_off[k]] = std::max(out.full_pixels[cut_off[k]], cv::countNonZero(whole[k].mask()));
    }
  }
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      if (const uint16_t l = out.instance.at<uint16_t>(y, x)) ++out.visible_pixels[l - 1u];
  return out;
}

Mesh planeMesh(float size, float grey) {
  if (!(size > 0.f) || size > 100.f) throw InputError("plane size must be in (0, 100] metres");
  // Tiles of at most 5 cm: the rasterizer clips a triangle at the camera's near plane, but
  // drops one with a corner far outside the image (beyond its guard band of about a million
  // pixels), so a large plane must be made of small pieces.
  const int n = std::max(1, static_cast<int>(std::ceil(size / 0.05f)));
  Mesh m;
  m.name = "plane";
  const float step = size / static_cast<float>(n), h = 0.5f * size;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      m.vertices.emplace_back(-h + static_cast<float>(j) * step, -h + static_cast<float>(i) * step, 0.f);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
      m.faces.emplace_back(a, b, d);
      m.faces.emplace_back(a, d, c);
    }
  m.colours.assign(m.vertices.size(), Eigen::Vector3f::Constant(grey));
  finishMesh(m);
  return m;
}

Mesh cuboidMesh(const Eigen::Vector3f& size, const Eigen::Vector3f& rgb, float max_tile_m) {
  if (!(size.minCoeff() > 0.f) || size.maxCoeff() > 10.f) throw InputError("cuboid sides must be in (0, 10] metres");
  if (!(max_tile_m >= 0.f)) throw InputError("a cuboid's tile size must be 0 (none) or positive");
  Mesh m;
  m.name = "cuboid";
  const Eigen::Vector3f h = 0.5f * size;
  const auto tiles = [&](int axis) {
    return max_tile_m > 0.f ? std::max(1, static_cast<int>(std::ceil(size[axis] / max_tile_m))) : 1;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (const float sign : {-1.f, 1.f}) {
      // The face at sign * h[axis]; u, v span it so that (u x v) points outwards.
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      Eigen::Vector3f n = Eigen::Vector3f::Zero(), u = Eigen::Vector3f::Zero(), v = Eigen::Vector3f::Zero();
      n[axis] = sign;
      u[a] = h[a];
      v[b] = sign * h[b];
      // Each tile its own four corners, in the order an untiled face has always had (the demo's
      // meshes in assets/ stay byte for byte what they were).
      const int nu = tiles(a), nv = tiles(b);
      const auto at = [](int k, int count) { return -1.f + 2.f * static_cast<float>(k) / static_cast<float>(count); };
      for (int i = 0; i < nv; ++i)
        for (int j = 0; j < nu; ++j) {
          const int base = static_cast<int>(m.vertices.size());
          for (const auto& [cu, cv] : {std::pair{j, i}, {j + 1, i}, {j + 1, i + 1}, {j, i + 1}}) {
            m.vertices.push_back(n.cwiseProduct(h) + at(cu, nu) * u + at(cv, nv) * v);
            m.normals.push_back(n);
          }
          m.faces.emplace_back(base, base + 1, base + 2);
          m.faces.emplace_back(base, base + 2, base + 3);
        }
    }
  m.colours.assign(m.vertices.size(), rgb);
  finishMesh(m);
  return m;
}

Mesh cylinderMesh(float radius, float height, const Eigen::Vector3f& rgb, int segments) {
  if (!(radius > 0.f && height > 0.f) || radius > 10.f || height > 10.f || segments < 3)
    throw InputError("a cylinder needs a radius and height in (0, 10] metres and 3 or more segments");
  Mesh m;
  m.name = "cylinder";
  const float h = 0.5f * height;
  const auto ring = [&](int i) {
    const float a = 2.f * std::numbers::pi_v<float> * static_cast<float>(i) / static_cast<float>(segments);
    return Eigen::Vector2f(std::cos(a), std::sin(a));
  };
  for (int i = 0; i < segments; ++i) {  // side: two vertices per segment with radial normals
    const Eigen::Vector2f c = ring(i);
    for (const float z : {-h, h}) {
      m.vertices.emplace_back(radius * c.x(), radius * c.y(), z);
      m.normals.emplace_back(c.x(), c.y(), 0.f);
    }
  }
  for (int i = 0; i < segments; ++i) {
    const int a = 2 * i, b = 2 * ((i + 1) % segments);
    m.faces.emplace_back(a, b, b + 1);
    m.faces.emplace_back(a, b + 1, a + 1);
  }
  for (const float sign : {-1.f, 1.f}) {  // caps: a centre and a ring with axial normals
    const int centre = static_cast<int>(m.vertices.size());
    m.vertices.emplace_back(0.f, 0.f, sign * h);
    m.normals.emplace_back(0.f, 0.f, sign);
    for (int i = 0; i < segments; ++i) {
      const Eigen::Vector2f c = ring(i);
      m.vertices.emplace_back(radius * c.x(), radius * c.y(), sign * h);
      m.normals.emplace_back(0.f, 0.f, sign);
    }
    for (int i = 0; i < segments; ++i) {
      const int a = centre + 1 + i, b = centre + 1 + (i + 1) % segments;
      if (sign > 0.f) m.faces.emplace_back(centre, a, b);
      else m.faces.emplace_back(centre, b, a);
    }
  }
  m.colours.assign(m.vertices.size(), rgb);
  finishMesh(m);
  return m;
}

MetalLighting metalLighting(const Lighting& light) {
  MetalLighting m;
  m.light = light;
  m.light.ambient = 0.6f * light.ambient;
  m.light.diffuse = 0.4f * light.diffuse;
  m.light.specular = 0.6f + light.specular;
  m.light.shininess = 2.f * light.shininess;
  return m;
}

void markMetal(SceneRendering& scene, std::size_t first, std::size_t last) {
  if (scene.metal.empty()) scene.metal = cv::Mat::zeros(scene.instance.size(), CV_8UC1);
  for (int y = 0; y < scene.instance.rows; ++y)
    for (int x = 0; x < scene.instance.cols; ++x) {
      const std::size_t label = scene.instance.at<uint16_t>(y, x);
      if (label > first && label <= last) scene.metal.at<uint8_t>(y, x) = 255;
    }
}

void applyLighting(SceneRendering& scene, const Lighting& light) {
  if (scene.normals.size() != scene.bgr.size()) throw InputError("applyLighting: the scene has no normals");
  const bool any_metal = scene.metal.size() == scene.bgr.size();
  const MetalLighting metal = metalLighting(light);
  const Eigen::Vector3f to_light = -light.direction.normalized();
  const Camera& cam = scene.camera;
  for (int y = 0; y < scene.bgr.rows; ++y)
    for (int x = 0; x < scene.bgr.cols; ++x) {
      if (scene.depth.at<float>(y, x) <= 0.f) continue;
      const bool is_metal = any_metal && scene.metal.at<uint8_t>(y, x) != 0;
      const Lighting& l = is_metal ? metal.light : light;
      const cv::Vec3f& nv = scene.normals.at<cv::Vec3f>(y, x);
      const Eigen::Vector3f n(nv[0], nv[1], nv[2]);
      const float lambert = std::max(0.f, n.dot(to_light));
      // Phong: the light mirrored about the normal against the direction to the camera.
      const Eigen::Vector3f to_eye = -cam.ray(x, y).normalized();
      const Eigen::Vector3f mirrored = 2.f * n.dot(to_light) * n - to_light;
      float highlight =
          lambert > 0.f ? l.specular * 255.f * std::pow(std::max(0.f, mirrored.dot(to_eye)), l.shininess) : 0.f;
      cv::Vec3b& c = scene.bgr.at<cv::Vec3b>(y, x);
      if (is_metal) {
        // Grey metal; the lamp beside the lens mirrors back from whatever faces the camera.
        highlight += metal.headlight * 255.f * std::pow(std::max(0.f, n.dot(to_eye)), metal.headlight_shininess);
        const float grey = 0.114f * c[0] + 0.587f * c[1] + 0.299f * c[2];
        c = cv::Vec3b::all(cv::saturate_cast<uint8_t>(grey));
      }
      for (int k = 0; k < 3; ++k)
        c[k] = cv::saturate_cast<uint8_t>(c[k] * l.gain[k] * (l.ambient + l.diffuse * lambert) + highlight);
    }
}

cv::Mat windowMedianDepth(const cv::Mat& depth, int window) {
  if (window <= 1) return depth.clone();
  const int r = window / 2;
  // Only where the window spans a depth change (more than a millimetre) can the median differ
  // from the centre by more than the noise; elsewhere the input stands.
  cv::Mat lo, hi, holes_near;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * r + 1, 2 * r + 1));
  const cv::Mat holes = depth <= 0.f;
  cv::Mat filled = depth.clone();
  filled.setTo(1e6f, holes);
  cv::erode(filled, lo, kernel);
  cv::dilate(depth, hi, kernel);
  cv::dilate(holes, holes_near, kernel);
  cv::Mat out = depth.clone();
  std::vector<float> values;
  values.reserve(static_cast<std::size_t>((2 * r + 1) * (2 * r + 1)));
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      if (!holes_near.at<uint8_t>(y, x) && hi.at<float>(y, x) - lo.at<float>(y, x) <= 1e-3f) continue;
      values.clear();
      int cells = 0;
      for (int v = std::max(0, y - r); v <= std::min(depth.rows - 1, y + r); ++v)
        for (int u = std::max(0, x - r); u <= std::min(depth.cols - 1, x + r); ++u) {
          ++cells;
          if (const float z = depth.at<float>(v, u); z > 0.f) values.push_back(z);
        }
      if (2 * values.size() <= static_cast<std::size_t>(cells)) {
        out.at<float>(y, x) = 0.f;
        continue;
      }
      const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
      std::nth_element(values.begin(), mid, values.end());
      out.at<float>(y, x) = *mid;
    }
  return out;
}

void toGreyscale(LinemodFrame& frame) {
  cv::Mat grey;
  cv::cvtColor(frame.bgr, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(grey, frame.bgr, cv::COLOR_GRAY2BGR);
}

namespace {
/// Drops the readings that grazing angles and random holes lose. Its own random stream
/// (seeded from the frame's), so that turning these on leaves the other noise as it was.
void dropGrazingAndHoles(const SceneRendering& scene, const DepthNoiseParams& noise, uint32_t seed, cv::Mat& depth_mm) {
  if (noise.grazing_dropout <= 0.f && noise.holes <= 0) return;
  std::mt19937 rng(seed ^ 0x9e3779b9u);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  const Camera& cam = scene.camera;
  if (noise.grazing_dropout > 0.f && scene.normals.size() == depth_mm.size()) {
    const float start = std::cos(noise.grazing_start_deg * std::numbers::pi_v<float> / 180.f);
    for (int y = 0; y < depth_mm.rows; ++y)
      for (int x = 0; x < depth_mm.cols; ++x) {
        if (scene.depth.at<float>(y, x) <= 0.f) continue;
        const cv::Vec3f& n = scene.normals.at<cv::Vec3f>(y, x);
        const Eigen::Vector3f ray = cam.ray(x, y).normalized();
        const float cos_angle = std::abs(n[0] * ray.x() + n[1] * ray.y() + n[2] * ray.z());
        const float u = uniform(rng);  // drawn for every surface pixel: reproducible layout
        if (cos_angle < start && u < noise.grazing_dropout * (start - cos_angle) / start)
          depth_mm.at<uint16_t>(y, x) = 0;
      }
  }
  const float r0 = noise.hole_radius_px[0], r1 = std::max(r0, noise.hole_radius_px[1]);
  for (int h = 0; h < noise.holes; ++h) {
    const cv::Point centre(static_cast<int>(uniform(rng) * static_cast<float>(depth_mm.cols)),
                           static_cast<int>(uniform(rng) * static_cast<float>(depth_mm.rows)));
    const cv::Size axes(static_cast<int>(std::lround(r0 + (r1 - r0) * uniform(rng))),
                        static_cast<int>(std::lround(r0 + (r1 - r0) * uniform(rng))));
    cv::ellipse(depth_mm, centre, axes, 180.0 * uniform(rng), 0, 360, cv::Scalar(0), cv::FILLED);
  }
}

/// What bare metal loses (DepthNoiseParams::specular_dropout, metal_dropout): its own random
/// stream, as dropGrazingAndHoles'.
void dropOnMetal(const SceneRendering& scene, const DepthNoiseParams& noise, uint32_t seed, cv::Mat& depth_mm) {
  if (scene.metal.size() != depth_mm.size() || (noise.specular_dropout <= 0.f && noise.metal_dropout <= 0.f)) return;
  std::mt19937 rng(seed ^ 0x6d657461u);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  const float lobe = std::cos(noise.specular_lobe_deg * std::numbers::pi_v<float> / 180.f);
  std::vector<cv::Point> metal;
  for (int y = 0; y < depth_mm.rows; ++y)
    for (int x = 0; x < depth_mm.cols; ++x) {
      if (!scene.metal.at<uint8_t>(y, x)) continue;
      metal.emplace_back(x, y);
      const cv::Vec3f& n = scene.normals.at<cv::Vec3f>(y, x);
      const Eigen::Vector3f ray = scene.camera.ray(x, y).normalized();
      const float facing = std::abs(n[0] * ray.x() + n[1] * ray.y() + n[2] * ray.z());
      if (facing > lobe && uniform(rng) < noise.specular_dropout) depth_mm.at<uint16_t>(y, x) = 0;
    }
  // Blobs of radius 1-2 pixels (about 7 pixels each) until metal_dropout of the metal is hit.
  const auto blobs = static_cast<std::size_t>(noise.metal_dropout * static_cast<float>(metal.size()) / 7.f);
  for (std::size_t b = 0; b < blobs && !metal.empty(); ++b) {
    const cv::Point c = metal[std::min(metal.size() - 1, static_cast<std::size_t>(uniform(rng) * static_cast<float>(metal.size())))];
    const int radius = uniform(rng) < 0.5f ? 1 : 2;
    for (int v = std::max(0, c.y - radius); v <= std::min(depth_mm.rows - 1, c.y + radius); ++v)
      for (int u = std::max(0, c.x - radius); u <= std::min(depth_mm.cols - 1, c.x + radius); ++u)
        if ((u - c.x) * (u - c.x) + (v - c.y) * (v - c.y) <= radius * radius && scene.metal.at<uint8_t>(v, u))
          depth_mm.at<uint16_t>(v, u) = 0;
  }
}
}  // namespace

LinemodFrame sensorFrame(const SceneRendering& scene, const DepthNoiseParams& noise, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss(0.f, 1.f);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  const cv::Mat z = noise.matching_window_px > 1 ? windowMedianDepth(scene.depth, noise.matching_window_px) : scene.depth;
  LinemodFrame f;
  f.depth_mm = cv::Mat::zeros(z.size(), CV_16UC1);
  for (int y = 0; y < z.rows; ++y)
    for (int x = 0; x < z.cols; ++x) {
      const float d = z.at<float>(y, x);
      if (d <= 0.f || (noise.max_range_m > 0.f && d > noise.max_range_m)) continue;
      bool edge = false;
      for (int dy = -1; dy <= 1 && !edge; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, v = y + dy;
          if (u < 0 || v < 0 || u >= z.cols || v >= z.rows) continue;
          const float n = z.at<float>(v, u);
          if (n <= 0.f || std::abs(n - d) > noise.edge_jump_m) {
            edge = true;
            break;
          }
        }
      const float sigma = noise.axial_sigma_at_1m * d * d;
      const float g = gauss(rng), u = uniform(rng);  // drawn for every pixel: reproducible layout
      if (edge && u < noise.edge_dropout) continue;
      float noisy = d + sigma * g;
      if (noise.quantization_m > 0.f) noisy = std::round(noisy / noise.quantization_m) * noise.quantization_m;
      f.depth_mm.at<uint16_t>(y, x) = static_cast<uint16_t>(std::clamp(std::lround(noisy * 1000.f), 0l, 65535l));
    }
  dropGrazingAndHoles(scene, noise, seed, f.depth_mm);
  dropOnMetal(scene, noise, seed, f.depth_mm);
  f.bgr = cv::Mat(scene.bgr.size(), CV_8UC3);
  for (int y = 0; y < f.bgr.rows; ++y)
    for (int x = 0; x < f.bgr.cols; ++x)
      for (int c = 0; c < 3; ++c)
        f.bgr.at<cv::Vec3b>(y, x)[c] =
            cv::saturate_cast<uint8_t>(scene.bgr.at<cv::Vec3b>(y, x)[c] + noise.colour_sigma * gauss(rng));
  return f;
}

}  // namespace vkpose
