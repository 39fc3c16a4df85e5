// The compute-shader rasterizer: GPU against the C++ reference, against ray casting of exact
// shapes, and the orientation of the image (no mirrored or flipped renderings).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "gpu/buffer.hpp"
#include "mesh_support.hpp"
#include "render/render.hpp"
#include "render/simplify.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

Camera smallCamera(int w = 200, int h = 160) {
  Camera c;
  c.fx = 572.f;
  c.fy = 570.f;
  c.cx = (w - 1) / 2.0 + 3.25;
  c.cy = (h - 1) / 2.0 - 2.5;
  c.width = w;
  c.height = h;
  return c;
}

Pose viewPose(const Eigen::Vector3f& dir, float distance, float inplane, const Eigen::Vector3f& centre = {0, 0, 0}) {
  const TrainingView v = lookAtView(dir, centre, distance, inplane);
  return {v.R, v.t};
}

/// Share of pixels where both agree on coverage, and the largest depth / normal / colour
/// differences where both cover.
struct Agreement {
  double mask_agree = 0;
  float max_depth_rel = 0, min_normal_dot = 1;
  int max_colour = 0;
};

Agreement compare(const Rendering& a, const Rendering& b) {
  Agreement g;
  int same = 0;
  for (int y = 0; y < a.depth.rows; ++y)
    for (int x = 0; x < a.depth.cols; ++x) {
      const float da = a.depth.at<float>(y, x), db = b.depth.at<float>(y, x);
      same += (da > 0) == (db > 0);
      if (da > 0 && db > 0) {
        g.max_depth_rel = std::max(g.max_depth_rel, std::abs(da - db) / da);
        const cv::Vec3f na = a.normals.at<cv::Vec3f>(y, x), nb = b.normals.at<cv::Vec3f>(y, x);
        g.min_normal_dot = std::min(g.min_normal_dot, na.dot(nb));
        for (int c = 0; c < 3; ++c)
          g.max_colour = std::max(g.max_colour, std::abs(a.bgr.at<cv::Vec3b>(y, x)[c] - b.bgr.at<cv::Vec3b>(y, x)[c]));
      }
    }
  g.mask_agree = static_cast<double>(same) / a.depth.total();
  return g;
}

/// Where the ray through pixel (x, y) first meets a sphere at `centre`: the depth, the unit
/// normal there, and the cosine between the ray and that normal. Empty when it misses.
struct SphereHit {
  float z = 0.f, cos_view = 0.f;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
};
std::optional<SphereHit> raySphere(const Camera& cam, int x, int y, const Eigen::Vector3f& centre, float radius) {
  const Eigen::Vector3f d((x - cam.cx) / cam.fx, (y - cam.cy) / cam.fy, 1.0);
  // |s d - c| = radius, nearest root.
  const float a = d.dot(d), b = -2.f * d.dot(centre), k = centre.dot(centre) - radius * radius;
  const float disc = b * b - 4 * a * k;
  if (disc <= 0.f) return std::nullopt;
  SphereHit hit;
  hit.z = (-b - std::sqrt(disc)) / (2 * a);
  hit.normal = (hit.z * d - centre).normalized();
  hit.cos_view = std::abs(hit.normal.dot(d.normalized()));
  return hit;
}

TEST(Render, GpuMatchesReferenceOnTheCoffeeCupAndAColouredPly) {
  // Without ../shared/data the demo's lidded cup and its carton (vertex colours) stand in.
  for (const char* file : {"meshes/coffee_cup.stl", "lmo_scene2_frame3/models/obj_000005.ply"}) {
    const Mesh mesh = test::meshOrStandIn(file);
    MeshRenderer renderer(test::context(), mesh);
    const Camera cam = smallCamera();
    std::vector<Pose> poses = {viewPose({0.3f, -0.5f, 0.8f}, 0.6f, 20.f, mesh.bboxCentre()),
                               viewPose({-0.7f, 0.2f, 0.3f}, 0.9f, -40.f, mesh.bboxCentre()),
                               viewPose({0.f, 0.f, 1.f}, 0.7f, 0.f, mesh.bboxCentre())};
    const auto gpu = renderer.render(cam, poses);
    ASSERT_EQ(gpu.size(), poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const Rendering ref = renderReference(mesh, cam, poses[i]);
      ASSERT_GT(cv::countNonZero(ref.mask()), 1000) << file;
      const Agreement g = compare(gpu[i], ref);
      // Stated tolerance: coverage is integer arithmetic (identical); depth, normals and
      // colour are the same float operations, equal up to the device's rounding.
      EXPECT_GE(g.mask_agree, 0.9995) << file << " view " << i;
      EXPECT_LE(g.max_depth_rel, 1e-5f) << file << " view " << i;
      EXPECT_GE(g.min_normal_dot, 0.999f) << file << " view " << i;
      EXPECT_LE(g.max_colour, 2) << file << " view " << i;
    }
  }
}

TEST(Render, DepthAloneIsTheFullRenderingsDepthBitForBit) {
  // Stage 6 renders depth alone (RenderedImages::depth): the resolve pass then writes pass 1's
  // depth without setting up the triangle again, and must give the same floats.
  const Mesh mesh = test::meshOrStandIn("lmo_scene2_frame3/models/obj_000005.ply");
  MeshRenderer renderer(test::context(), mesh);
  const Camera cam = smallCamera();
  const std::vector<Pose> poses = {viewPose({0.3f, -0.5f, 0.8f}, 0.6f, 20.f, mesh.bboxCentre()),
                                   viewPose({-0.7f, 0.2f, 0.3f}, 0.9f, -40.f, mesh.bboxCentre())};
  const auto full = renderer.render(cam, poses);
  const auto depth = renderer.render(cam, poses, RenderedImages::depth);
  ASSERT_EQ(depth.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    ASSERT_GT(cv::countNonZero(full[i].mask()), 1000);
    EXPECT_EQ(std::memcmp(full[i].depth.data, depth[i].depth.data, full[i].depth.total() * sizeof(float)), 0)
        << "view " << i;
    EXPECT_TRUE(depth[i].normals.empty());
    EXPECT_TRUE(depth[i].bgr.empty());
  }
  // And a full rendering after a depth-only one is whole again.
  const auto again = renderer.render(cam, {poses[0]});
  EXPECT_EQ(cv::countNonZero(again[0].bgr.reshape(1) != full[0].bgr.reshape(1)), 0);
}

TEST(Render, ViewsThroughTheirOwnWindowsInOneCallAreTheViewsRenderedAlone) {
  // Stage 6 renders each start in its own window of the frame, all of an object's starts in
  // one call (a camera per pose, the views sharing a canvas as large as the largest window):
  // each must be the pixels its window's camera renders alone, depth, normals and colours.
  const Mesh mesh = test::meshOrStandIn("lmo_scene2_frame3/models/obj_000005.ply");
  MeshRenderer renderer(test::context(), mesh);
  const Camera frame = smallCamera(320, 240);
  const auto window = [&](int x, int y, int w, int h) {
    Camera c = frame;
    c.cx -= x;
    c.cy -= y;
    c.width = w;
    c.height = h;
    return c;
  };
  const std::vector<Camera> cameras = {window(40, 30, 180, 150), window(100, 60, 120, 110), window(0, 0, 320, 240)};
  const std::vector<Pose> poses = {viewPose({0.3f, -0.5f, 0.8f}, 0.6f, 20.f, mesh.bboxCentre()),
                                   viewPose({-0.7f, 0.2f, 0.3f}, 0.9f, -40.f, mesh.bboxCentre()),
                                   viewPose({0.f, 0.f, 1.f}, 0.7f, 0.f, mesh.bboxCentre())};
  const auto together = renderer.render(cameras, poses);
  ASSERT_EQ(together.size(), poses.size());
  const auto same = [](const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() &&
           std::memcmp(a.clone().data, b.clone().data, a.total() * a.elemSize()) == 0;
  };
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Rendering alone = renderer.render(cameras[i], {poses[i]}).front();
    ASSERT_GT(cv::countNonZero(alone.mask()), 500) << "view " << i;
    EXPECT_TRUE(same(together[i].depth, alone.depth)) << "view " << i;
    EXPECT_TRUE(same(together[i].normals, alone.normals)) << "view " << i;
    EXPECT_TRUE(same(together[i].bgr, alone.bgr)) << "view " << i;
  }
}

// The rasterizer's edge functions run in 32 bits for triangles under 2,048 px across and in
// 64 bits for wider ones (raster_common.glsl); the C++ reference is 64-bit throughout. A 2 m
// box seen from 2 cm off one face has triangles of tens of thousands of pixels, whose edge
// functions would overflow 32 bits.
TEST(Render, TrianglesWiderThanTwoThousandPixelsMatchTheReference) {
  const Mesh box = test::boxMesh({2.f, 2.f, 2.f});
  MeshRenderer renderer(test::context(), box);
  const Camera cam = smallCamera();
  Pose pose;
  pose.R = Eigen::AngleAxisf(0.01f, Eigen::Vector3f(1.f, 0.5f, 0.f).normalized()).toRotationMatrix();
  pose.t = Eigen::Vector3f(0.1f, -0.05f, 1.03f);  // the near face is 2-3 cm from the camera
  const Rendering gpu = renderer.render(cam, {pose})[0];
  const Rendering ref = renderReference(box, cam, pose);
  int wide = 0;  // faces wider than 8,192 px in the image (all corners in front of the camera)
  for (const Eigen::Vector3i& f : box.faces) {
    float lo = 1e30f, hi = -1e30f;
    bool front = true;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f c = pose.R * box.vertices[static_cast<std::size_t>(f[k])] + pose.t;
      front = front && c.z() > 1e-3f;
      const float x = static_cast<float>(cam.fx) * c.x() / c.z();
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
    wide += front && hi - lo > 8192.f;
  }
  ASSERT_GE(wide, 1) << "the pose must put a wide triangle in front of the camera";
  ASSERT_GT(cv::countNonZero(ref.mask()), 1000);
  const Agreement g = compare(gpu, ref);
  EXPECT_GE(g.mask_agree, 0.9995);
  EXPECT_LE(g.max_depth_rel, 1e-5f);
  EXPECT_GE(g.min_normal_dot, 0.999f);
}

// lavapipe ends a shader invocation's loops after 65,535 iterations in all, and the raster
// pass loops over its triangle's pixel box: a triangle of a larger box lost its lower rows (a
// third of a bin floor 0.8 m away) until the rows were shared among invocations. A 60 x 45 cm
// face 0.6 m away fills most of a 640 x 480 frame; each of its triangles has a box of about
// 250,000 pixels.
TEST(Render, TrianglesOfMoreThanLavapipesLoopLimitInPixelsRenderWhole) {
  const Mesh board = test::boxMesh({0.6f, 0.45f, 0.01f});
  MeshRenderer renderer(test::context(), board);
  const Camera cam;
  ASSERT_EQ(cam.width * cam.height, 640 * 480);
  Pose pose;
  pose.R = Eigen::AngleAxisf(0.2f, Eigen::Vector3f(1.f, 0.3f, 0.f).normalized()).toRotationMatrix();
  pose.t = Eigen::Vector3f(0.01f, -0.02f, 0.6f);
  const Rendering gpu = renderer.render(cam, {pose})[0];
  const Rendering ref = renderReference(board, cam, pose);
  ASSERT_GT(cv::countNonZero(ref.mask()), 200000);
  const Agreement g = compare(gpu, ref);
  EXPECT_GE(g.mask_agree, 0.9995);
  EXPECT_LE(g.max_depth_rel, 1e-5f);
  EXPECT_GE(g.min_normal_dot, 0.999f);
}

// A floor under the camera that reaches behind it: each of its two triangles has a corner
// behind the camera, which the rasterizer once dropped (synth tiled its floors and bin walls
// for that). Now the part in front of the near plane is drawn: every pixel whose ray meets the
// floor within its extent, at the depth where it meets it, on the GPU as in the reference,
// with the corners' colours interpolated alike.
TEST(Render, AFloorReachingBehindTheCameraIsClippedNotDropped) {
  Mesh floor;
  floor.name = "floor";
  constexpr float kBelow = 0.1f, kHalfWidth = 0.8f, kBehind = -0.5f, kAhead = 3.f;  // camera frame, metres
  floor.vertices = {{-kHalfWidth, kBelow, kBehind}, {kHalfWidth, kBelow, kBehind}, {kHalfWidth, kBelow, kAhead},
                    {-kHalfWidth, kBelow, kAhead}};
  floor.colours = {{1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}, {1.f, 1.f, 1.f}};
  floor.faces = {{0, 1, 2}, {0, 2, 3}};
  finishMesh(floor);
  // A whole frame: the floor's box spans all of its width and its lower half, more pixels than
  // lavapipe lets one invocation visit (rasterBands shares them out).
  const Camera cam;
  ASSERT_EQ(cam.width * cam.height, 640 * 480);
  const Pose pose;  // the mesh is in the camera frame
  MeshRenderer renderer(test::context(), floor);
  const Rendering gpu = renderer.render(cam, {pose})[0];
  const Rendering ref = renderReference(floor, cam, pose);
  int expected = 0, covered = 0, depth_right = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const float ry = static_cast<float>((y - cam.cy) / cam.fy), rx = static_cast<float>((x - cam.cx) / cam.fx);
      const float z = ry > 0.f ? kBelow / ry : 0.f;  // where the ray meets the floor's plane
      // Pixels a pixel or more inside the floor's outline (its far edge and its sides).
      const bool inside = ry > 0.f && z < kAhead * 0.98f && std::abs(rx * z) < kHalfWidth * 0.98f;
      if (!inside) continue;
      ++expected;
      const float got = gpu.depth.at<float>(y, x);
      covered += got > 0.f;
      depth_right += std::abs(got - z) <= 1e-4f * z;
    }
  ASSERT_GT(expected, 100000);
  EXPECT_EQ(covered, expected);
  EXPECT_GE(depth_right, expected * 999 / 1000);
  const Agreement g = compare(gpu, ref);
  EXPECT_GE(g.mask_agree, 0.9995);
  EXPECT_LE(g.max_depth_rel, 1e-5f);
  EXPECT_GE(g.min_normal_dot, 0.999f);
  EXPECT_LE(g.max_colour, 2);
  // The colours vary along the floor: the corners' weights were used.
  const cv::Vec3b near = gpu.bgr.at<cv::Vec3b>(cam.height - 1, cam.width / 2);
  const cv::Vec3b far = gpu.bgr.at<cv::Vec3b>(static_cast<int>(cam.cy) + 4, cam.width / 2);
  EXPECT_GT(cv::norm(cv::Vec3i(near) - cv::Vec3i(far)), 30.0);
}

/// Distance along the pixel's ray (z) to an axis-aligned box under `pose`, or 0 for a miss.
float rayCastBox(const Camera& cam, const Pose& pose, const Eigen::Vector3f& half, int x, int y) {
  const Eigen::Vector3f ray_cam((x - cam.cx) / cam.fx, (y - cam.cy) / cam.fy, 1.0);
  const Eigen::Vector3f o = -pose.R.transpose() * pose.t, d = pose.R.transpose() * ray_cam;
  float t0 = 0.f, t1 = 1e9f;
  for (int a = 0; a < 3; ++a) {
    const float inv = 1.f / d[a];
    float ta = (-half[a] - o[a]) * inv, tb = (half[a] - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1 ? t0 : 0.f;  // ray_cam has z = 1, so t is the depth
}

TEST(Render, BoxDepthEqualsRayCasting) {
  const Eigen::Vector3f size(0.10f, 0.06f, 0.08f);
  const Mesh box = test::boxMesh(size);
  MeshRenderer renderer(test::context(), box);
  const Camera cam = smallCamera();
  const Pose pose = viewPose({0.4f, -0.6f, 0.7f}, 0.55f, 15.f);
  const Rendering r = renderer.render(cam, {pose})[0];
  int checked = 0, disagree = 0, exact = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const float expected = rayCastBox(cam, pose, 0.5f * size, x, y);
      const float got = r.depth.at<float>(y, x);
      // Coverage snaps vertices to 1/8 pixel, so the silhouette may differ by a pixel; depth
      // is the exact ray-plane intersection (float rounding only).
      if ((expected > 0) != (got > 0)) {
        ++disagree;  // only on the silhouette: the 1/8-pixel snapping of the corners
        continue;
      }
      if (expected > 0) {
        // Pixels next to an edge between two faces may be given to the neighbouring face
        // (snapping): within 0.1 mm there; exact up to float rounding everywhere else.
        EXPECT_NEAR(got, expected, 1e-4f) << "pixel " << x << "," << y;
        exact += std::abs(got - expected) <= 2e-6f;
        ++checked;
      }
    }
  EXPECT_GT(checked, 3000);
  EXPECT_GT(exact, checked * 98 / 100);
  EXPECT_LT(disagree, checked / 100);
}

TEST(Render, SphereDepthEqualsRayCastingWithinFacetting) {
  const float radius = 0.05f;
  const Mesh sphere = test::icosphere(radius, 5);  // 20480 faces: facets lie < 0.01 mm inside
  MeshRenderer renderer(test::context(), sphere);
  const Camera cam = smallCamera();
  const Pose pose{Eigen::Matrix3f::Identity(), Eigen::Vector3f(0.01f, -0.005f, 0.5f)};
  const Rendering r = renderer.render(cam, {pose})[0];
  int checked = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      // Interior pixels only (away from grazing rays).
      const auto hit = raySphere(cam, x, y, pose.t, radius);
      if (!hit || hit->cos_view < 0.5f) continue;
      ASSERT_GT(r.depth.at<float>(y, x), 0.f) << x << "," << y;
      EXPECT_NEAR(r.depth.at<float>(y, x), hit->z, 1e-4f) << x << "," << y;
      // The interpolated vertex normals approximate the sphere's normal.
      const cv::Vec3f n = r.normals.at<cv::Vec3f>(y, x);
      EXPECT_GT(n.dot(cv::Vec3f(hit->normal.x(), hit->normal.y(), hit->normal.z())), 0.999f);
      ++checked;
    }
  EXPECT_GT(checked, 2000);
}

TEST(Render, ProjectedVerticesLandOnTheMaskNoMirrorNoFlip) {
  const Mesh l = test::lShapeMesh();
  MeshRenderer renderer(test::context(), l);
  const Camera cam = smallCamera();
  std::vector<Pose> poses;
  for (float inplane : {-50.f, 0.f, 35.f})
    poses.push_back(viewPose({0.2f, -0.9f, 0.4f}, 0.6f, inplane, l.bboxCentre()));
  const auto renders = renderer.render(cam, poses);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    cv::Mat mask = renders[i].mask();
    cv::dilate(mask, mask, cv::Mat());  // vertices sit on the silhouette: allow one pixel
    for (const auto& v : l.vertices) {
      const Eigen::Vector3f pc = poses[i].R * v + poses[i].t;
      const Eigen::Vector2f uv = cam.project(pc);
      const int x = static_cast<int>(std::lround(uv.x())), y = static_cast<int>(std::lround(uv.y()));
      ASSERT_TRUE(x >= 0 && y >= 0 && x < cam.width && y < cam.height);
      EXPECT_GT(mask.at<uint8_t>(y, x), 0) << "vertex projects off the rendering at " << x << "," << y;
    }
    // And the mask is not larger than the object: its area matches the projected hull's.
    std::vector<cv::Point2f> pts;
    for (const auto& v : l.vertices) {
      const Eigen::Vector2f uv = cam.project(poses[i].R * v + poses[i].t);
      pts.emplace_back(uv.x(), uv.y());
    }
    std::vector<cv::Point2f> hull;
    cv::convexHull(pts, hull);
    EXPECT_LE(cv::countNonZero(renders[i].mask()), cv::contourArea(hull) + 2 * cv::arcLength(hull, true));
  }
}

TEST(Render, ColourlessMeshesAreGreyShadedAndBackgroundIsEmpty) {
  const Mesh box = test::boxMesh({0.1f, 0.1f, 0.1f});
  MeshRenderer renderer(test::context(), box);
  const Camera cam = smallCamera();
  const Rendering r = renderer.render(cam, {viewPose({0.f, 0.f, 1.f}, 0.6f, 0.f)})[0];
  const cv::Vec3b centre = r.bgr.at<cv::Vec3b>(static_cast<int>(cam.cy), static_cast<int>(cam.cx));
  EXPECT_EQ(centre[0], centre[1]);
  EXPECT_GT(centre[0], 200);  // a face seen head-on is bright
  EXPECT_EQ(r.depth.at<float>(0, 0), 0.f);
  EXPECT_EQ(r.bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
}

TEST(Render, ManyViewsSplitIntoBatches) {
  const Mesh sphere = test::icosphere(0.05f, 2);
  MeshRenderer renderer(test::context(), sphere);
  Camera cam = smallCamera(640, 480);
  const std::size_t per_batch = renderer.viewsPerBatch(cam);
  std::vector<Pose> poses(per_batch + 3, Pose{Eigen::Matrix3f::Identity(), Eigen::Vector3f(0, 0, 0.5f)});
  poses.back().t.z() = 0.8f;
  const auto renders = renderer.render(cam, poses);
  ASSERT_EQ(renders.size(), poses.size());
  EXPECT_NEAR(renders.back().depth.at<float>(static_cast<int>(cam.cy), static_cast<int>(cam.cx)), 0.75f, 1e-3f);
  EXPECT_NEAR(renders.front().depth.at<float>(static_cast<int>(cam.cy), static_cast<int>(cam.cx)), 0.45f, 1e-3f);
}

// Renderers sharing a workspace (the detector's, one per bank) hold the full-frame outputs
// once: the second mesh's render allocates nothing more, and still draws its own mesh.
TEST(Render, RenderersSharingAWorkspaceAllocateItOnce) {
  const Mesh small = test::icosphere(0.03f, 2), large = test::icosphere(0.06f, 2);
  const Camera cam = smallCamera(320, 240);
  const std::vector<Pose> poses(3, Pose{Eigen::Matrix3f::Identity(), Eigen::Vector3f(0, 0, 0.5f)});
  const auto workspace = makeRenderWorkspace(test::context());
  MeshRenderer a(test::context(), small, workspace), b(test::context(), large, workspace);
  const auto first = a.render(cam, poses);
  const std::size_t after_first = gpu::bufferMemory().live;
  const auto second = b.render(cam, poses);
  EXPECT_EQ(gpu::bufferMemory().live, after_first);
  const cv::Point centre(static_cast<int>(cam.cx), static_cast<int>(cam.cy));
  EXPECT_NEAR(first[0].depth.at<float>(centre), 0.47f, 2e-3f);
  EXPECT_NEAR(second[2].depth.at<float>(centre), 0.44f, 2e-3f);
  EXPECT_GT(cv::countNonZero(second[0].mask()), 2 * cv::countNonZero(first[0].mask()));
  {
    MeshRenderer own(test::context(), small);  // no workspace given: one of its own
    own.render(cam, poses);
    EXPECT_GT(gpu::bufferMemory().live, after_first + std::size_t{3} * 320 * 240 * 32);
  }
  EXPECT_EQ(gpu::bufferMemory().live, after_first);
}

// The detector renders a simplified copy of each mesh (src/render/simplify.hpp): fewer faces,
// the surface within the error asked for, and painted regions that keep their borders.
TEST(Render, SimplifiedSphereStaysWithinItsErrorOfRayCasting) {
  const float radius = 0.05f, max_error = 0.0005f;
  const Mesh sphere = test::icosphere(radius, 5);
  const Mesh simple = simplifiedForRendering(sphere, max_error);
  EXPECT_LT(simple.faces.size(), sphere.faces.size() / 5);
  EXPECT_EQ(simple.vertices.size(), sphere.vertices.size());  // only faces go
  const Camera cam = smallCamera();
  const Pose pose{Eigen::Matrix3f::Identity(), Eigen::Vector3f(0.01f, -0.005f, 0.5f)};
  const Rendering r = MeshRenderer(test::context(), simple).render(cam, {pose})[0];
  int checked = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const auto hit = raySphere(cam, x, y, pose.t, radius);
      if (!hit || hit->cos_view < 0.5f) continue;
      const float s = hit->z, cos_view = hit->cos_view;
      // Facets of a sphere lie inside it: the depth is at least the sphere's, and at most twice
      // the error along the ray (1 / cos of the viewing angle) behind it. Twice: the error is
      // meshoptimizer's quadric estimate, which on a sphere undershoots (measured: 1.72 times).
      const float z = r.depth.at<float>(y, x);
      ASSERT_GT(z, 0.f) << x << "," << y;
      EXPECT_GE(z, s - 1e-5f) << x << "," << y;
      EXPECT_LE(z, s + 2.f * max_error / cos_view + 1e-5f) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 2000);
}

TEST(Render, SimplifiedPaintedPlaneKeepsItsColourBorder) {
  // A 10 cm square of 40 x 40 quads, red left of x = 0 and blue right of it; the vertices on
  // x = 0 are there twice, once a colour. Flat, so the simplifier may merge all it likes
  // except across that seam.
  Mesh plane;
  plane.name = "painted plane";
  const int cells = 40;
  const float half = 0.05f, step = 2.f * half / cells;
  const Eigen::Vector3f red(1.f, 0.f, 0.f), blue(0.f, 0.f, 1.f);
  auto vertex = [&](int i, int j, bool right) {
    plane.vertices.emplace_back(-half + i * step, -half + j * step, 0.f);
    plane.normals.emplace_back(0.f, 0.f, -1.f);
    plane.colours.push_back(right ? blue : red);
    return static_cast<int>(plane.vertices.size()) - 1;
  };
  std::vector<int> left_id((cells + 1) * (cells + 1), -1), right_id((cells + 1) * (cells + 1), -1);
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      const int at = j * (cells + 1) + i;
      if (i <= cells / 2) left_id[static_cast<std::size_t>(at)] = vertex(i, j, false);
      if (i >= cells / 2) right_id[static_cast<std::size_t>(at)] = vertex(i, j, true);
    }
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const auto& ids = i < cells / 2 ? left_id : right_id;
      const auto id = [&](int di, int dj) { return ids[static_cast<std::size_t>((j + dj) * (cells + 1) + i + di)]; };
      // Facing a camera on -z looking along +z: counter-clockwise as the camera sees it.
      plane.faces.emplace_back(id(0, 0), id(0, 1), id(1, 1));
      plane.faces.emplace_back(id(0, 0), id(1, 1), id(1, 0));
    }
  finishMesh(plane);
  const Mesh simple = simplifiedForRendering(plane, 0.0005f);
  EXPECT_LT(simple.faces.size(), plane.faces.size() / 10);
  const Camera cam = smallCamera();
  const Pose pose{Eigen::Matrix3f::Identity(), Eigen::Vector3f(0.f, 0.f, 0.4f)};
  const Rendering full = renderReference(plane, cam, pose), r = renderReference(simple, cam, pose);
  ASSERT_GT(cv::countNonZero(full.mask()), 5000);
  const float seam_x = static_cast<float>(cam.cx + cam.fx * pose.t.x() / pose.t.z());
  int compared = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      if (!(full.depth.at<float>(y, x) > 0.f)) continue;
      EXPECT_GT(r.depth.at<float>(y, x), 0.f) << x << "," << y;  // no holes
      EXPECT_NEAR(r.depth.at<float>(y, x), full.depth.at<float>(y, x), 1e-5f) << x << "," << y;
      if (std::abs(static_cast<float>(x) - seam_x) < 2.f) continue;
      const cv::Vec3b a = full.bgr.at<cv::Vec3b>(y, x), b = r.bgr.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(a[c] - b[c]), 2) << x << "," << y;  // no purple
      ++compared;
    }
  EXPECT_GT(compared, 5000);
}

TEST(Render, SimplifiedCoffeeCupLooksTheSameWithAFifteenthOfItsFaces) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const Mesh cup = loadMesh(test::sharedData() + "/meshes/coffee_cup.stl");
  // The detector's setting: 0.2 % of the diameter.
  const Mesh simple = simplifiedForRendering(cup, kDetectionRenderError * cup.diameter);
  EXPECT_LT(simple.faces.size() * 15, cup.faces.size());
  const Mesh box = test::boxMesh({0.1f, 0.1f, 0.1f});
  EXPECT_EQ(simplifiedForRendering(box, kDetectionRenderError * box.diameter).faces.size(), box.faces.size());  // nothing to take
  const Camera cam = smallCamera();
  MeshRenderer full(test::context(), cup), coarse(test::context(), simple);
  const std::vector<Pose> poses = {viewPose({0.3f, -0.5f, 0.8f}, 0.6f, 20.f, cup.bboxCentre()),
                                   viewPose({-0.7f, 0.2f, 0.3f}, 0.9f, -40.f, cup.bboxCentre())};
  const auto a = full.render(cam, poses), b = coarse.render(cam, poses);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    ASSERT_GT(cv::countNonZero(a[i].mask()), 1000);
    std::vector<float> diff;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        const float da = a[i].depth.at<float>(y, x), db = b[i].depth.at<float>(y, x);
        if (da > 0.f && db > 0.f) diff.push_back(std::abs(da - db));
      }
    EXPECT_GE(compare(a[i], b[i]).mask_agree, 0.998) << "view " << i;
    std::sort(diff.begin(), diff.end());
    // 0.27 mm on the surface; along the ray more where the surface is seen at a slant, and a
    // few pixels on inner edges where the nearer surface changes.
    EXPECT_LE(diff[diff.size() / 2], 0.0003f) << "view " << i;
    EXPECT_LE(diff[diff.size() * 95 / 100], 0.002f) << "view " << i;
  }
}

TEST(Render, BadCameraIsAnInputError) {
  const Mesh box = test::boxMesh({0.1f, 0.1f, 0.1f});
  MeshRenderer renderer(test::context(), box);
  Camera cam = smallCamera();
  cam.fx = 0;
  EXPECT_THROW(renderer.render(cam, {Pose{}}), InputError);
  cam = smallCamera();
  cam.width = 0;
  EXPECT_THROW(renderReference(box, cam, Pose{}), InputError);
}

}  // namespace
}  // namespace vkpose
