// `vkpose synth`: reproducible bytes, a BOP dataset the reader loads with boxes that match the
// poses, placements that never intersect and rest on the table or in the bin, Tejani poses
// taken verbatim, and clear errors for bad input.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "mesh_support.hpp"
#include "synth/placement.hpp"
#include "synth/scene.hpp"
#include "vkpose/bank.hpp"
#include "test_support.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/synth.hpp"

namespace vkpose {
namespace {

namespace fs = std::filesystem;

fs::path freshDir(const std::string& name) {
  const fs::path dir = test::scratchDir("vkpose_synth_" + name + "_");
  fs::remove_all(dir);
  return dir;
}

/// An L-shaped part (no symmetry, one unstable side) as a PLY in millimetres.
std::string lPartPly() {
  static const std::string path = [] {
    const fs::path dir = freshDir("meshes");
    fs::create_directories(dir);
    const std::string p = (dir / "l_part.ply").string();
    writePlyMillimetres(test::lShapeMesh(), p, true);
    return p;
  }();
  return path;
}

SynthParams smallParams(uint32_t seed) {
  SynthParams p;
  p.meshes = {lPartPly()};
  p.units = MeshUnits::Millimetres;
  p.images = 2;
  p.seed = seed;
  p.min_instances = 2;
  p.max_instances = 3;
  p.clutter = 3;
  p.camera.width = 320;
  p.camera.height = 240;
  p.camera.cx = 159.5;
  p.camera.cy = 119.5;
  p.camera.fx = p.camera.fy = 286.0;
  return p;
}

std::map<std::string, std::string> filesUnder(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file()) {
      std::ifstream in(e.path(), std::ios::binary);
      std::ostringstream bytes;
      bytes << in.rdbuf();
      out[fs::relative(e.path(), root).string()] = bytes.str();
    }
  return out;
}

/// Box of the mesh's vertices projected at a pose, clipped to the image.
cv::Rect projectedBox(const Mesh& mesh, const GroundTruthPose& g, const Camera& c) {
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  for (const auto& v : mesh.vertices) {
    const Eigen::Vector2f p = c.project(g.R * v + g.t);
    x0 = std::min(x0, p.x()), y0 = std::min(y0, p.y()), x1 = std::max(x1, p.x()), y1 = std::max(y1, p.y());
  }
  const cv::Rect box(cv::Point(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))),
                     cv::Point(static_cast<int>(std::ceil(x1)) + 1, static_cast<int>(std::ceil(y1)) + 1));
  return box & cv::Rect(0, 0, c.width, c.height);
}

TEST(SynthDataset, SameSeedSameBytesOtherSeedOtherBytes) {
  const fs::path a = freshDir("a"), b = freshDir("b"), c = freshDir("c");
  generateSyntheticDataset(test::context(), smallParams(7), a.string(), false);
  generateSyntheticDataset(test::context(), smallParams(7), b.string(), false);
  generateSyntheticDataset(test::context(), smallParams(8), c.string(), false);
  const auto fa = filesUnder(a), fb = filesUnder(b), fc = filesUnder(c);
  ASSERT_EQ(fa.size(), 10u);  // models: ply + info; camera.json; 2 rgb + 2 depth; 3 scene files
  ASSERT_EQ(fb.size(), fa.size());
  for (const auto& [name, bytes] : fa) {
    ASSERT_TRUE(fb.count(name)) << name;
    EXPECT_TRUE(fb.at(name) == bytes) << name << " differs between two runs with the same seed";
  }
  for (const char* name : {"test/000001/rgb/000000.png", "test/000001/depth/000001.png", "test/000001/scene_gt.json"})
    EXPECT_FALSE(fc.at(name) == fa.at(name)) << name << " is the same with another seed";
  for (const auto& d : {a, b, c}) fs::remove_all(d);
}

TEST(SynthDataset, LoadsAsBopAndEveryPoseProjectsOntoItsBoxes) {
  const fs::path dir = freshDir("bop");
  SynthParams p = smallParams(3);
  p.symmetric = {1};
  const SynthSummary s = generateSyntheticDataset(test::context(), p, dir.string(), false);
  const BopDataset ds = loadBopDataset(dir.string());
  ASSERT_EQ(ds.images.size(), 2u);
  ASSERT_EQ(ds.models.size(), 1u);
  EXPECT_TRUE(ds.models.at(1).symmetric);
  const Mesh model = loadMesh(ds.modelPath(1), MeshUnits::Millimetres);
  const Mesh original = test::lShapeMesh();
  EXPECT_NEAR(ds.models.at(1).diameter, original.diameter, 1e-5f);
  EXPECT_LT((model.bbox_min - original.bbox_min).norm(), 1e-5f);
  int instances = 0;
  float nearest = 1e9f, farthest = 0.f;  // of the centres, as the summary reports them
  for (const BopImage& im : ds.images) {
    EXPECT_EQ(im.camera.width, 320);
    EXPECT_EQ(im.camera.depth_scale, 1.0);
    ASSERT_EQ(im.gt.size(), im.gt_info.size());
    EXPECT_GE(im.gt.size(), 2u);
    const cv::Mat depth = cv::imread(im.depth_path, cv::IMREAD_ANYDEPTH);
    for (std::size_t i = 0; i < im.gt.size(); ++i) {
      const GroundTruthInfo& info = im.gt_info[i];
      ++instances;
      ASSERT_GT(info.px_count_visib, 0) << "placements stand where the camera sees them";
      const cv::Rect projected = projectedBox(model, im.gt[i], im.camera);
      EXPECT_EQ((info.bbox_visib & projected), info.bbox_visib) << "image " << im.image_id << " instance " << i;
      EXPECT_EQ((info.bbox_obj & projected), info.bbox_obj) << "image " << im.image_id << " instance " << i;
      EXPECT_EQ((info.bbox_visib & info.bbox_obj), info.bbox_visib);
      EXPECT_GE(info.px_count_all, info.px_count_visib);
      EXPECT_LE(info.px_count_valid, info.px_count_all);
      EXPECT_NEAR(info.visib_fract, static_cast<float>(info.px_count_visib) / static_cast<float>(info.px_count_all),
                  1e-6f);
      // The sensor sees the object's centre's depth near where the pose puts it.
      const Eigen::Vector3f centre = im.gt[i].R * model.bboxCentre() + im.gt[i].t;
      EXPECT_GT(centre.z(), 0.5f);
      EXPECT_LT(centre.z(), 2.0f);
      nearest = std::min(nearest, centre.norm());
      farthest = std::max(farthest, centre.norm());
    }
    EXPECT_GT(cv::countNonZero(depth), depth.total() / 2) << "the table fills the view";
  }
  EXPECT_EQ(instances, s.instances);
  EXPECT_NEAR(s.nearest_m, nearest, 1e-3f);  // the files hold poses to the micrometre
  EXPECT_NEAR(s.farthest_m, farthest, 1e-3f);
  EXPECT_LT(s.nearest_m, s.farthest_m);
  fs::remove_all(dir);
}

/// Any vertex of `a` inside the bounding box of `b` (b's frame): a check of placements that
/// does not use the separating-axis test they were made with.
bool vertexInside(const Mesh& a, const Pose& wa, const Mesh& b, const Pose& wb) {
  const Pose b_T_a = compose(invert(wb), wa);
  for (const auto& v : a.vertices) {
    const Eigen::Vector3f p = b_T_a.R * v + b_T_a.t;
    if ((p.array() > b.bbox_min.array()).all() && (p.array() < b.bbox_max.array()).all()) return true;
  }
  return false;
}

float lowestZ(const Mesh& m, const Pose& w) {
  float z = 1e9f;
  for (const auto& v : m.vertices) z = std::min(z, (w.R * v + w.t).z());
  return z;
}

// A model that a turn maps onto itself, shape and colour (the spark-plug key's half-turn), is
// written with BOP's symmetries_discrete (row-major 4x4, translation in mm), so that eval
// scores it with ADI; an L has none.
TEST(SynthDataset, ExactSymmetriesAreWrittenAsBopsDiscreteOnes) {
  const Mesh box = test::boxMesh({0.04f, 0.08f, 0.2f}, {0.f, 0.f, 0.1f});
  BopModel symmetric{1, &box, {}};
  for (const NearSymmetry& s : exactSymmetries(box, 1e-4f)) symmetric.discrete_symmetries.push_back(s.transform());
  ASSERT_EQ(symmetric.discrete_symmetries.size(), 3u);
  const Mesh l = test::lShapeMesh();
  ASSERT_TRUE(exactSymmetries(l, 1e-4f).empty());
  const BopModel plain{2, &l, {}};
  const nlohmann::json info = nlohmann::json::parse(modelsInfoJson({symmetric, plain}));
  ASSERT_EQ(info["1"]["symmetries_discrete"].size(), 3u);
  for (const auto& m : info["1"]["symmetries_discrete"]) {
    ASSERT_EQ(m.size(), 16u);
    Pose t;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) t.R(r, c) = m[4 * r + c].get<float>();
      t.t[r] = m[4 * r + 3].get<float>() * 1e-3f;
    }
    EXPECT_EQ(m[15].get<double>(), 1.0);
    EXPECT_NEAR(t.R.determinant(), 1.f, 1e-5f);
    EXPECT_LT((t.R * box.bboxCentre() + t.t - box.bboxCentre()).norm(), 1e-5f) << "the box stays where it is";
  }
  EXPECT_FALSE(info["2"].contains("symmetries_discrete"));
}

TEST(SynthPlacement, TableObjectsRestOnItAndNeverIntersect) {
  const Mesh part = test::lShapeMesh(), box = test::boxMesh({0.06f, 0.04f, 0.1f}), sphere = test::icosphere(0.04f, 2);
  const std::vector<const Mesh*> meshes{&part, &box, &sphere, &part, &box, &part, &sphere, &part};
  const Camera camera = tejaniCamera();
  int placed = 0;
  for (uint32_t seed = 0; seed < 20; ++seed) {
    std::mt19937 rng(seed);
    const Pose camera_T_world = randomCamera({}, rng);
    PlacementParams params;
    const auto poses = placeObjects(meshes, {}, params, camera, camera_T_world, rng);
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      if (!poses[i]) continue;
      ++placed;
      EXPECT_NEAR(lowestZ(*meshes[i], *poses[i]), 0.f, 1e-4f) << "seed " << seed << " object " << i;
      const Eigen::Vector3f centre = compose(camera_T_world, *poses[i]).t;
      EXPECT_GT(centre.z(), 0.3f);
      for (std::size_t j = 0; j < i; ++j) {
        if (!poses[j]) continue;
        EXPECT_FALSE(vertexInside(*meshes[i], *poses[i], *meshes[j], *poses[j])) << seed << ": " << i << ", " << j;
        EXPECT_FALSE(vertexInside(*meshes[j], *poses[j], *meshes[i], *poses[i])) << seed << ": " << j << ", " << i;
      }
    }
  }
  EXPECT_GT(placed, 20 * 7) << "nearly every object finds a place";
}

TEST(SynthPlacement, BinPilesStayInsideAndNeverIntersect) {
  const Mesh part = test::lShapeMesh(), box = test::boxMesh({0.06f, 0.04f, 0.1f});
  const std::vector<const Mesh*> meshes(12, &part);
  PlacementParams params;
  params.layout = Layout::Bin;
  int above_floor = 0;
  for (uint32_t seed = 0; seed < 5; ++seed) {
    std::mt19937 rng(seed);
    const auto poses = placeObjects(meshes, binWalls(params), params, tejaniCamera(), randomCamera({}, rng), rng);
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      ASSERT_TRUE(poses[i]) << "12 parts fit in the bin";
      const float low = lowestZ(part, *poses[i]);
      EXPECT_GE(low, 0.f);
      above_floor += low > 0.01f;
      for (const auto& v : part.vertices) {
        const Eigen::Vector3f w = poses[i]->R * v + poses[i]->t;
        EXPECT_LE(std::abs(w.x()), 0.5f * params.bin_inner_m.x());
        EXPECT_LE(std::abs(w.y()), 0.5f * params.bin_inner_m.y());
      }
      for (std::size_t j = 0; j < i; ++j)
        EXPECT_FALSE(vertexInside(part, *poses[i], part, *poses[j]) || vertexInside(part, *poses[j], part, *poses[i]))
            << seed << ": " << i << ", " << j;
    }
  }
  EXPECT_GT(above_floor, 0) << "some parts settle on others: a pile, not a layer";
}

TEST(SynthPlacement, RestingOrientationsAreStable) {
  // A box rests on any face; the most likely ones keep its centre low.
  const auto box = restingOrientations(test::boxMesh({0.1f, 0.04f, 0.02f}));
  EXPECT_EQ(box.size(), 6u);
  // An L: resting on the end of its short leg tips over, so fewer faces are stable.
  const Mesh l = test::lShapeMesh();
  const auto rest = restingOrientations(l);
  EXPECT_LT(rest.size(), 6u);
  for (const auto& r : rest) EXPECT_NEAR(lowestZ(l, {r.R, Eigen::Vector3f(0.f, 0.f, r.lift_m)}), 0.f, 1e-5f);
}

TEST(SynthPlacement, ObjectsRestOnlyWhereTrainingSaysTheyStand) {
  // A scene must hold the poses a bank trained with --resting all covers, no others: synth
  // once let the milk jug balance on its cap (+z up), which training rejects as a base.
  VKPOSE_REQUIRE_SHARED_DATA();
  for (const char* name : {"milk.stl", "juicecarton.stl", "coffee_cup.stl"}) {
    const Mesh mesh = loadMesh(test::sharedData() + "/meshes/" + name, MeshUnits::Metres);
    const UpAxisChoice choice = findUpAxis(mesh);
    std::vector<Eigen::Vector3f> stands;
    for (const RestingCandidate& c : choice.candidates)
      if (c.stands()) stands.push_back(c.up);
    const auto rest = restingOrientations(mesh);
    ASSERT_EQ(rest.size(), stands.size()) << name;
    for (std::size_t i = 0; i < rest.size(); ++i) {
      // The object's up in the world is +z: R maps some standing candidate's up there.
      const Eigen::Vector3f up = rest[i].R.transpose() * Eigen::Vector3f::UnitZ();
      EXPECT_TRUE(std::any_of(stands.begin(), stands.end(), [&](const Eigen::Vector3f& s) { return s.dot(up) > 0.999f; }))
          << name << " rests with " << upAxisName(up) << " up";
    }
  }
  const auto milk = restingOrientations(loadMesh(test::sharedData() + "/meshes/milk.stl", MeshUnits::Metres));
  for (const auto& r : milk) EXPECT_LT((r.R.transpose() * Eigen::Vector3f::UnitZ()).z(), 0.999f) << "the jug on its cap";
}

TEST(SynthScene, AnObjectTheBorderCutsInHalfIsHalfVisible) {
  // BOP's px_count_all counts what the border cuts off (calc_gt_info renders three times the
  // image): a box on the optical axis of a camera whose principal point is on the left edge is
  // cut in half (its silhouette is symmetric about the axis), one to its right is whole.
  const Mesh box = test::boxMesh({0.1f, 0.1f, 0.1f});
  Camera camera;
  camera.cx = 0.0;
  std::vector<SceneObject> objects(2);
  objects[0].mesh = objects[1].mesh = &box;
  objects[0].pose.t = Eigen::Vector3f(0.f, 0.f, 0.8f);
  objects[1].pose.t = Eigen::Vector3f(0.3f, 0.f, 0.8f);
  const SceneRendering r = renderScene(test::context(), objects, camera);
  EXPECT_NEAR(r.visibleFraction(0), 0.5f, 0.03f);
  EXPECT_GT(r.full_pixels[0], cv::countNonZero(r.full_masks[0]));
  EXPECT_FLOAT_EQ(r.visibleFraction(1), 1.f);
}

TEST(SynthScene, ABinFloorSeenFromCloseIsWhole) {
  // A 1 m floor tilted 60 degrees, its centre 0.3 m in front of the camera: its near half
  // reaches behind the camera (whose triangles the rasterizer once dropped, and now clips).
  // Tiled, every pixel whose ray meets the floor's top face (1 cm from its edges) shows the
  // floor.
  const float side = 1.f, thickness = 0.01f;
  const Mesh floor = cuboidMesh({side, side, thickness}, {0.4f, 0.3f, 0.3f}, 0.05f);
  SceneObject o;
  o.mesh = &floor;
  o.pose.R = Eigen::AngleAxisf(std::numbers::pi_v<float> / 3.f, Eigen::Vector3f::UnitX()).toRotationMatrix() *
             Eigen::AngleAxisf(std::numbers::pi_v<float>, Eigen::Vector3f::UnitX()).toRotationMatrix();  // top face (+z) to the camera
  o.pose.t = Eigen::Vector3f(0.f, 0.f, 0.3f);
  const Camera camera;
  const SceneRendering r = renderScene(test::context(), {o}, camera);
  const Eigen::Vector3f normal = o.pose.R.col(2), top = o.pose.t + 0.5f * thickness * normal;
  ASSERT_LT((o.pose.R * Eigen::Vector3f(0.f, -0.5f * side, 0.f) + o.pose.t).z() *
                (o.pose.R * Eigen::Vector3f(0.f, 0.5f * side, 0.f) + o.pose.t).z(),
            0.f)
      << "one edge of the floor must lie behind the camera";
  int expected = 0, missing = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3f ray(static_cast<float>((x - camera.cx) / camera.fx),
                                static_cast<float>((y - camera.cy) / camera.fy), 1.f);
      const float along = normal.dot(top) / normal.dot(ray);
      if (!(along > 0.f)) continue;
      const Eigen::Vector3f in_object = o.pose.R.transpose() * (along * ray - o.pose.t);
      if (std::abs(in_object.x()) > 0.5f * side - 0.01f || std::abs(in_object.y()) > 0.5f * side - 0.01f) continue;
      ++expected;
      missing += r.depth.at<float>(y, x) > 0.f ? 0 : 1;
    }
  EXPECT_GT(expected, camera.width * camera.height / 4);
  EXPECT_EQ(missing, 0) << "of " << expected << " pixels on the floor";
}

TEST(SynthTejani, PosesAreUsedVerbatim) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string data = test::sharedData();
  const fs::path dir = freshDir("tejani");
  SynthParams p;
  p.meshes = {data + "/meshes/coffee_cup.stl", data + "/meshes/juicecarton.stl"};
  p.poses = data + "/tejani_poses";
  p.images = 3;
  p.clutter = 2;
  generateSyntheticDataset(test::context(), p, dir.string(), false);
  const auto files = tejaniPoseFiles(p.poses, {"coffee_cup", "juicecarton"});
  ASSERT_EQ(files.size(), 2u);
  EXPECT_NE(files[1].front().find("juice_carton"), std::string::npos);
  const BopDataset ds = loadBopDataset(dir.string());
  ASSERT_EQ(ds.images.size(), 3u);
  for (const BopImage& im : ds.images) {
    const std::size_t m = static_cast<std::size_t>(im.image_id) % 2, k = static_cast<std::size_t>(im.image_id) / 2;
    const std::vector<Pose> poses = loadTejaniPoses(files[m][k]);
    ASSERT_EQ(im.gt.size(), poses.size()) << files[m][k];
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(im.gt[i].obj_id, static_cast<int>(m) + 1);
      EXPECT_LT((im.gt[i].R - poses[i].R).cwiseAbs().maxCoeff(), 1e-6f);
      EXPECT_LT((im.gt[i].t - poses[i].t).cwiseAbs().maxCoeff(), 1e-6f);
      EXPECT_GT(im.gt_info[i].px_count_visib, 0);
    }
  }
  fs::remove_all(dir);
}

TEST(SynthTejani, TheTableIsUnderTheInstances) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string data = test::sharedData();
  const Mesh cup = loadMesh(data + "/meshes/coffee_cup.stl");
  const auto files = tejaniPoseFiles(data + "/tejani_poses/coffee_cup", {"coffee_cup"});
  for (std::size_t f = 0; f < 10; ++f) {
    const std::vector<Pose> poses = loadTejaniPoses(files[0][f]);
    const Pose world_T_camera = invert(supportFrame(std::vector<const Mesh*>(poses.size(), &cup), poses));
    float lowest = 1e9f;
    for (const Pose& pose : poses) {
      const float z = lowestZ(cup, compose(world_T_camera, pose));
      EXPECT_GE(z, -1e-4f);
      EXPECT_LT(z, 0.02f) << files[0][f] << ": every cup stands on the table";
      lowest = std::min(lowest, z);
    }
    EXPECT_NEAR(lowest, 0.f, 1e-4f);
    EXPECT_GT(world_T_camera.t.z(), 0.3f) << "the camera is above the table";
  }
}

TEST(SynthBadInput, ClearErrors) {
  const fs::path dir = freshDir("bad"), out = dir / "out";
  fs::create_directories(dir / "empty");
  auto run = [&](const SynthParams& p) {
    return test::inputErrorOf([&] { generateSyntheticDataset(test::context(), p, out.string(), false); });
  };
  SynthParams p = smallParams(1);
  p.meshes = {(dir / "missing.stl").string()};
  EXPECT_NE(run(p).find("missing.stl"), std::string::npos);
  p = smallParams(1);
  p.images = 0;
  EXPECT_NE(run(p).find("--images"), std::string::npos);
  p = smallParams(1);
  p.symmetric = {2};
  EXPECT_NE(run(p).find("--symmetric 2"), std::string::npos);
  p = smallParams(1);
  p.poses = (dir / "empty").string();
  EXPECT_NE(run(p).find("no pose files"), std::string::npos);
  p.poses = (dir / "nowhere").string();
  EXPECT_NE(run(p).find("nowhere"), std::string::npos);
  // A pose file whose count does not match its matrices.
  fs::create_directories(dir / "poses");
  std::ofstream(dir / "poses" / "poses1.txt") << "2\n1 0 0 0\n0 1 0 0\n0 0 1 0.8\n0 0 0 1\n";
  p.poses = (dir / "poses").string();
  p.images = 1;
  EXPECT_NE(run(p).find("poses1.txt"), std::string::npos);
  // Fewer pose files than images.
  std::ofstream(dir / "poses" / "poses1.txt", std::ios::trunc) << "1\n1 0 0 0\n0 1 0 0\n0 0 1 0.8\n0 0 0 1\n";
  p.images = 2;
  EXPECT_NE(run(p).find("needs 2 pose files"), std::string::npos);
  p.placement.layout = Layout::Bin;
  EXPECT_NE(run(p).find("bin"), std::string::npos);
  EXPECT_NE(test::inputErrorOf([] { parseMeshUnits("inches"); }).find("inches"), std::string::npos);
  // An output folder with something in it is never overwritten without being asked.
  fs::create_directories(out);
  std::ofstream(out / "keep.txt") << "mine";
  p = smallParams(1);
  p.images = 1;
  EXPECT_NE(run(p).find("--force"), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "models"));
  generateSyntheticDataset(test::context(), p, out.string(), true);
  EXPECT_TRUE(fs::exists(out / "keep.txt")) << "--force removes only what synth writes";
  EXPECT_TRUE(fs::exists(out / "test" / "000001" / "rgb" / "000000.png"));
  EXPECT_FALSE(fs::exists(dir / "empty" / "models")) << "nothing is written before the input is checked";
  fs::remove_all(dir);
}

TEST(SynthCloseRange, TheCameraDistanceIsAlongTheOpticalAxis) {
  CameraRange range;
  range.min_distance_m = 0.3f;
  range.max_distance_m = 0.45f;
  for (uint32_t seed = 0; seed < 50; ++seed) {
    std::mt19937 rng(seed);
    const Pose camera_T_world = randomCamera(range, rng);
    // The point looked at lies on the table (z = 0) at the drawn distance along the axis.
    const Pose world_T_camera = invert(camera_T_world);
    const Eigen::Vector3f axis = world_T_camera.R.col(2), position = world_T_camera.t;
    const float distance = -position.z() / axis.z();
    EXPECT_GE(distance, 0.3f - 1e-4f) << seed;
    EXPECT_LE(distance, 0.45f + 1e-4f) << seed;
  }
  // Without a distance range the height range holds, drawn as before.
  std::mt19937 a(7), b(7);
  CameraRange heights;
  const Pose p = randomCamera(heights, a), q = randomCamera(heights, b);
  EXPECT_TRUE(p.R.isApprox(q.R) && p.t.isApprox(q.t));
  const float height = invert(p).t.z();
  EXPECT_GE(height, heights.min_height_m - 1e-4f);
  EXPECT_LE(height, heights.max_height_m + 1e-4f);
}

TEST(SynthPlacement, ABinsOwnCameraSeesItsPartsWhereADefaultBankFindsThem) {
  // A user trains with the default --radii and makes bins with synth's defaults: every part in
  // those bins lies within the distances that bank finds (issue 52: with the table's tilted
  // camera over the bins, half of the cups left unpicked lay outside them).
  SynthParams params;
  params.meshes = {"unused"};
  params.images = 1;
  params.min_instances = params.max_instances = 8;
  params.placement.layout = Layout::Bin;
  EXPECT_EQ(cameraRangeOf(params).max_tilt_deg, binCellCamera().max_tilt_deg);
  EXPECT_EQ(cameraRangeOf(params).min_distance_m, binCellCamera().min_distance_m);
  Mesh cup = test::lShapeMesh();  // a part of a coffee cup's size, 12 cm across
  const float scale = 0.12f / cup.diameter;
  for (auto& v : cup.vertices) v *= scale;
  finishMesh(cup);
  const auto [near_m, far_m] = coveredDistances(ViewSamplingParams{}.radii);
  std::size_t parts = 0;
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    params.seed = seed;
    const SynthImage image = synthesizeImage(test::context(), params, {cup}, 0);
    for (const Pose& pose : image.poses) {
      EXPECT_GE(pose.t.norm(), near_m) << "seed " << seed;
      EXPECT_LE(pose.t.norm(), far_m) << "seed " << seed;
    }
    parts += image.poses.size();
  }
  EXPECT_GE(parts, 16u) << "the bins hold parts";
  // A table keeps the workcell camera; a range given keeps what it says.
  params.placement.layout = Layout::Table;
  EXPECT_EQ(cameraRangeOf(params).max_tilt_deg, CameraRange{}.max_tilt_deg);
  EXPECT_EQ(cameraRangeOf(params).max_distance_m, 0.f) << "drawn by height";
  params.placement.layout = Layout::Bin;
  params.camera_range = cameraAtDistances(0.3f, 0.45f);
  EXPECT_EQ(cameraRangeOf(params).max_distance_m, 0.45f);
  EXPECT_EQ(cameraRangeOf(params).max_tilt_deg, CameraRange{}.max_tilt_deg) << "as such datasets were made before";
}

TEST(SynthCloseRange, BinsFitSmallPartsAndLeaveLargeOnesAlone) {
  const Camera camera = tejaniCamera();
  PlacementParams bin;
  CameraRange close, far;
  close.min_distance_m = 0.3f;
  close.max_distance_m = 0.45f;
  // LM-O-sized parts from 0.6 m and farther: the default bin, unchanged.
  const PlacementParams same = fitBinToParts(bin, 0.15f, camera, far);
  EXPECT_EQ(same.bin_inner_m, bin.bin_inner_m);
  EXPECT_EQ(same.bin_wall_height_m, bin.bin_wall_height_m);
  // A 40 mm part from 0.3 m: the bin fits the view (the 640x480 view there is 0.34 x 0.25 m)
  // and its walls shrink with it.
  const PlacementParams small = fitBinToParts(bin, 0.04f, camera, close);
  EXPECT_LT(small.bin_inner_m.x(), 0.3f * 640.f / 571.f);
  EXPECT_LT(small.bin_inner_m.y(), 0.3f * 480.f / 571.f);
  EXPECT_GE(small.bin_inner_m.minCoeff(), 4 * 0.04f);
  EXPECT_LT(small.bin_wall_height_m, bin.bin_wall_height_m);
  EXPECT_GE(small.bin_wall_height_m, 0.04f);
}

TEST(SynthCloseRange, SmallPartsInABinSeenFromClose) {
  SynthParams params;
  params.meshes = {"unused"};
  params.images = 1;
  params.seed = 11;
  params.min_instances = params.max_instances = 6;
  params.placement.layout = Layout::Bin;
  params.camera_range = cameraAtDistances(0.3f, 0.45f);
  Mesh part = test::lShapeMesh();  // scaled to a 40 mm part
  const float scale = 0.04f / part.diameter;
  for (auto& v : part.vertices) v *= scale;
  finishMesh(part);
  const SynthImage image = synthesizeImage(test::context(), params, {part}, 0);
  ASSERT_GE(image.poses.size(), 4u) << "the parts fit in the fitted bin";
  int seen = 0;
  for (const Pose& pose : image.poses) {
    EXPECT_GT(pose.t.z(), 0.15f);
    EXPECT_LT(pose.t.z(), 0.5f);
    const Eigen::Vector2f px = image.camera.project(pose.t);
    seen += px.x() >= 0 && px.y() >= 0 && px.x() < 640 && px.y() < 480;
  }
  EXPECT_GE(seen, 4) << "most parts are in view";
  // Depth where the parts are: 15 to 50 cm.
  double lo = 1e9, hi = 0;
  cv::minMaxLoc(image.frame.depth_mm, &lo, &hi, nullptr, nullptr, image.frame.depth_mm > 0);
  EXPECT_GT(lo, 100);
  EXPECT_LT(hi, 800);
  params.camera_range->min_distance_m = 0.05f;
  EXPECT_THROW(validateSynthParams(params), InputError);
  params.camera_range->min_distance_m = 0.3f;
  params.placement.bin_inner_m = {0.f, 0.3f};
  EXPECT_THROW(validateSynthParams(params), InputError);
}

// ---- the close-range sensor (issue 51) ----------------------------------------------------

/// A plane 0.4 m away with a bar `bar_px` pixels wide standing 2 cm in front of it, across the image.
cv::Mat planeWithBar(int bar_px) {
  cv::Mat depth(60, 80, CV_32FC1, cv::Scalar(0.4f));
  depth(cv::Rect(40 - bar_px / 2, 0, bar_px, 60)).setTo(0.38f);
  return depth;
}

TEST(SynthCloseRange, AMatchingWindowLosesThinPartsAndKeepsWideOnes) {
  // A 9-pixel window: a bar 3 pixels wide (a screw's shank) merges into the plane behind it; one
  // 15 pixels wide keeps its depth in the middle, and the plane away from it is untouched.
  const cv::Mat thin = windowMedianDepth(planeWithBar(3), 9), wide = windowMedianDepth(planeWithBar(15), 9);
  EXPECT_FLOAT_EQ(thin.at<float>(30, 40), 0.4f) << "the thin bar is gone";
  EXPECT_FLOAT_EQ(wide.at<float>(30, 40), 0.38f) << "the wide bar stays";
  EXPECT_FLOAT_EQ(wide.at<float>(30, 10), 0.4f);
  const cv::Mat same = windowMedianDepth(planeWithBar(3), 1);
  EXPECT_FLOAT_EQ(same.at<float>(30, 40), 0.38f) << "no window, no change";
  // Mostly empty windows read nothing; a single hole in a plane is filled.
  cv::Mat holes(40, 40, CV_32FC1, cv::Scalar(0.f));
  holes(cv::Rect(0, 0, 10, 40)).setTo(0.5f);
  holes.at<float>(20, 3) = 0.f;
  const cv::Mat h = windowMedianDepth(holes, 5);
  EXPECT_FLOAT_EQ(h.at<float>(20, 3), 0.5f);
  EXPECT_FLOAT_EQ(h.at<float>(20, 30), 0.f);
}

TEST(SynthCloseRange, MetalShinesAndLosesDepthWhereItFacesTheCamera) {
  // A steel plate facing the camera beside a matte one: with the close-range sensor the metal
  // plate's depth is mostly lost (the projector's pattern mirrors straight back), the matte one
  // keeps nearly all; lit alike, the metal is brighter where it faces the lamp by the lens.
  const Mesh plate = cuboidMesh({0.06f, 0.06f, 0.005f}, {0.6f, 0.6f, 0.6f});
  std::vector<SceneObject> objects(2);
  objects[0].mesh = objects[1].mesh = &plate;
  objects[0].pose.t = Eigen::Vector3f(-0.05f, 0.f, 0.4f);
  objects[1].pose.t = Eigen::Vector3f(0.05f, 0.f, 0.4f);
  Camera camera;
  SceneRendering scene = renderScene(test::context(), objects, camera);
  markMetal(scene, 0, 1);
  ASSERT_GT(cv::countNonZero(scene.metal), 500);
  EXPECT_EQ(cv::countNonZero(scene.metal & (scene.instance == 2)), 0);
  Lighting light;
  light.direction = Eigen::Vector3f(0.3f, 0.3f, 1.f).normalized();
  applyLighting(scene, light);
  const LinemodFrame frame = sensorFrame(scene, closeRangeNoise(), 5);
  const cv::Mat metal = scene.instance == 1, matte = scene.instance == 2;
  const double metal_read = cv::countNonZero(metal & (frame.depth_mm > 0)) / static_cast<double>(cv::countNonZero(metal));
  const double matte_read = cv::countNonZero(matte & (frame.depth_mm > 0)) / static_cast<double>(cv::countNonZero(matte));
  EXPECT_LT(metal_read, 0.3);
  EXPECT_GT(matte_read, 0.8);
  EXPECT_GT(cv::mean(scene.bgr, metal)[1], cv::mean(scene.bgr, matte)[1] + 40.0);
  const cv::Vec3b c = scene.bgr.at<cv::Vec3b>(static_cast<int>(camera.cy), static_cast<int>(camera.cx - 0.05 * camera.fx / 0.4));
  EXPECT_TRUE(c[0] == c[1] && c[1] == c[2]) << "bare metal is grey";
}

TEST(SynthCloseRange, GreyCamerasAndScaledCopiesInADataset) {
  SynthParams p = smallParams(3);
  p.images = 2;
  p.placement.layout = Layout::Bin;
  p.scaled_copies = 2;
  p.greyscale = true;
  p.metal_parts = true;
  p.noise = closeRangeNoise();
  const fs::path dir = freshDir("copies");
  generateSyntheticDataset(test::context(), p, dir.string(), false);
  const BopDataset data = loadBopDataset(dir.string(), "test");
  ASSERT_EQ(data.images.size(), 2u);
  int copies = 0;
  for (const BopImage& im : data.images) {
    const std::vector<ScaledCopy> scaled = loadScaledCopies(im);
    copies += static_cast<int>(scaled.size());
    for (const ScaledCopy& c : scaled) {
      EXPECT_EQ(c.obj_id, 1);
      EXPECT_TRUE((c.scale >= 0.8f && c.scale <= 0.9f) || (c.scale >= 1.1f && c.scale <= 1.2f)) << c.scale;
      EXPECT_NEAR(c.pose.R.determinant(), 1.f, 1e-3f);
      for (const GroundTruthPose& g : im.gt) EXPECT_GT((g.t - c.pose.t).norm(), 0.005f) << "not in the ground truth";
    }
    const cv::Mat rgb = cv::imread(im.rgb_path, cv::IMREAD_COLOR);
    std::vector<cv::Mat> ch;
    cv::split(rgb, ch);
    EXPECT_EQ(cv::countNonZero(ch[0] != ch[1]) + cv::countNonZero(ch[1] != ch[2]), 0) << "a grey camera";
  }
  EXPECT_GE(copies, 2) << "copies find room in the bin";

  // A detection at a copy's centre counts as reporting it; one elsewhere, or under the score, does not.
  TemplateBank bank;
  bank.mesh = test::lShapeMesh();
  bank.diameter = bank.mesh.diameter;
  ScaledCopy copy{1, 1.15f, {}};
  copy.pose.t = Eigen::Vector3f(0.f, 0.f, 0.5f);
  Detection on_it;
  on_it.score = 0.7f;
  on_it.pose.t = copy.pose.t + 0.15f * bank.mesh.bboxCentre();  // the centres of part and copy agree
  Detection aside = on_it;
  aside.pose.t.x() += bank.diameter;
  Detection weak = on_it;
  weak.score = 0.3f;
  const std::map<int, int> index{{1, 0}};
  EXPECT_EQ(scaledCopiesReported({copy}, {on_it}, {bank}, index, 0.5f), 1);
  EXPECT_EQ(scaledCopiesReported({copy}, {aside, weak}, {bank}, index, 0.5f), 0);
  EXPECT_EQ(scaledCopiesReported({copy}, {on_it}, {bank}, {{2, 0}}, 0.5f), 0) << "another object's copy";

  p.scaled_copies = 51;
  EXPECT_THROW(validateSynthParams(p), InputError);
  p.scaled_copies = 1;
  p.noise.matching_window_px = 40;
  EXPECT_THROW(validateSynthParams(p), InputError);
}

}  // namespace
}  // namespace vkpose
