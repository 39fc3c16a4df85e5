// Synthetic multi-object scenes and sensor noise.
#include <cmath>
#include <map>
#include <random>

#include "vkpose/error.hpp"
#include "vkpose/scene.hpp"

namespace vkpose {

SceneRendering renderScene(const GpuContext& ctx, const std::vector<SceneObject>& objects, const Camera& camera) {
  validateCamera(camera);
  const cv::Size size(camera.width, camera.height);
  SceneRendering out;
  out.depth = cv::Mat::zeros(size, CV_32FC1);
  out.bgr = cv::Mat::zeros(size, CV_8UC3);
  out.instance = cv::Mat::zeros(size, CV_16UC1);
  out.visible_pixels.assign(objects.size(), 0);
  out.full_pixels.assign(objects.size(), 0);
  if (objects.size() > 65535) throw InputError("a scene holds at most 65535 objects");

  // One renderer per distinct mesh, all of its poses in one call.
  std::map<const Mesh*, std::vector<std::size_t>> by_mesh;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (!objects[i].mesh) throw InputError("scene object " + std::to_string(i) + " has no mesh");
    by_mesh[objects[i].mesh].push_back(i);
  }
  for (const auto& [mesh, indices] : by_mesh) {
    MeshRenderer renderer(ctx, *mesh);
    std::vector<Pose> poses;
    for (std::size_t i : indices) poses.push_back(objects[i].pose);
    const std::vector<Rendering> views = renderer.render(camera, poses);
    for (std::size_t k = 0; k < indices.size(); ++k) {
      const Rendering& r = views[k];
      const auto label = static_cast<uint16_t>(indices[k] + 1);
      out.full_pixels[indices[k]] = cv::countNonZero(r.depth > 0.f);
      for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
          const float z = r.depth.at<float>(y, x);
          float& best = out.depth.at<float>(y, x);
          if (z > 0.f && (best == 0.f || z < best)) {
            best = z;
            out.bgr.at<cv::Vec3b>(y, x) = r.bgr.at<cv::Vec3b>(y, x);
            out.instance.at<uint16_t>(y, x) = label;
          }
        }
    }
  }
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      if (const uint16_t l = out.instance.at<uint16_t>(y, x)) ++out.visible_pixels[l - 1u];
  return out;
}

Mesh planeMesh(float size, float grey) {
  if (!(size > 0.f) || size > 100.f) throw InputError("plane size must be in (0, 100] metres");
  // Tiles of at most 5 cm: the rasterizer drops a triangle with a corner far outside the
  // image instead of clipping it, so a large plane must be made of small pieces.
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

LinemodFrame sensorFrame(const SceneRendering& scene, const DepthNoiseParams& noise, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss(0.f, 1.f);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  const cv::Mat& z = scene.depth;
  LinemodFrame f;
  f.depth_mm = cv::Mat::zeros(z.size(), CV_16UC1);
  for (int y = 0; y < z.rows; ++y)
    for (int x = 0; x < z.cols; ++x) {
      const float d = z.at<float>(y, x);
      if (d <= 0.f) continue;
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
  f.bgr = cv::Mat(scene.bgr.size(), CV_8UC3);
  for (int y = 0; y < f.bgr.rows; ++y)
    for (int x = 0; x < f.bgr.cols; ++x)
      for (int c = 0; c < 3; ++c)
        f.bgr.at<cv::Vec3b>(y, x)[c] =
            cv::saturate_cast<uint8_t>(scene.bgr.at<cv::Vec3b>(y, x)[c] + noise.colour_sigma * gauss(rng));
  return f;
}

}  // namespace vkpose
