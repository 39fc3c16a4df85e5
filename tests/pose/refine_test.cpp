// Pose refinement (stage 7): MLS, voxel grid and the adaptive coarse-to-fine ICP on rendered
// and real crops against known poses, and against a plain fixed-threshold PCL ICP.
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <thread>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cloud_support.hpp"
#include "mesh_support.hpp"
#include "geometry/nearest_neighbours.hpp"
#include "geometry/point_cloud.hpp"
#include "pose/refine.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

using test::rotationErrorDeg;
using test::translationError;

Pose lookAt(const Eigen::Vector3f& dir, const Eigen::Vector3f& centre, float distance, float inplane) {
  const TrainingView v = lookAtView(dir, centre, distance, inplane);
  return {v.R, v.t};
}

/// What stage 6 hands over: the model's visible surface rendered at the initial pose, in the
/// object frame.
PointCloud modelSurface(const Mesh& mesh, const Camera& camera, const Pose& initial) {
  return transformed(test::visibleSurface(mesh, camera, initial), test::inverse(initial));
}

void print(const std::string& what, const RefineResult& r, const Pose& truth) {
  std::cout << fmt::format("{}: {:.2f} deg {:.2f} mm off, {} iterations, converged {}/{}, fitness {:.3g} m^2 "
                           "({} pairs), scene {} / model {} points, MLS {:.1f} ms, voxel {:.1f} ms, ICP {:.1f} ms\n",
                           what, rotationErrorDeg(r.pose.R, truth.R), 1e3f * translationError(r.pose, truth),
                           r.iterations, r.coarse_converged, r.converged, r.fitness, r.correspondences,
                           r.scene_points, r.model_points, r.mls_ms, r.voxel_ms, r.icp_ms);
}

bool samePose(const Pose& a, const Pose& b) { return a.R == b.R && a.t == b.t; }

// ---- the pipeline on synthetic crops with exact ground truth ------------------------------

/// The L-shaped test mesh at 0.7 m in a crop with 1 mm noise, a background 5 cm behind and 5%
/// outliers.
struct LShapeScene {
  Mesh mesh = test::lShapeMesh();
  Camera camera;
  Pose truth = lookAt({0.4f, -0.5f, 0.75f}, mesh.centroid, 0.7f, 20.f);
  PointCloud scene;
  LShapeScene() {
    std::mt19937 rng(7);
    scene = test::syntheticCrop(mesh, camera, truth, 0.001f, 0.05f, rng);
  }
};

TEST(Refine, RecoversPerturbedPoseOfLShapeInClutter) {
  const LShapeScene s;
  const Pose initial = test::perturbed(s.truth, {1.f, 2.f, -0.5f}, 8.f, {0.012f, -0.006f, 0.0065f});
  ASSERT_NEAR(rotationErrorDeg(initial.R, s.truth.R), 8.f, 0.01f);
  ASSERT_NEAR(translationError(initial, s.truth), 0.015f, 1e-4f);
  const RefineResult r = refinePose(modelSurface(s.mesh, s.camera, initial), s.scene, initial);
  print("L shape, 8 deg 15 mm off", r, s.truth);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(rotationErrorDeg(r.pose.R, s.truth.R), 2.f);
  EXPECT_LT(translationError(r.pose, s.truth), 0.003f);
  EXPECT_NEAR(r.pose.R.determinant(), 1.f, 1e-5f);
  EXPECT_GT(r.correspondences, r.model_points / 3);
  EXPECT_LT(r.fitness, 4e-6);  // (2 mm)^2: residuals at the noise level
  EXPECT_GT(r.mls_ms, 0.0);
  EXPECT_GT(r.icp_ms, 0.0);
}

// The paper's reason for the adaptive threshold: no distance to tune. On 8 hypotheses 8 deg and
// 15 mm off, in a crop with 10% outliers, it succeeds as often as the best fixed threshold and
// is as accurate; a fixed threshold below the initial error (5 mm) loses hypotheses.
// Measured (mean ADD over the 8): adaptive 8/8, 0.61 mm; fixed 5 mm 5/8, 5.4 mm; 1 cm 7/8,
// 2.2 mm; 2 and 5 cm 8/8, 0.67 mm. With 30% outliers every variant fails most hypotheses
// (not asserted).
TEST(Refine, AdaptiveThresholdMatchesBestFixedPclIcpInClutter) {
  // The figures above are the can's: on the carton that would stand in for it the adaptive
  // threshold brings back 5 of 8, so this comparison keeps the real model.
  VKPOSE_REQUIRE_SHARED_DATA();
  const Mesh mesh = loadMesh(test::sharedData() + "/lmo_scene2_frame3/models/obj_000005.ply", MeshUnits::Millimetres);
  const Camera camera;
  const Pose truth = lookAt({0.3f, -0.6f, 0.7f}, mesh.centroid, 0.7f, -30.f);
  std::mt19937 rng(11);
  const PointCloud scene = test::syntheticCrop(mesh, camera, truth, 0.0015f, 0.1f, rng, 0.03f, 20);
  const auto hypotheses = test::hypothesesAround(truth, 8, 8.f, 0.015f, 3);
  std::vector<PointCloud> models;
  for (const auto& h : hypotheses) models.push_back(modelSurface(mesh, camera, h));

  struct Score {
    int ok = 0;
    double mean_add = 0;
  };
  auto score = [&](float fixed_m) {
    Score s;
    for (std::size_t i = 0; i < hypotheses.size(); ++i) {
      RefineParams params;
      params.fixed_max_correspondence_m = fixed_m;
      const RefineResult r = refinePose(models[i], scene, hypotheses[i], params);
      s.ok += rotationErrorDeg(r.pose.R, truth.R) < 2.f && translationError(r.pose, truth) < 0.003f;
      s.mean_add += test::addError(mesh.vertices, r.pose, truth) / double(hypotheses.size());
    }
    std::cout << fmt::format("{}: {}/8 within 2 deg and 3 mm, mean ADD {:.2f} mm\n",
                             fixed_m > 0 ? fmt::format("fixed {} m", fixed_m) : std::string("adaptive"), s.ok,
                             1e3 * s.mean_add);
    return s;
  };
  const Score adaptive = score(0.f);
  EXPECT_EQ(adaptive.ok, 8);
  double best_fixed_add = std::numeric_limits<double>::max();
  for (float fixed : {0.005f, 0.01f, 0.02f, 0.05f}) {
    const Score f = score(fixed);
    EXPECT_GE(adaptive.ok, f.ok) << "fixed " << fixed;
    best_fixed_add = std::min(best_fixed_add, f.mean_add);
  }
  EXPECT_LE(adaptive.mean_add, 1.1 * best_fixed_add);
}

TEST(Refine, RecoversPosesOfLmoModelInSyntheticCrop) {
  // A synthetic crop needs only a mesh: without ../shared/data the demo's carton stands in.
  const Mesh mesh = test::meshOrStandIn("lmo_scene2_frame3/models/obj_000005.ply", MeshUnits::Millimetres);
  const Camera camera;
  const Pose truth = lookAt({-0.5f, 0.2f, 0.8f}, mesh.centroid, 0.75f, 50.f);
  std::mt19937 rng(2);
  const PointCloud scene = test::syntheticCrop(mesh, camera, truth, 0.0015f, 0.05f, rng);
  for (const Pose& initial : test::hypothesesAround(truth, 3, 8.f, 0.015f, 9)) {
    const RefineResult r = refinePose(modelSurface(mesh, camera, initial), scene, initial);
    print("obj_000005 synthetic", r, truth);
    EXPECT_TRUE(r.converged);
    EXPECT_LT(rotationErrorDeg(r.pose.R, truth.R), 2.f);
    EXPECT_LT(translationError(r.pose, truth), 0.003f);
  }
}

// ---- a real crop ----------------------------------------------------------------------------

/// LM-O scene 2 frame 3, object 5 (the can): its ground-truth pose and the depth crop of its
/// visible box grown by 10 pixels (table and neighbour included), metres.
struct LmoCrop {
  Mesh mesh;
  Camera camera;
  Pose truth;
  PointCloud scene;
};

LmoCrop lmoCrop(int margin_px = 10) {
  const std::string dir = test::sharedData() + "/lmo_scene2_frame3/";
  LmoCrop c;
  c.mesh = loadMesh(dir + "models/obj_000005.ply", MeshUnits::Millimetres);
  c.camera = loadCamera(dir + "camera.json");
  const auto gt = nlohmann::json::parse(std::ifstream(dir + "test/000002/scene_gt.json"))["3"];
  const auto info = nlohmann::json::parse(std::ifstream(dir + "test/000002/scene_gt_info.json"))["3"];
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (gt[i]["obj_id"] != 5) continue;
    const auto R = gt[i]["cam_R_m2c"].get<std::vector<float>>();
    const auto t = gt[i]["cam_t_m2c"].get<std::vector<float>>();
    c.truth.R = Eigen::Matrix<float, 3, 3, Eigen::RowMajor>(R.data());
    c.truth.t = 0.001f * Eigen::Vector3f(t[0], t[1], t[2]);
    const auto b = info[i]["bbox_visib"].get<std::vector<int>>();
    const cv::Rect roi(b[0] - margin_px, b[1] - margin_px, b[2] + 2 * margin_px, b[3] + 2 * margin_px);
    c.scene = test::backProjectMm(test::lmoFrame().depth_mm, c.camera, roi);
  }
  return c;
}

// On real depth the ground truth is not ICP's optimum: this frame's depth lies a median 6 mm
// behind the model rendered at the ground-truth pose, so ICP started at the ground truth moves
// 4.7 mm (and 0.7 deg). The check: from 8 deg / 15 mm off, ICP reaches that same optimum
// (translation within 2 mm; rotation about the can's axis is weakly constrained, measured up
// to 3.3 deg) and is correct by the paper's criterion (ADD < 0.15 diameter).
TEST(Refine, ReachesTheDataOptimumOnRealLmoCrop) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const LmoCrop c = lmoCrop();
  ASSERT_GT(c.scene.size(), 8000u);
  const RefineResult optimum = refinePose(modelSurface(c.mesh, c.camera, c.truth), c.scene, c.truth);
  print("real crop, from the ground truth", optimum, c.truth);
  EXPECT_LT(translationError(optimum.pose, c.truth), 0.007f);
  for (const Pose& initial : test::hypothesesAround(c.truth, 4, 8.f, 0.015f, 5)) {
    const RefineResult r = refinePose(modelSurface(c.mesh, c.camera, initial), c.scene, initial);
    print(fmt::format("real crop ({} points), from {:.1f} mm ADD", c.scene.size(),
                      1e3f * test::addError(c.mesh.vertices, initial, c.truth)),
          r, c.truth);
    EXPECT_TRUE(r.converged);
    EXPECT_LT(translationError(r.pose, optimum.pose), 0.002f);
    EXPECT_LT(rotationErrorDeg(r.pose.R, optimum.pose.R), 4.f);
    EXPECT_LT(test::addError(c.mesh.vertices, r.pose, c.truth), 0.15f * c.mesh.diameter);
    EXPECT_LT(test::addError(c.mesh.vertices, r.pose, c.truth), test::addError(c.mesh.vertices, initial, c.truth));
  }
}

// ---- the parts --------------------------------------------------------------------------

double rmsRadialError(const PointCloud& points, const Eigen::Vector3f& centre, float radius) {
  double sum = 0;
  for (const auto& p : points) sum += std::pow((p - centre).norm() - radius, 2);
  return std::sqrt(sum / double(points.size()));
}

// Depth noise of 1.5 mm on a 4 cm sphere seen at 0.7 m. The voxel grid alone does not remove it
// (it bins by the noisy positions); MLS at the default radius does. Measured: 1.08 mm ->
// 0.20 mm RMS (order 2), plane fits (order 1) 0.65 mm, curvature bias.
TEST(Refine, MlsReducesNoiseOnSphere) {
  const float radius = 0.04f;
  Pose pose;
  pose.t = {0.02f, -0.01f, 0.7f};
  const Camera camera;
  PointCloud noisy = test::visibleSurface(test::icosphere(radius, 4), camera, pose);
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.f, 0.0015f);
  for (auto& p : noisy) p.z() += noise(rng);
  const double before = rmsRadialError(noisy, pose.t, radius);
  ASSERT_GT(before, 0.001);
  const RefineParams defaults;
  const PointCloud smoothed = smoothMls(noisy, defaults.mls_radius, defaults.mls_polynomial_order);
  const PointCloud seeds = smoothMls(noisy, defaults.mls_radius, defaults.mls_polynomial_order, defaults.voxel_size);
  const PointCloud voxel_only = voxelFilter(noisy, defaults.voxel_size);
  const double after = rmsRadialError(smoothed, pose.t, radius);
  const double after_seeds = rmsRadialError(seeds, pose.t, radius);
  std::cout << fmt::format("RMS radial error: noisy {:.3f} mm, voxel only {:.3f}, MLS {:.3f}, MLS at seeds {:.3f}\n",
                           1e3 * before, 1e3 * rmsRadialError(voxel_only, pose.t, radius), 1e3 * after,
                           1e3 * after_seeds);
  EXPECT_GT(smoothed.size(), noisy.size() * 95 / 100);
  EXPECT_LT(after, 0.35 * before);
  EXPECT_LT(after_seeds, 0.35 * before);
  EXPECT_LT(seeds.size(), noisy.size() / 2);
  EXPECT_LT(rmsRadialError(smoothMls(noisy, defaults.mls_radius, 1), pose.t, radius), before);
  // Neighbourhoods thinned to the default's 64 points smooth nearly as well.
  const double thinned = rmsRadialError(
      smoothMls(noisy, defaults.mls_radius, defaults.mls_polynomial_order, defaults.voxel_size, defaults.mls_max_neighbours),
      pose.t, radius);
  std::cout << fmt::format("MLS at seeds, at most {} neighbours: {:.3f} mm\n", defaults.mls_max_neighbours, 1e3 * thinned);
  EXPECT_LT(thinned, 0.35 * before);
}

// smoothMls against PCL's MovingLeastSquares on the same crops: a noisy sphere on a table seen at
// 0.7 m (every point and voxel seeds, orders 1 and 2) and a sparse corner where neighbourhoods
// hold fewer than 6 points. The same points in the same order, to float rounding.
TEST(Mls, MatchesPclsMovingLeastSquares) {
  Pose pose;
  pose.t = {0.02f, -0.01f, 0.7f};
  const Camera camera;
  PointCloud crop = test::visibleSurface(test::icosphere(0.04f, 4), camera, pose);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 0.0015f);
  std::uniform_real_distribution<float> uni(-0.08f, 0.08f);
  for (auto& p : crop) p.z() += noise(rng);
  for (int i = 0; i < 4000; ++i) crop.emplace_back(uni(rng), uni(rng), 0.74f + noise(rng));  // the table
  for (int i = 0; i < 30; ++i) crop.emplace_back(0.2f + 0.003f * i, 0.2f, 0.7f);  // a sparse line
  crop.emplace_back(std::nanf(""), 0.f, 0.7f);
  for (const auto& [order, seed_voxel] : {std::pair{2, 0.f}, std::pair{2, 0.004f}, std::pair{1, 0.004f}}) {
    const PointCloud ours = smoothMls(crop, 0.01f, order, seed_voxel);
    const PointCloud pcl = smoothMlsPcl(crop, 0.01f, order, seed_voxel);
    ASSERT_EQ(ours.size(), pcl.size()) << "order " << order << ", seeds " << seed_voxel;
    float worst = 0.f;
    for (std::size_t i = 0; i < ours.size(); ++i) worst = std::max(worst, (ours[i] - pcl[i]).norm());
    EXPECT_LT(worst, 2e-6f) << "order " << order << ", seeds " << seed_voxel;
  }
}

TEST(Refine, MlsFlattensNoisyPlaneAndDropsIsolatedPoints) {
  PointCloud plane;
  std::mt19937 rng(4);
  std::normal_distribution<float> noise(0.f, 0.002f);
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 80; ++x) plane.emplace_back(0.0012f * x, 0.0012f * y, 0.8f + noise(rng));
  plane.emplace_back(0.5f, 0.5f, 0.3f);  // alone: no neighbours within the radius
  const PointCloud out = smoothMls(plane, 0.01f, 2);
  double before = 0, after = 0;
  for (std::size_t i = 0; i + 1 < plane.size(); ++i) before += std::pow(plane[i].z() - 0.8f, 2);
  for (const auto& p : out) after += std::pow(p.z() - 0.8f, 2);
  before = std::sqrt(before / double(plane.size() - 1));
  after = std::sqrt(after / double(out.size()));
  EXPECT_EQ(out.size(), plane.size() - 1);
  EXPECT_LT(after, 0.3 * before);
}

// A 2 cm cube of points 1 mm apart, offset so that no point lies on a voxel face: a 4 mm grid
// keeps one point per voxel, at the voxel's centre (the mean of its 4x4x4 points).
TEST(Refine, VoxelFilterKeepsOneCentroidPerVoxel) {
  PointCloud grid;
  for (int z = 0; z < 20; ++z)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x) grid.emplace_back(0.0005f + 0.001f * x, 0.0005f + 0.001f * y, 0.7005f + 0.001f * z);
  grid.emplace_back(std::nanf(""), 0.f, 0.7f);
  const PointCloud out = voxelFilter(grid, 0.004f);
  ASSERT_EQ(out.size(), 125u);
  std::set<std::tuple<int, int, int>> cells;
  for (const auto& p : out) {
    const Eigen::Vector3f cell = (p - Eigen::Vector3f(0.f, 0.f, 0.7f)) / 0.004f;
    const Eigen::Vector3f centre = cell.array().floor() + 0.5f;
    EXPECT_LT((cell - centre).norm(), 1e-3f) << p.transpose();
    cells.emplace(int(cell.x()), int(cell.y()), int(cell.z()));
  }
  EXPECT_EQ(cells.size(), 125u);
  EXPECT_EQ(voxelFilter(grid, 0.f).size(), grid.size() - 1);  // 0: no filter, NaN dropped
  EXPECT_TRUE(voxelFilter({}, 0.004f).empty());
}

TEST(Refine, EmptyOrTinyCloudsReturnTheInitialPose) {
  const LShapeScene s;
  const PointCloud model = modelSurface(s.mesh, s.camera, s.truth);
  const Pose initial = test::perturbed(s.truth, {0.f, 1.f, 0.f}, 5.f, {0.01f, 0.f, 0.f});
  PointCloud five(s.scene.begin(), s.scene.begin() + 5);
  PointCloud one_voxel(200, s.truth.t);  // 200 points, 1 after the voxel grid
  PointCloud not_finite(100, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  for (const auto& [name, m, sc] : {std::tuple{"empty scene", model, PointCloud{}},
                                    std::tuple{"empty model", PointCloud{}, s.scene},
                                    std::tuple{"5 scene points", model, five},
                                    std::tuple{"one voxel", one_voxel, s.scene},
                                    std::tuple{"NaN scene", model, not_finite}}) {
    SCOPED_TRACE(name);
    RefineResult r;
    ASSERT_NO_THROW(r = refinePose(m, sc, initial));
    EXPECT_FALSE(r.converged);
    EXPECT_EQ(r.iterations, 0);
    EXPECT_TRUE(samePose(r.pose, initial));
  }
}

TEST(Refine, RejectsNonsenseParameters) {
  const PointCloud cloud(20, Eigen::Vector3f(0.f, 0.f, 0.7f));
  auto with = [](auto change) {
    RefineParams p;
    change(p);
    return p;
  };
  EXPECT_THROW(refinePose(cloud, cloud, {}, with([](auto& p) { p.voxel_size = -1.f; })), InputError);
  EXPECT_THROW(refinePose(cloud, cloud, {}, with([](auto& p) { p.coarse_fraction = 0.f; })), InputError);
  EXPECT_THROW(refinePose(cloud, cloud, {}, with([](auto& p) { p.fine_fraction = 1.5f; })), InputError);
  EXPECT_THROW(refinePose(cloud, cloud, {}, with([](auto& p) { p.mls_radius = 0.f; })), InputError);
  EXPECT_THROW(refinePose(cloud, cloud, {}, with([](auto& p) { p.fine_iterations = -1; })), InputError);
  // One range per parameter (the config table's): a radius of 0 is refused with MLS off too.
  EXPECT_THROW(refinePose(cloud, cloud, {}, with([](auto& p) { p.mls = false, p.mls_radius = 0.f; })), InputError);
  EXPECT_NO_THROW(refinePose(cloud, cloud, {}, with([](auto& p) { p.mls = false; })));
  EXPECT_THROW(smoothMls(cloud, std::nanf(""), 2), InputError);
}

// refinePose runs for several hypotheses at once: no shared state, so threads give exactly the
// sequential results.
TEST(Refine, ParallelCallsGiveTheSequentialResults) {
  const LShapeScene s;
  const auto hypotheses = test::hypothesesAround(s.truth, 4, 8.f, 0.015f, 21);
  std::vector<PointCloud> models;
  for (const auto& h : hypotheses) models.push_back(modelSurface(s.mesh, s.camera, h));
  std::vector<RefineResult> sequential, parallel(hypotheses.size());
  for (std::size_t i = 0; i < hypotheses.size(); ++i)
    sequential.push_back(refinePose(models[i], s.scene, hypotheses[i]));
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < hypotheses.size(); ++i)
    threads.emplace_back([&, i] { parallel[i] = refinePose(models[i], s.scene, hypotheses[i]); });
  for (auto& t : threads) t.join();
  for (std::size_t i = 0; i < hypotheses.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_TRUE(samePose(parallel[i].pose, sequential[i].pose));
    EXPECT_EQ(parallel[i].iterations, sequential[i].iterations);
    EXPECT_EQ(parallel[i].fitness, sequential[i].fitness);
    EXPECT_EQ(parallel[i].scene_points, sequential[i].scene_points);
    EXPECT_LT(translationError(sequential[i].pose, s.truth), 0.003f);
  }
}

// ICP's nearest-neighbour grid against PCL's k-d tree and a brute-force scan: the same point for
// every query, near the surface (the fine grid answers), centimetres off it (the coarse grid),
// far away (the whole-cloud scan), with non-finite points in the cloud and a grid squeezed
// into a few cells.
TEST(NearestNeighbours, FindTheSamePointsAsPclsKdTreeAndABruteForceScan) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(-1.f, 1.f);
  std::normal_distribution<float> noise(0.f, 0.002f);
  // A voxel-filtered surface crop, like ICP's scene: a bumpy patch 12 cm across, a ledge, a
  // few stray points, one NaN and one infinite point.
  PointCloud surface;
  for (int i = 0; i < 6000; ++i) {
    const float x = 0.06f * uni(rng), y = 0.06f * uni(rng);
    const float z = 0.7f + 0.01f * std::sin(40.f * x) * std::cos(30.f * y) + (x > 0.03f ? 0.02f : 0.f) + noise(rng);
    surface.emplace_back(x, y, z);
  }
  for (int i = 0; i < 20; ++i) surface.emplace_back(0.1f * uni(rng), 0.1f * uni(rng), 0.7f + 0.1f * uni(rng));
  surface.insert(surface.begin() + 17, Eigen::Vector3f(std::nanf(""), 0.f, 0.7f));
  surface.push_back(Eigen::Vector3f(0.f, std::numeric_limits<float>::infinity(), 0.7f));
  const PointCloud cloud = voxelFilter(surface, 0.004f);
  PointCloud queries;
  for (const float spread : {0.002f, 0.01f, 0.03f, 0.3f})  // near, centimetres off, far
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector3f p = cloud[std::uniform_int_distribution<std::size_t>(0, cloud.size() - 1)(rng)];
      queries.push_back(p + spread * Eigen::Vector3f(uni(rng), uni(rng), uni(rng)));
    }
  queries.push_back(Eigen::Vector3f(std::nanf(""), 0.f, 0.f));
  PointCloud with_bad = cloud;  // the grid must skip what the filter would have dropped
  with_bad.insert(with_bad.begin() + 3, Eigen::Vector3f(std::nanf(""), 0.f, 0.7f));

  const std::vector<int> pcl_nearest = nearestByPclKdTree(with_bad, queries);
  for (const std::size_t max_cells : {std::size_t(1) << 22, std::size_t(64)}) {
    const NearestNeighbours grid(with_bad, 0.004f, max_cells);
    EXPECT_EQ(grid.size(), cloud.size());
    std::size_t differ_from_pcl = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      float d = 0.f;
      const int found = grid.nearest(queries[q], d);
      if (!queries[q].allFinite()) {
        EXPECT_EQ(found, -1);
        continue;
      }
      float brute = std::numeric_limits<float>::infinity();
      for (const auto& p : with_bad)
        if (p.allFinite()) brute = std::min(brute, (p - queries[q]).squaredNorm());
      ASSERT_GE(found, 0);
      EXPECT_EQ(d, brute) << "query " << q;
      EXPECT_EQ(d, (with_bad[static_cast<std::size_t>(found)] - queries[q]).squaredNorm());
      if (found != pcl_nearest[q]) {  // a tie, nothing else
        ++differ_from_pcl;
        EXPECT_EQ((with_bad[static_cast<std::size_t>(pcl_nearest[q])] - queries[q]).squaredNorm(), d);
      }
    }
    EXPECT_LE(differ_from_pcl, 2u);
    // The far queries need the whole-cloud scan, the near ones never.
    EXPECT_GT(grid.fullScans(), 0u);
    EXPECT_LT(grid.fullScans(), 1000u);

    // With a hint (ICP's last answer for the same model point): the nearest point of the query
    // before a step of up to 3 mm, any point of the cloud, none, a non-finite or unknown one.
    std::size_t hinted = 0;
    for (std::size_t q = 0; q + 1 < queries.size(); ++q) {
      float before_d = 0.f;
      const Eigen::Vector3f before = queries[q] + 0.003f * Eigen::Vector3f(uni(rng), uni(rng), uni(rng));
      const int from_before = grid.nearest(before, before_d);
      const int any = static_cast<int>(std::uniform_int_distribution<std::size_t>(0, with_bad.size() - 1)(rng));
      for (const int hint : {from_before, any, -1, 3, static_cast<int>(with_bad.size()) + 5}) {
        float d = 0.f, plain_d = 0.f;
        const int found = grid.nearest(queries[q], hint, d);
        const int plain = grid.nearest(queries[q], plain_d);
        EXPECT_EQ(d, plain_d) << "query " << q << " hint " << hint;
        ASSERT_GE(found, 0);
        EXPECT_EQ((with_bad[static_cast<std::size_t>(found)] - queries[q]).squaredNorm(), d);
        hinted += found == plain;
      }
    }
    EXPECT_GE(hinted, 5 * (queries.size() - 1) - 10);  // the same point but for ties

    // Within a distance (the symmetry search's capped distances): the nearest point when it
    // lies within, else -1; no whole-cloud scan while the distance is within the coarse
    // grid's reach (a smaller grid than max_cells asks for has larger cells).
    std::size_t within_scans = 0;
    const float coarse_reach = NearestNeighbours::kMaxRing * NearestNeighbours::kCoarse * 0.004f;
    for (const float max_dist : {0.f, 0.003f, 0.012f, coarse_reach}) {
      std::size_t inside = 0;
      for (const auto& q : queries) {
        float d = 0.f, plain_d = 0.f;
        const std::size_t scans_before = grid.fullScans();
        const int found = grid.nearestWithin(q, max_dist, d);
        within_scans += grid.fullScans() - scans_before;
        const int plain = grid.nearest(q, plain_d);
        if (plain >= 0 && plain_d <= max_dist * max_dist) {
          ++inside;
          EXPECT_EQ(d, plain_d) << "within " << max_dist;
          ASSERT_GE(found, 0);
          EXPECT_EQ((with_bad[static_cast<std::size_t>(found)] - q).squaredNorm(), d);
        } else {
          EXPECT_EQ(found, -1) << "within " << max_dist;
          EXPECT_EQ(d, std::numeric_limits<float>::infinity());
        }
      }
      if (max_dist >= 0.012f) {
        EXPECT_GT(inside, 1000u);  // both answers were asked for
      }
      if (max_dist > 0.f && max_dist < coarse_reach) {
        EXPECT_LT(inside, queries.size() - 100);
      }
    }
    float d = 0.f;
    EXPECT_EQ(grid.nearestWithin(queries[0], -1.f, d), -1);
    EXPECT_EQ(grid.nearestWithin(queries[0], std::nanf(""), d), -1);
    if (max_cells > 64) {
      EXPECT_EQ(within_scans, 0u);
    }
  }
  float d = 0.f;
  EXPECT_EQ(NearestNeighbours({}, 0.004f).nearest(Eigen::Vector3f(0.f, 0.f, 1.f), d), -1);
  EXPECT_NE(test::inputErrorOf([] { NearestNeighbours({Eigen::Vector3f::Zero()}, 0.f); }).find("cell size"), std::string::npos);
}

}  // namespace
}  // namespace vkpose
