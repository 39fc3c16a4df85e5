#include <algorithm>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "gpu/batch.hpp"
#include "gpu/buffer.hpp"
#include "gpu/kernel.hpp"
#include "render/raster_math.hpp"
#include "render/render.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {

using render::ScreenParams;
using render::Triangle;

uint32_t packBgr(const Eigen::Vector3f& rgb) {
  return render::packChannel(rgb.z()) | (render::packChannel(rgb.y()) << 8) | (render::packChannel(rgb.x()) << 16);
}

Eigen::Vector3f unpackBgr(uint32_t packed) {
  // unpackUnorm4x8 order: component 0 is the lowest byte (blue here).
  return {static_cast<float>(packed & 0xFF) / 255.0f, static_cast<float>((packed >> 8) & 0xFF) / 255.0f,
          static_cast<float>((packed >> 16) & 0xFF) / 255.0f};
}

void checkRenderable(const Mesh& mesh, const Camera& camera) {
  validateCamera(camera, "render camera");
  if (mesh.faces.empty()) throw InputError(fmt::format("mesh '{}' has no triangles to render", mesh.name));
}

/// The reference's raster pass: per pixel the nearest face as (depth bits << 32 | face), the
/// maximum where no face covers it (raster_depth.comp and raster_clipped.comp).
std::vector<uint64_t> rasterizeReference(const Mesh& mesh, const ScreenParams& sp, const Pose& pose) {
  const int W = sp.width, H = sp.height;
  std::vector<uint64_t> raster(static_cast<std::size_t>(W) * H, std::numeric_limits<uint64_t>::max());
  auto corners = [&](const Eigen::Vector3i& f) {
    return std::array<Eigen::Vector3f, 3>{mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]};
  };
  const auto write = [&](int x, int y, float z, std::size_t f) {
    uint32_t bits;
    std::memcpy(&bits, &z, 4);
    auto& slot = raster[static_cast<std::size_t>(y) * W + x];
    slot = std::min(slot, (uint64_t{bits} << 32) | f);
  };
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    Triangle t;
    if (render::setupTriangle(sp, pose, corners(mesh.faces[f]), t)) {
      for (int y = t.box_y0; y <= t.box_y1; ++y)
        for (int x = t.box_x0; x <= t.box_x1; ++x) {
          const auto e = render::edgesAt(t, x, y);
          if (e[0] < 0 || e[1] < 0 || e[2] < 0) continue;
          write(x, y, render::depthAt(sp, t, x, y), f);
        }
      continue;
    }
    // A face reaching past the camera: its part in front of kClipZ.
    render::ClippedFace c;
    if (!render::clipFace(sp, pose, corners(mesh.faces[f]), c)) continue;
    for (int y = c.box_y0; y <= c.box_y1; ++y)
      for (int x = c.box_x0; x <= c.box_x1; ++x)
        if (render::insideClipped(c, x, y)) write(x, y, render::planeDepthAt(sp, c.n, c.n_p0, c.z_near, c.z_far, x, y), f);
  }
  return raster;
}

}  // namespace

Rendering renderReference(const Mesh& mesh, const Camera& camera, const Pose& pose) {
  checkRenderable(mesh, camera);
  const ScreenParams sp(camera);
  const int W = camera.width, H = camera.height;
  const std::vector<uint64_t> raster = rasterizeReference(mesh, sp, pose);
  auto corners = [&](const Eigen::Vector3i& f) {
    return std::array<Eigen::Vector3f, 3>{mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]};
  };
  Rendering out;
  out.depth = cv::Mat::zeros(H, W, CV_32FC1);
  out.normals = cv::Mat::zeros(H, W, CV_32FC3);
  out.bgr = cv::Mat::zeros(H, W, CV_8UC3);
  const bool has_normals = !mesh.normals.empty(), has_colours = !mesh.colours.empty();
  std::vector<uint32_t> colours;
  for (const auto& c : mesh.colours) colours.push_back(packBgr(c));
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const uint64_t key = raster[static_cast<std::size_t>(y) * W + x];
      if (key == std::numeric_limits<uint64_t>::max()) continue;
      const auto f = static_cast<uint32_t>(key & 0xFFFFFFFFu);
      const Eigen::Vector3i& idx = mesh.faces[f];
      float z;
      const auto zbits = static_cast<uint32_t>(key >> 32);
      std::memcpy(&z, &zbits, 4);
      Triangle t;
      Eigen::Vector3f w, face_n;
      if (render::setupTriangle(sp, pose, corners(idx), t)) {
        const auto e = render::edgesAt(t, x, y);
        const float inv_area = 1.0f / static_cast<float>(t.area);
        w = {static_cast<float>(e[0]) * inv_area * t.rz[0] * z, static_cast<float>(e[1]) * inv_area * t.rz[1] * z,
             static_cast<float>(e[2]) * inv_area * t.rz[2] * z};
        face_n = t.n;
      } else {  // a clipped face: weights from its corners in the camera frame
        const Eigen::Vector3f point = sp.ray(x, y);
        w = render::faceWeights(pose, corners(idx), point * z, face_n);
      }
      Eigen::Vector3f n;
      if (has_normals) {
        const Eigen::Vector3f m = w.x() * mesh.normals[idx[0]] + w.y() * mesh.normals[idx[1]] + w.z() * mesh.normals[idx[2]];
        n = render::toCamera({pose.R, Eigen::Vector3f::Zero()}, m);
      } else {
        n = face_n;
      }
      const Eigen::Vector3f ray((static_cast<float>(x) - sp.cx) / sp.fx, (static_cast<float>(y) - sp.cy) / sp.fy, 1.0f);
      const float len2 = n.dot(n);
      if (len2 > 0.f) n = n * (1.0f / std::sqrt(len2));
      if (n.dot(ray) > 0.f) n = -n;
      Eigen::Vector3f bgr;
      if (has_colours) {
        bgr = w.x() * unpackBgr(colours[idx[0]]) + w.y() * unpackBgr(colours[idx[1]]) + w.z() * unpackBgr(colours[idx[2]]);
      } else {
        const float lambert = std::max(0.0f, -n.dot(ray) * (1.0f / std::sqrt(ray.dot(ray))));
        bgr = Eigen::Vector3f::Constant(0.25f + 0.65f * lambert);
      }
      out.depth.at<float>(y, x) = z;
      out.normals.at<cv::Vec3f>(y, x) = {n.x(), n.y(), n.z()};
      out.bgr.at<cv::Vec3b>(y, x) = {static_cast<uint8_t>(render::packChannel(bgr.x())),
                                     static_cast<uint8_t>(render::packChannel(bgr.y())),
                                     static_cast<uint8_t>(render::packChannel(bgr.z()))};
    }
  return out;
}

Rendering rotateInPlane(const Rendering& r, float degrees, double cx, double cy) {
  if (degrees == 0.f) return {r.depth.clone(), r.normals.clone(), r.bgr.clone()};
  const double a = degrees * CV_PI / 180.0, c = std::cos(a), s = std::sin(a);
  // Camera-frame points turn by Rz(a), so image offsets from the principal point turn by the
  // same 2D rotation; warpAffine with this forward map samples the source for each output.
  const cv::Matx23d forward(c, -s, cx - c * cx + s * cy, s, c, cy - s * cx - c * cy);
  Rendering out;
  const cv::Size size = r.depth.size();
  cv::warpAffine(r.depth, out.depth, forward, size, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  cv::warpAffine(r.bgr, out.bgr, forward, size, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  cv::Mat normals;
  cv::warpAffine(r.normals, normals, forward, size, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  const float cf = static_cast<float>(c), sf = static_cast<float>(s);
  cv::transform(normals, out.normals, cv::Matx33f(cf, -sf, 0.f, sf, cf, 0.f, 0.f, 0.f, 1.f));
  return out;
}

// ---- GPU --------------------------------------------------------------------------------

namespace {
using gpu::RasterPush;
constexpr std::size_t kBatchBytes = 96u << 20;  // per-batch output budget

/// lavapipe (llvmpipe's gallivm) ends an invocation's loops after 65,535 iterations counted
/// over all of them together (LP_MAX_TGSI_LOOP_ITERATIONS); a GPU has no such limit. The
/// raster pass loops over its triangle's pixel box, so a box of more pixels lost its lower
/// rows (a bin floor 0.8 m away, 340 x 270 px, a third of it). The box's rows are shared
/// among this many invocations (the dispatch's z groups), each within the budget: 1 for a
/// template window of up to about 93 x 640 pixels, 6 for a 640 x 480 frame.
uint32_t rasterBands(const Camera& camera) {
  constexpr uint32_t kLoopBudget = 60000;  // a row costs width + 2 steps (measured); under 65,535
  const auto width = static_cast<uint32_t>(camera.width), height = static_cast<uint32_t>(camera.height);
  const uint32_t rows = std::max(1u, kLoopBudget / (width + 2));  // rows a band may take
  return (height + rows - 1) / rows;
}
constexpr std::size_t kMaxViewsPerBatch = 256;
/// Vertices, faces and pose rows are texel buffers of four 32-bit words (raster_common.glsl).
const std::vector<gpu::TexelBinding> kMeshTexels = {{0, vk::Format::eR32G32B32A32Uint},
                                                    {1, vk::Format::eR32G32B32A32Uint},
                                                    {2, vk::Format::eR32G32B32A32Uint}};
/// The resolve pass also reads pass 1's 64-bit keys, the vertex normals and colours so.
const std::vector<gpu::TexelBinding> kResolveTexels = {
    {0, vk::Format::eR32G32B32A32Uint}, {1, vk::Format::eR32G32B32A32Uint}, {2, vk::Format::eR32G32B32A32Uint},
    {3, vk::Format::eR32G32Uint},       {4, vk::Format::eR32G32B32A32Uint}, {5, vk::Format::eR32Uint}};
}  // namespace

struct RenderWorkspace {
  explicit RenderWorkspace(const GpuContext& c) : batch(c) {}
  gpu::Batch batch;  ///< one command buffer and fence, reused by every render()
  gpu::Buffer poses, keys, depth, normal_out, colour_out;
};

std::shared_ptr<RenderWorkspace> makeRenderWorkspace(const GpuContext& ctx) {
  return std::make_shared<RenderWorkspace>(ctx);
}

struct MeshRenderer::Impl {
  Impl(const GpuContext& c, const Mesh& mesh, std::shared_ptr<RenderWorkspace> ws)
      : ctx(c),
        workspace(ws ? std::move(ws) : makeRenderWorkspace(c)),
        batch(workspace->batch),
        raster(c, gpu::ShaderId::raster_depth, 4, sizeof(RasterPush), {}, kMeshTexels),
        clipped(c, gpu::ShaderId::raster_clipped, 4, sizeof(RasterPush), {}, kMeshTexels),
        resolve(c, gpu::ShaderId::raster_resolve, 9, sizeof(RasterPush), {}, kResolveTexels) {
    face_count = static_cast<uint32_t>(mesh.faces.size());
    centre = mesh.bboxCentre();
    for (const auto& v : mesh.vertices) radius = std::max(radius, (v - centre).norm());
    flags = (mesh.normals.empty() ? 0u : gpu::kRasterVertexNormals) |
            (mesh.colours.empty() ? 0u : gpu::kRasterVertexColours);
    std::vector<float> v4;
    for (const auto& v : mesh.vertices) v4.insert(v4.end(), {v.x(), v.y(), v.z(), 0.f});
    std::vector<uint32_t> f4;
    for (const auto& f : mesh.faces)
      f4.insert(f4.end(), {static_cast<uint32_t>(f[0]), static_cast<uint32_t>(f[1]), static_cast<uint32_t>(f[2]), 0u});
    std::vector<float> n4;
    for (const auto& n : mesh.normals) n4.insert(n4.end(), {n.x(), n.y(), n.z(), 0.f});
    if (n4.empty()) n4.resize(4, 0.f);
    std::vector<uint32_t> c1;
    for (const auto& colour : mesh.colours) c1.push_back(packBgr(colour));
    if (c1.empty()) c1.push_back(0);
    const std::size_t max_range = ctx.device().max_storage_buffer_range;
    const std::size_t max_texels = ctx.device().max_texel_buffer_elements;
    if (v4.size() * 4 > max_range || f4.size() * 4 > max_range || v4.size() / 4 > max_texels ||
        f4.size() / 4 > max_texels)
      throw InputError(fmt::format("mesh '{}' is too large for one device buffer ({} triangles)", mesh.name, face_count));
    vertices = gpu::Buffer(ctx, v4.size() * 4);
    faces = gpu::Buffer(ctx, f4.size() * 4);
    normals = gpu::Buffer(ctx, n4.size() * 4);
    colours = gpu::Buffer(ctx, c1.size() * 4);
    batch.upload(vertices, v4.data(), v4.size() * 4);
    batch.upload(faces, f4.data(), f4.size() * 4);
    batch.upload(normals, n4.data(), n4.size() * 4);
    batch.upload(colours, c1.data(), c1.size() * 4);
    batch.submit();
  }
  const GpuContext& ctx;
  std::shared_ptr<RenderWorkspace> workspace;
  gpu::Batch& batch;
  gpu::Kernel raster, clipped, resolve;
  gpu::Buffer vertices, faces, normals, colours;
  uint32_t face_count = 0, flags = 0;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();  ///< of the mesh's box, object frame
  float radius = 0.f;                                ///< every vertex lies within it of centre

  /// Some pose puts a vertex at render::kNearZ or nearer: the batch needs the clipping pass.
  bool reachesPastTheCamera(const std::vector<Pose>& poses, std::size_t first, std::size_t n) const {
    for (std::size_t v = first; v < first + n; ++v)
      if ((poses[v].R * centre + poses[v].t).z() - radius <= render::kNearZ) return true;
    return false;
  }
};

MeshRenderer::MeshRenderer(const GpuContext& ctx, const Mesh& mesh, std::shared_ptr<RenderWorkspace> workspace) {
  if (!ctx.device().int64_atomics)
    throw DeviceError(fmt::format("the template renderer needs 64-bit buffer atomics, which {} lacks",
                                  ctx.device().name));
  if (mesh.faces.empty()) throw InputError(fmt::format("mesh '{}' has no triangles to render", mesh.name));
  impl_ = std::make_unique<Impl>(ctx, mesh, std::move(workspace));
}

MeshRenderer::~MeshRenderer() = default;

std::size_t MeshRenderer::viewsPerBatch(const Camera& camera) const {
  const std::size_t pixels = static_cast<std::size_t>(camera.width) * camera.height;
  // Largest per-pixel binding: the normals (16 bytes); the whole batch: 8 + 4 + 16 + 4.
  const std::size_t by_range = impl_->ctx.device().max_storage_buffer_range / (pixels * 16);
  const std::size_t by_budget = kBatchBytes / (pixels * 32);
  // The resolve pass reads the batch's keys as one texel buffer.
  const std::size_t by_texels = impl_->ctx.device().max_texel_buffer_elements / pixels;
  return std::clamp<std::size_t>(std::min({by_range, by_budget, by_texels, kMaxViewsPerBatch}), 1, kMaxViewsPerBatch);
}

std::vector<Rendering> MeshRenderer::render(const Camera& camera, const std::vector<Pose>& poses,
                                            RenderedImages images) {
  return render(std::vector<Camera>(poses.size(), camera), poses, images);
}

namespace {

/// The image all of a batch's views render into: as large as the largest camera's; each
/// view's rendering is its top-left corner. The cameras must share their focal lengths (the
/// kernels take them from the push constants, each view's principal point from its pose).
Camera canvasFor(const std::vector<Camera>& cameras) {
  Camera canvas = cameras.front();
  for (const Camera& c : cameras) {
    validateCamera(c, "render camera");
    if (c.fx != canvas.fx || c.fy != canvas.fy)
      throw std::logic_error("MeshRenderer::render: the cameras of one call need the same focal lengths");
    canvas.width = std::max(canvas.width, c.width);
    canvas.height = std::max(canvas.height, c.height);
  }
  return canvas;
}

/// View v's rendering out of a batch's downloads on the canvas.
Rendering unpackView(std::size_t v, const Camera& canvas, const Camera& camera, std::vector<float>& depth,
                     std::vector<float>& normals, std::vector<uint32_t>& colour) {
  const std::size_t pixels = static_cast<std::size_t>(canvas.width) * canvas.height;
  const cv::Rect own(0, 0, camera.width, camera.height);
  Rendering r;
  r.depth = cv::Mat(canvas.height, canvas.width, CV_32FC1, depth.data() + v * pixels)(own).clone();
  if (normals.empty()) return r;  // depth alone
  cv::Mat n4(canvas.height, canvas.width, CV_32FC4, normals.data() + v * pixels * 4);
  cv::cvtColor(n4(own), r.normals, cv::COLOR_BGRA2BGR);
  cv::Mat c4(canvas.height, canvas.width, CV_8UC4, colour.data() + v * pixels);
  cv::cvtColor(c4(own), r.bgr, cv::COLOR_BGRA2BGR);
  return r;
}

}  // namespace

std::vector<Rendering> MeshRenderer::render(const std::vector<Camera>& cameras, const std::vector<Pose>& poses,
                                            RenderedImages images) {
  if (cameras.size() != poses.size()) throw std::logic_error("MeshRenderer::render: a camera per pose");
  if (poses.empty()) return {};
  const Camera canvas = canvasFor(cameras);
  auto& m = *impl_;
  auto& w = *m.workspace;
  const std::size_t pixels = static_cast<std::size_t>(canvas.width) * canvas.height;
  if (pixels * 16 > m.ctx.device().max_storage_buffer_range || pixels > m.ctx.device().max_texel_buffer_elements)
    throw InputError(fmt::format("render size {}x{} is too large for one device buffer", canvas.width, canvas.height));
  const std::size_t per_batch = viewsPerBatch(canvas);
  const bool depth_only = images == RenderedImages::depth;
  const RasterPush push{canvas.floatIntrinsics(), canvas.width, canvas.height, m.face_count,
                        m.flags | (depth_only ? gpu::kRasterDepthOnly : 0u)};
  const uint32_t face_groups = gpu::groupsFor(m.face_count, gpu::kWorkgroupSize);
  std::vector<Rendering> out;
  out.reserve(poses.size());
  std::vector<float> depth, normals;
  std::vector<uint32_t> colour;
  for (std::size_t first = 0; first < poses.size(); first += per_batch) {
    const std::size_t n = std::min(per_batch, poses.size() - first);
    std::vector<float> rows;  // per view R | t, then the principal point (raster_common.glsl)
    for (std::size_t v = first; v < first + n; ++v) {
      for (int r = 0; r < 3; ++r)
        rows.insert(rows.end(), {poses[v].R(r, 0), poses[v].R(r, 1), poses[v].R(r, 2), poses[v].t(r)});
      const FloatIntrinsics k = cameras[v].floatIntrinsics();
      rows.insert(rows.end(), {k.cx, k.cy, 0.f, 0.f});
    }
    w.poses.reserve(m.ctx, rows.size() * 4);
    w.keys.reserve(m.ctx, n * pixels * 8);
    w.depth.reserve(m.ctx, n * pixels * 4);
    w.normal_out.reserve(m.ctx, n * pixels * 16);
    w.colour_out.reserve(m.ctx, n * pixels * 4);
    depth.resize(n * pixels);
    normals.resize(depth_only ? 0 : n * pixels * 4);
    colour.resize(depth_only ? 0 : n * pixels);
    gpu::Batch& batch = m.batch;
    batch.upload(w.poses, rows.data(), rows.size() * 4);
    batch.fill(w.keys, 0xFFFFFFFFu, n * pixels * 8);
    batch.dispatch(m.raster, {m.vertices, m.faces, w.poses, w.keys}, push, face_groups,
                   static_cast<uint32_t>(n), rasterBands(canvas));
    if (m.reachesPastTheCamera(poses, first, n))
      batch.dispatch(m.clipped, {m.vertices, m.faces, w.poses, w.keys}, push, face_groups,
                     static_cast<uint32_t>(n), rasterBands(canvas));
    batch.dispatch(m.resolve,
                   {m.vertices, m.faces, w.poses, w.keys, m.normals, m.colours, w.depth, w.normal_out, w.colour_out},
                   push, gpu::groupsFor(pixels, gpu::kWorkgroupSize), static_cast<uint32_t>(n));
    batch.download(w.depth, depth.data(), n * pixels * 4);
    if (!depth_only) {
      batch.download(w.normal_out, normals.data(), n * pixels * 16);
      batch.download(w.colour_out, colour.data(), n * pixels * 4);
    }
    batch.submit();
    for (std::size_t v = 0; v < n; ++v) out.push_back(unpackView(v, canvas, cameras[first + v], depth, normals, colour));
  }
  return out;
}

}  // namespace vkpose
