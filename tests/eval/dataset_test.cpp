// Dataset readers: the BOP files of the real LM-O frame, Tejani et al.'s pose files, and
// damaged copies of both, which must give an InputError naming the file and the field or line.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "test_support.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string lmoRoot() { return test::sharedData() + "/lmo_scene2_frame3"; }

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeText(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

json readJsonFile(const fs::path& p) { return json::parse(readText(p)); }

void writeJsonFile(const fs::path& p, const json& j) { writeText(p, j.dump(1)); }

void expectMentions(const std::string& message, std::initializer_list<std::string> parts) {
  for (const auto& p : parts)
    EXPECT_NE(message.find(p), std::string::npos) << "'" << p << "' missing from: " << message;
}

bool isRotation(const Eigen::Matrix3f& R, float tol) {
  return (R.transpose() * R - Eigen::Matrix3f::Identity()).cwiseAbs().maxCoeff() < tol &&
         std::abs(R.determinant() - 1.f) < tol;
}

TEST(Dataset, LmoFrameReadsAsBop) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const BopDataset ds = loadBopDataset(lmoRoot());
  ASSERT_EQ(ds.images.size(), 1u);
  const BopImage& im = ds.images[0];
  EXPECT_EQ(im.scene_id, 2);
  EXPECT_EQ(im.image_id, 3);
  EXPECT_TRUE(fs::exists(im.rgb_path));
  EXPECT_TRUE(fs::exists(im.depth_path));
  EXPECT_EQ(fs::path(im.rgb_path).filename(), "000003.png");

  ASSERT_EQ(im.gt.size(), 8u);
  std::vector<int> ids;
  for (const auto& g : im.gt) {
    ids.push_back(g.obj_id);
    // LM-O's annotations are orthonormal to 3e-4, the drill's (obj 8) only to 2e-3.
    EXPECT_TRUE(isRotation(g.R, 3e-3f)) << "obj " << g.obj_id;
    EXPECT_GT(g.t.z(), 0.8f) << "metres";
    EXPECT_LT(g.t.z(), 1.3f) << "metres";
  }
  EXPECT_EQ(ids, (std::vector<int>{1, 5, 6, 8, 9, 10, 11, 12}));

  // The ape, as in scene_gt.json: R row-major, t converted from millimetres.
  const GroundTruthPose& ape = im.gt[0];
  EXPECT_FLOAT_EQ(ape.R(0, 1), 0.47867615f);
  EXPECT_FLOAT_EQ(ape.R(1, 0), 0.3746311f);
  EXPECT_FLOAT_EQ(ape.R(2, 2), -0.84552592f);
  EXPECT_NEAR(ape.t.x(), 0.16168945982, 1e-7);
  EXPECT_NEAR(ape.t.y(), -0.11374032768, 1e-7);
  EXPECT_NEAR(ape.t.z(), 1.11283112737, 1e-7);
  // scene_gt_info.json: the ape is 20% visible.
  ASSERT_EQ(im.gt_info.size(), 8u);
  EXPECT_NEAR(ape.visib_fract, 0.19964507542, 1e-7);
  EXPECT_EQ(im.gt_info[0].bbox_visib, cv::Rect(401, 164, 20, 33));
  EXPECT_EQ(im.gt_info[0].px_count_visib, 225);
  EXPECT_EQ(im.gt_info[0].px_count_all, 1127);

  EXPECT_DOUBLE_EQ(im.camera.fx, 572.4114);
  EXPECT_DOUBLE_EQ(im.camera.fy, 573.57043);
  EXPECT_DOUBLE_EQ(im.camera.cx, 325.2611);
  EXPECT_DOUBLE_EQ(im.camera.cy, 242.04899);
  EXPECT_EQ(im.camera.width, 640);
  EXPECT_EQ(im.camera.height, 480);
  EXPECT_DOUBLE_EQ(im.camera.depth_scale, 1.0);
}

TEST(Dataset, LmoModelsInfoInMetresWithSymmetries) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const BopDataset ds = loadBopDataset(lmoRoot());
  const json info = readJsonFile(lmoRoot() + "/models/models_info.json");
  ASSERT_EQ(ds.models.size(), info.size());
  ASSERT_EQ(ds.models.size(), 8u);
  for (const auto& [key, j] : info.items()) {
    const int obj_id = std::stoi(key);
    ASSERT_TRUE(ds.models.count(obj_id)) << obj_id;
    const ModelInfo& m = ds.models.at(obj_id);
    EXPECT_EQ(m.obj_id, obj_id);
    EXPECT_FLOAT_EQ(m.diameter, static_cast<float>(j["diameter"].get<double>() * 0.001)) << obj_id;
    EXPECT_FLOAT_EQ(m.bbox_size.x(), static_cast<float>(j["size_x"].get<double>() * 0.001)) << obj_id;
    // Eggbox (10) and glue (11) have discrete symmetries in BOP's file; the others none.
    EXPECT_EQ(m.symmetric, obj_id == 10 || obj_id == 11) << obj_id;
  }
  EXPECT_FLOAT_EQ(ds.models.at(1).diameter, 0.102099f);

  // The files hold what the paths name; the decimated evaluation models match the diameters.
  EXPECT_EQ(fs::path(ds.modelPath(1)), fs::path(lmoRoot()) / "models" / "obj_000001.ply");
  EXPECT_EQ(fs::path(ds.evalModelPath(1)), fs::path(lmoRoot()) / "models_eval" / "obj_000001.ply");
  for (const auto& [obj_id, m] : ds.models) {
    EXPECT_TRUE(fs::exists(ds.modelPath(obj_id)));
    const Mesh mesh = loadMesh(ds.evalModelPath(obj_id), MeshUnits::Millimetres);
    EXPECT_NEAR(mesh.diameter, m.diameter, 0.02f * m.diameter) << obj_id;
  }
}

TEST(Dataset, IcbinIsNotABopDataset) {
  VKPOSE_REQUIRE_SHARED_DATA();
  // IC-BIN here is frames and a camera file only: the reader says what is missing.
  expectMentions(test::inputErrorOf([] { loadBopDataset(test::sharedData() + "/icbin"); }), {"models_info.json"});
  const Camera c = loadCamera(test::sharedData() + "/icbin/camera.json");
  EXPECT_DOUBLE_EQ(c.fx, 550.0);
  EXPECT_DOUBLE_EQ(c.cy, 244.0);
}

/// A copy of the LM-O layout (JSON files, stand-in image files) that a test may damage.
class DatasetBrokenBop : public ::testing::Test {
 protected:
  fs::path root, scene;
  void SetUp() override {
    VKPOSE_REQUIRE_SHARED_DATA();
    root = fs::temp_directory_path() / ("vkpose_broken_bop_" + std::to_string(::getpid()));
    fs::remove_all(root);
    scene = root / "test" / "000002";
    fs::create_directories(root / "models");
    fs::create_directories(scene / "rgb");
    fs::create_directories(scene / "depth");
    const fs::path src(lmoRoot());
    fs::copy_file(src / "camera.json", root / "camera.json");
    fs::copy_file(src / "models" / "models_info.json", root / "models" / "models_info.json");
    for (const char* f : {"scene_gt.json", "scene_camera.json", "scene_gt_info.json"})
      fs::copy_file(src / "test" / "000002" / f, scene / f);
    writeText(scene / "rgb" / "000003.png", "stand-in");
    writeText(scene / "depth" / "000003.png", "stand-in");
  }
  void TearDown() override {
    if (!root.empty()) fs::remove_all(root);
  }
  void editJson(const fs::path& p, const std::function<void(json&)>& edit) {
    json j = readJsonFile(p);
    edit(j);
    writeJsonFile(p, j);
  }
  std::string loadError() {
    return test::inputErrorOf([&] { loadBopDataset(root.string()); });
  }
};

TEST_F(DatasetBrokenBop, TheIntactCopyLoads) { EXPECT_EQ(loadBopDataset(root.string()).images.at(0).gt.size(), 8u); }

TEST_F(DatasetBrokenBop, MissingFiles) {
  fs::remove(scene / "scene_gt_info.json");  // optional: visibility 1 without it
  const BopDataset ds = loadBopDataset(root.string());
  EXPECT_TRUE(ds.images.at(0).gt_info.empty());
  EXPECT_FLOAT_EQ(ds.images.at(0).gt[0].visib_fract, 1.f);

  fs::remove(scene / "rgb" / "000003.png");
  expectMentions(loadError(), {"rgb", "000003.png or 000003.jpg"});
  writeText(scene / "rgb" / "000003.jpg", "stand-in");
  EXPECT_EQ(fs::path(loadBopDataset(root.string()).images.at(0).rgb_path).extension(), ".jpg");
  fs::remove(scene / "depth" / "000003.png");
  expectMentions(loadError(), {"depth", "000003.png"});
  writeText(scene / "depth" / "000003.png", "stand-in");

  expectMentions(test::inputErrorOf([&] { loadBopDataset(root.string(), "val"); }), {"val", "split"});
  fs::remove(scene / "scene_camera.json");
  expectMentions(loadError(), {"scene_camera.json"});
  fs::remove(scene / "scene_gt.json");
  expectMentions(loadError(), {"scene_gt.json"});
  fs::remove(root / "models" / "models_info.json");
  expectMentions(loadError(), {"models_info.json"});
  fs::remove(root / "camera.json");
  expectMentions(loadError(), {"camera.json"});
}

TEST_F(DatasetBrokenBop, MalformedJson) {
  for (const char* text : {"", "{ \"3\": [", "[1, 2]", "{\"3\": 5}", "{\"three\": []}", "{\"3\": [7]}"}) {
    writeText(scene / "scene_gt.json", text);
    expectMentions(loadError(), {"scene_gt.json"});
  }
  writeText(scene / "scene_gt.json", "{\"three\": []}");
  expectMentions(loadError(), {"'three'"});
  writeText(root / "models" / "models_info.json", "{\"1\": {\"diameter\": 1,}}");
  expectMentions(loadError(), {"models_info.json", "JSON"});
}

TEST_F(DatasetBrokenBop, GroundTruthFields) {
  const fs::path gt = scene / "scene_gt.json";
  const std::string original = readText(gt);
  const auto check = [&](const std::function<void(json&)>& edit, std::initializer_list<std::string> parts) {
    writeText(gt, original);
    editJson(gt, edit);
    expectMentions(loadError(), parts);
  };
  check([](json& j) { j["3"][2]["cam_R_m2c"].erase(8); },
        {"scene_gt.json", "image 3", "instance 2", "cam_R_m2c", "9 numbers, found 8 values"});
  check([](json& j) { j["3"][0]["obj_id"] = "one"; }, {"instance 0", "obj_id"});
  check([](json& j) { j["3"][0]["obj_id"] = 1.5; }, {"obj_id"});
  check([](json& j) { j["3"][4].erase("cam_t_m2c"); }, {"instance 4", "cam_t_m2c"});
  check([](json& j) { j["3"][1]["cam_t_m2c"][1] = "far"; }, {"instance 1", "cam_t_m2c"});
  check([](json& j) { j["3"][1]["cam_R_m2c"][0] = 2.0; }, {"instance 1", "cam_R_m2c", "rotation"});
  check([](json& j) { j["3"][7]["obj_id"] = 99; }, {"instance 7", "obj_id 99", "models_info.json"});
  check([](json& j) { j["3"][3] = "pose"; }, {"instance 3", "object"});
}

TEST_F(DatasetBrokenBop, CameraInfoAndModelFields) {
  editJson(scene / "scene_camera.json", [](json& j) {
    j["4"] = j["3"];
    j.erase("3");
  });
  expectMentions(loadError(), {"scene_camera.json", "image 3"});
  editJson(scene / "scene_camera.json", [](json& j) {
    j["3"] = j["4"];
    j["3"]["cam_K"].erase(0);
  });
  expectMentions(loadError(), {"scene_camera.json", "cam_K"});
  editJson(scene / "scene_camera.json", [](json& j) {
    j["3"]["cam_K"] = json::array({0, 0, 325, 0, 573, 242, 0, 0, 1});
  });
  expectMentions(loadError(), {"scene_camera.json", "focal"});
  editJson(scene / "scene_camera.json", [](json& j) { j["3"]["cam_K"] = j["4"]["cam_K"]; });

  const std::string info = readText(scene / "scene_gt_info.json");
  editJson(scene / "scene_gt_info.json", [](json& j) { j["3"][5]["visib_fract"] = "x"; });
  expectMentions(loadError(), {"scene_gt_info.json", "instance 5", "visib_fract"});
  writeText(scene / "scene_gt_info.json", info);
  editJson(scene / "scene_gt_info.json", [](json& j) { j["3"].erase(7); });
  expectMentions(loadError(), {"scene_gt_info.json", "7 entries", "8"});
  writeText(scene / "scene_gt_info.json", info);

  const fs::path models = root / "models" / "models_info.json";
  const std::string original = readText(models);
  const auto check = [&](const std::function<void(json&)>& edit, std::initializer_list<std::string> parts) {
    writeText(models, original);
    editJson(models, edit);
    expectMentions(loadError(), parts);
  };
  check([](json& j) { j["5"].erase("diameter"); }, {"models_info.json", "object 5", "diameter"});
  check([](json& j) { j["5"]["diameter"] = -3; }, {"object 5", "diameter"});
  check([](json& j) { j["5"]["diameter"] = "big"; }, {"object 5", "diameter"});
  check([](json& j) { j["10"]["symmetries_discrete"] = 3; }, {"object 10", "symmetries_discrete"});
  check([](json& j) { j["x5"] = j["5"]; }, {"'x5'", "obj_id"});
}

// ---------------------------------------------------------------------------------------
// Tejani et al. pose files

std::string tejaniRoot() { return test::sharedData() + "/tejani_poses"; }

TEST(Dataset, TejaniRealPoseFiles) {
  VKPOSE_REQUIRE_SHARED_DATA();
  int files = 0, poses = 0;
  std::vector<std::string> refused;
  for (const auto& object : fs::directory_iterator(tejaniRoot())) {
    for (const auto& file : fs::directory_iterator(object.path())) {
      ++files;
      const std::string path = file.path().string();
      int stated = -1;
      std::ifstream(path) >> stated;
      try {
        const auto loaded = loadTejaniPoses(path);
        EXPECT_EQ(static_cast<int>(loaded.size()), stated) << path;
        EXPECT_GE(loaded.size(), 1u) << path;
        for (const auto& p : loaded) {
          EXPECT_TRUE(isRotation(p.R, 1e-5f)) << path;
          EXPECT_GT(p.t.z(), 0.3f) << path << ": metres, in front of the camera";
          EXPECT_LT(p.t.z(), 2.0f) << path;
          EXPECT_LT(p.t.head<2>().norm(), 1.0f) << path;
        }
        poses += static_cast<int>(loaded.size());
      } catch (const InputError& e) {
        refused.push_back(e.what());
      }
    }
  }
  EXPECT_EQ(files, 793);
  EXPECT_EQ(poses, 2015);  // the stated counts of the 792 good files
  // One file states 2 poses and holds 1: it is refused with its name and lines.
  ASSERT_EQ(refused.size(), 1u);
  expectMentions(refused[0],
                 {"joystick", "poses1563.txt", "line 1 says 2 poses", "ends at line 5", "1 complete matrix"});
}

class DatasetBrokenTejani : public ::testing::Test {
 protected:
  fs::path dir;
  std::vector<std::string> lines;  ///< of coffee_cup/poses1010.txt: 3 poses, 13 lines
  void SetUp() override {
    VKPOSE_REQUIRE_SHARED_DATA();
    dir = fs::temp_directory_path() / ("vkpose_broken_tejani_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ifstream in(tejaniRoot() + "/coffee_cup/poses1010.txt");
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    ASSERT_EQ(lines.size(), 13u);
    ASSERT_EQ(lines[0], "3");
  }
  void TearDown() override {
    if (!dir.empty()) fs::remove_all(dir);
  }
  /// Writes the lines (1-based line `n` replaced by `text` for each edit) and reads them back.
  std::string errorWith(std::vector<std::pair<int, std::string>> edits, std::size_t keep_lines = 13) {
    auto copy = lines;
    for (const auto& [n, text] : edits) copy[static_cast<std::size_t>(n - 1)] = text;
    copy.resize(keep_lines);
    const fs::path p = dir / "poses1010.txt";
    std::ofstream out(p);
    for (const auto& l : copy) out << l << '\n';
    out.close();
    return test::inputErrorOf([&] { loadTejaniPoses(p.string()); });
  }
};

TEST_F(DatasetBrokenTejani, TheIntactCopyLoads) {
  const auto poses = loadTejaniPoses(tejaniRoot() + "/coffee_cup/poses1010.txt");
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_FLOAT_EQ(poses[0].R(0, 1), -0.405976f);
  EXPECT_FLOAT_EQ(poses[0].t.x(), 0.215795f);
  EXPECT_FLOAT_EQ(poses[2].t.z(), 0.635644f);
}

TEST_F(DatasetBrokenTejani, CountTooLarge) {
  expectMentions(errorWith({{1, "4"}}),
                 {"poses1010.txt", "line 1 says 4 poses", "ends at line 13", "3 complete matrices"});
  expectMentions(errorWith({}, 11),
                 {"line 1 says 3 poses", "ends at line 11", "2 complete matrices and 8 more numbers"});
}

TEST_F(DatasetBrokenTejani, CountTooSmall) {
  expectMentions(errorWith({{1, "2"}}), {"poses1010.txt", "line 1 says 2 poses", "from line 10"});
  expectMentions(errorWith({{1, "0"}}), {"line 1 says 0 poses", "from line 2"});
}

TEST_F(DatasetBrokenTejani, GarbageNaNAndNonRotations) {
  expectMentions(errorWith({{7, "  0.1 abc 0.2 0.3"}}), {"poses1010.txt", "line 7", "'abc' is not a number"});
  expectMentions(errorWith({{3, "nan 0 0 0"}}), {"line 3", "not a finite number"});
  expectMentions(errorWith({{1, "three"}}), {"line 1", "'three'"});
  expectMentions(errorWith({{1, "-1"}}), {"line 1", "'-1'"});
  expectMentions(errorWith({{7, "1.7 0 0 0.1"}}), {"poses1010.txt", "lines 6-9 (pose 1)", "not a rotation"});
  // A reflection is orthonormal but not a rotation.
  expectMentions(errorWith({{2, "-1 0 0 0"}, {3, "0 1 0 0"}, {4, "0 0 1 1"}}), {"lines 2-5 (pose 0)", "det R = -1"});
  expectMentions(errorWith({{13, "0 0 0.5 1"}}), {"lines 10-13 (pose 2)", "last row"});
  expectMentions(errorWith({}, 0), {"poses1010.txt", "empty"});
  expectMentions(test::inputErrorOf([&] { loadTejaniPoses((dir / "absent.txt").string()); }), {"absent.txt", "cannot open"});
}

}  // namespace
}  // namespace vkpose
