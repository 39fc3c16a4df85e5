// Mesh loading, exact diameters and view sampling.
#include <algorithm>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include <Eigen/LU>

#include "mesh_support.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

const std::string kAssimpModels = "/usr/share/assimp/models";

TEST(ExactDiameter, EqualsBruteForceOnRandomClouds) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.f, 1.f);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<Eigen::Vector3f> pts;
    for (int i = 0; i < 400; ++i) pts.emplace_back(g(rng), 0.3f * g(rng), 2.f * g(rng));
    float brute = 0.f;
    for (std::size_t i = 0; i < pts.size(); ++i)
      for (std::size_t j = i + 1; j < pts.size(); ++j) brute = std::max(brute, (pts[i] - pts[j]).norm());
    EXPECT_FLOAT_EQ(exactDiameter(pts), brute);
  }
}

TEST(MeshLoading, CoffeeCupInMetres) {
  VKPOSE_REQUIRE_SHARED_DATA();
  MeshLoadReport report;
  const Mesh cup = loadMesh(test::sharedData() + "/meshes/coffee_cup.stl", MeshUnits::Auto, &report);
  EXPECT_EQ(cup.name, "coffee_cup");
  EXPECT_TRUE(report.inferred);
  EXPECT_EQ(report.units, MeshUnits::Metres);
  EXPECT_NEAR(cup.diameter, 0.137f, 0.002f);  // shared/data/README.md: about 0.137 m
  EXPECT_GT(cup.faces.size(), 30000u);
  EXPECT_TRUE(cup.normals.empty()) << "STL facet normals are dropped: the renderer uses face normals";
  // Identical vertices are joined: a closed surface has about half as many vertices as faces.
  EXPECT_LT(cup.vertices.size(), cup.faces.size());
  EXPECT_LT(cup.bboxCentre().norm(), 0.005f);  // origin at the bounding-box centre
  EXPECT_NE(cup.file_hash, 0u);
}

TEST(MeshLoading, LmoPlyInMillimetresWithColoursAndNormals) {
  VKPOSE_REQUIRE_SHARED_DATA();
  MeshLoadReport report;
  const Mesh ape = loadMesh(test::sharedData() + "/lmo_scene2_frame3/models/obj_000001.ply", MeshUnits::Auto, &report);
  EXPECT_EQ(report.units, MeshUnits::Millimetres);
  EXPECT_NEAR(ape.diameter, 0.102099f, 1e-5f);  // models_info.json: 102.099 mm
  EXPECT_EQ(ape.colours.size(), ape.vertices.size());
  EXPECT_EQ(ape.normals.size(), ape.vertices.size());
  EXPECT_NEAR(ape.bbox_min.x(), -0.0379343f, 1e-6f);
  const Mesh explicit_mm = loadMesh(test::sharedData() + "/lmo_scene2_frame3/models/obj_000001.ply", MeshUnits::Millimetres);
  EXPECT_FLOAT_EQ(explicit_mm.diameter, ape.diameter);
}

TEST(MeshLoading, AsciiStlBinaryStlPlyAndObjFromAssimpTestModels) {
  if (!std::ifstream(kAssimpModels + "/STL/Spider_ascii.stl")) GTEST_SKIP() << "assimp-testmodels is not installed";
  const Mesh ascii = loadMesh(kAssimpModels + "/STL/Spider_ascii.stl", MeshUnits::Metres);
  const Mesh binary = loadMesh(kAssimpModels + "/STL/Spider_binary.stl", MeshUnits::Metres);
  EXPECT_EQ(ascii.faces.size(), binary.faces.size());
  EXPECT_NEAR(ascii.diameter, binary.diameter, 1e-4f * binary.diameter);
  const Mesh ply = loadMesh(kAssimpModels + "/PLY/cube.ply", MeshUnits::Metres);
  EXPECT_EQ(ply.faces.size(), 12u);
  EXPECT_NEAR(ply.diameter, std::sqrt(3.f), 1e-4f);  // the unit cube's space diagonal
  const Mesh obj = loadMesh(kAssimpModels + "/OBJ/box.obj", MeshUnits::Metres);
  EXPECT_EQ(obj.faces.size(), 12u);
  const Mesh coloured = loadMesh(kAssimpModels + "/OBJ/cube_with_vertexcolors.obj", MeshUnits::Metres);
  EXPECT_EQ(coloured.colours.size(), coloured.vertices.size());
}

TEST(MeshLoading, BadFilesGiveClearErrors) {
  auto expectError = [](const std::string& path, const std::string& words) {
    try {
      loadMesh(path, MeshUnits::Metres);
      ADD_FAILURE() << path << ": expected an InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expectError("/nonexistent/mesh.stl", "no such mesh file");
  const std::string dir = ::testing::TempDir();
  std::ofstream(dir + "/empty.stl").close();
  expectError(dir + "/empty.stl", "empty");
  std::ofstream(dir + "/garbage.ply") << "ply\nformat nonsense\n\x01\x02\x03";
  expectError(dir + "/garbage.ply", "garbage.ply");
  std::ofstream(dir + "/nofaces.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expectError(dir + "/nofaces.obj", "nofaces.obj");
  std::ofstream(dir + "/nan.obj") << "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n";
  expectError(dir + "/nan.obj", "nan.obj");
  if (std::ifstream(kAssimpModels + "/OBJ/testpoints.obj")) expectError(kAssimpModels + "/OBJ/testpoints.obj", "testpoints.obj");
  EXPECT_THROW(parseMeshUnits("cm"), InputError);
}

// assimp 5.2 hangs or crashes on these instead of failing (fuzz_mesh found several): loadMesh reads
// the PLY header first and refuses them at once. The same headers with their data load.
TEST(MeshLoading, PlyHeadersThatCannotHoldTheirDataAreRefused) {
  auto error = [](const std::string& name, const std::string& text) {
    const std::string path = ::testing::TempDir() + "/" + name;
    std::ofstream(path, std::ios::binary) << text;
    try {
      loadMesh(path, MeshUnits::Metres);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string vertices = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string ascii = "ply\nformat ascii 1.0\n", binary = "ply\nformat binary_little_endian 1.0\n";
  EXPECT_EQ(error("tri.ply", ascii + vertices + faces + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "no error");
  EXPECT_NE(error("no_end.ply", ascii + vertices + faces + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").find("no end_header line"),
            std::string::npos);
  EXPECT_NE(error("bad_end.ply", ascii + vertices + "end_headerx\n0 0 0\n").find("no end_header line"), std::string::npos);
  EXPECT_NE(error("magic_only.PLY", "PLY\n").find("no end_header line"), std::string::npos) << "assimp's magic is any case";
  // 50 million vertices declared over 6 bytes: assimp allocated 600 MB and read for half a minute.
  const std::string many = "element vertex 50000000\nproperty float x\nproperty float y\nproperty float z\n";
  EXPECT_NE(error("many.ply", ascii + many + "end_header\n0 0 0\n").find("declares 50000000 'vertex' elements"),
            std::string::npos);
  EXPECT_NE(error("many_bin.ply", binary + many + "end_header\n0 0 0\n").find("declares 50000000 'vertex'"),
            std::string::npos);
  const std::string many_faces = "element face 50000000\nproperty list uchar int vertex_indices\n";
  EXPECT_NE(error("many_faces.ply", ascii + vertices + many_faces + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
                .find("declares 50000000 'face'"),
            std::string::npos);
  EXPECT_NE(error("huge.ply", ascii + "element vertex 99999999999999999999999\nproperty float x\nend_header\n0\n")
                .find("not 'element NAME COUNT'"),
            std::string::npos);
  // ASCII: each line one instance, as assimp reads it.
  EXPECT_NE(error("short_line.ply", ascii + vertices + faces + "end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n")
                .find("line 13 ('4 0 1 2') is not one 'face' element"),
            std::string::npos);
  EXPECT_NE(error("split.ply", ascii + vertices + faces + "end_header\n0 0\n0\n1 0 0\n0 1 0\n3 0 1 2\n")
                .find("is not one 'vertex' element"),
            std::string::npos);
  // Binary: 3 floats a vertex, so 35 bytes cannot hold 3 vertices and a 13-byte face.
  std::string data(3 * 12 + 13, '\0');
  EXPECT_NE(error("short_bin.ply", binary + vertices + faces + "end_header\n" + data.substr(0, 35)).find("declares"),
            std::string::npos);
  // assimp's own test model pond.0.ply is 69 bytes short of its 70,051 declared vertices.
  if (std::ifstream(kAssimpModels + "/PLY/pond.0.ply")) {
    EXPECT_THROW(loadMesh(kAssimpModels + "/PLY/pond.0.ply", MeshUnits::Metres), InputError);
  }
}

TEST(ViewSampling, PaperDefaultsGive14040Views) {
  const ViewSamplingParams params;
  const auto views = sampleViews(params, Eigen::Vector3f(0.01f, -0.02f, 0.03f));
  EXPECT_EQ(views.size(), 216u * 5u * 13u);
  for (const auto& v : views) {
    EXPECT_NEAR((v.R * v.R.transpose() - Eigen::Matrix3f::Identity()).norm(), 0.f, 1e-5f);
    EXPECT_NEAR(v.R.determinant(), 1.f, 1e-5f);
    // The object's centre is on the optical axis at the training distance.
    const Eigen::Vector3f c = v.R * Eigen::Vector3f(0.01f, -0.02f, 0.03f) + v.t;
    EXPECT_NEAR(c.x(), 0.f, 1e-5f);
    EXPECT_NEAR(c.y(), 0.f, 1e-5f);
    EXPECT_NEAR(c.z(), v.distance, 1e-5f);
  }
  EXPECT_FLOAT_EQ(views.front().distance, 0.6f);
  EXPECT_FLOAT_EQ(views.front().inplane_deg, -60.f);
  EXPECT_NEAR(views.back().distance, 1.0f, 1e-5f);
  EXPECT_FLOAT_EQ(views.back().inplane_deg, 60.f);
}

TEST(ViewSampling, UpperHemisphereKeepsCamerasAboveAndSpreadsThem) {
  const auto dirs = sphereViewpoints(216, false);
  float min_sep = 10.f;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    EXPECT_GT(dirs[i].z(), 0.f);
    EXPECT_NEAR(dirs[i].norm(), 1.f, 1e-5f);
    for (std::size_t j = i + 1; j < dirs.size(); ++j) min_sep = std::min(min_sep, (dirs[i] - dirs[j]).norm());
  }
  // 216 points on a hemisphere (area 2 pi): mean spacing about sqrt(2 pi / 216) = 0.17.
  EXPECT_GT(min_sep, 0.08f);
  const auto full = sphereViewpoints(100, true);
  int below = 0;
  for (const auto& d : full) below += d.z() < 0.f;
  EXPECT_EQ(below, 50);
}

TEST(ViewSampling, ImageUpIsTheObjectsUpAndInplaneRotatesAboutTheAxis) {
  const TrainingView side = lookAtView({1.f, 0.f, 0.f}, Eigen::Vector3f::Zero(), 0.8f, 0.f);
  // Object +z points to image -y (up) for a camera level with the object.
  const Eigen::Vector3f up_cam = side.R * Eigen::Vector3f::UnitZ();
  EXPECT_NEAR(up_cam.y(), -1.f, 1e-5f);
  const TrainingView turned = lookAtView({1.f, 0.f, 0.f}, Eigen::Vector3f::Zero(), 0.8f, 30.f);
  const Eigen::Vector3f up_turned = turned.R * Eigen::Vector3f::UnitZ();
  EXPECT_NEAR(std::atan2(up_turned.x(), -up_turned.y()), 30.f * 3.14159265f / 180.f, 1e-4f);
  const TrainingView pole = lookAtView({0.f, 0.f, 1.f}, Eigen::Vector3f::Zero(), 0.8f, 0.f);
  EXPECT_TRUE(pole.R.allFinite());
}

// Near a hemisphere's pole the image's up hangs on where the camera stands, not on its roll:
// a part lying flat under a camera looking down shows at any turn. The whole turn near the
// pole (full_turn_within_deg) gives every such view a template close by; the paper's -60 to 60
// leaves turns that no template comes near.
TEST(ViewSampling, TheWholeTurnNearThePoleCoversAPartSeenFromAboveAtAnyTurn) {
  const auto whole = fullTurnInPlane({-60.f, 60.f, 10.f});
  ASSERT_EQ(whole.size(), 36u);
  EXPECT_FLOAT_EQ(whole.front(), -180.f);
  EXPECT_FLOAT_EQ(whole.back(), 170.f);
  EXPECT_EQ(fullTurnInPlane({-180.f, 170.f, 10.f}), (SteppedRange{-180.f, 170.f, 10.f}.values()));  // the range's own
  const auto sevens = fullTurnInPlane({0.f, 10.f, 7.f});  // -175 to 182 on the grid of 0 and 7
  ASSERT_EQ(sevens.size(), 52u);
  EXPECT_NEAR(sevens.front(), -175.f, 1e-3f);
  EXPECT_TRUE(std::any_of(sevens.begin(), sevens.end(), [](float a) { return std::abs(a - 7.f) < 1e-3f; }));
  EXPECT_EQ(fullTurnInPlane({0.f, 0.f, 1.f}).size(), 36u);  // one angle: every 10 degrees

  ViewSamplingParams params;
  params.radii = {0.4f, 0.4f, 1.f};
  params.full_turn_within_deg = 40.f;
  const auto views = sampleViews(params, Eigen::Vector3f::Zero());
  std::map<int, std::set<float>> turns;
  for (const TrainingView& v : views) turns[v.viewpoint].insert(v.inplane_deg);
  const auto dirs = sphereViewpoints(params.viewpoints, false);
  for (const auto& [viewpoint, angles] : turns) {
    const bool near_pole = dirs[static_cast<std::size_t>(viewpoint)].z() >= std::cos(40.f * 3.14159265f / 180.f);
    EXPECT_EQ(angles.size(), near_pole ? 36u : 13u) << viewpoint;
  }
  ViewSamplingParams paper = params;
  paper.full_turn_within_deg = 0.f;
  const auto paper_views = sampleViews(paper, Eigen::Vector3f::Zero());
  EXPECT_EQ(paper_views.size(), 216u * 13u);
  EXPECT_GT(views.size(), paper_views.size());

  // Cameras within 30 degrees of the top at every turn: the nearest view's rotation.
  const auto nearest = [](const std::vector<TrainingView>& vs, const Eigen::Matrix3f& R) {
    float best = 180.f;
    for (const TrainingView& v : vs)
      best = std::min(best, std::acos(std::clamp(((v.R.transpose() * R).trace() - 1.f) / 2.f, -1.f, 1.f)) * 180.f /
                                3.14159265f);
    return best;
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> polar(0.f, 30.f), azimuth(0.f, 360.f), turn(-180.f, 180.f);
  float worst_whole = 0.f, worst_paper = 0.f;
  for (int i = 0; i < 60; ++i) {
    const float p = polar(rng) * 3.14159265f / 180.f, a = azimuth(rng) * 3.14159265f / 180.f;
    const Eigen::Vector3f dir(std::sin(p) * std::cos(a), std::sin(p) * std::sin(a), std::cos(p));
    const Eigen::Matrix3f R = lookAtView(dir, Eigen::Vector3f::Zero(), 0.4f, turn(rng)).R;
    worst_whole = std::max(worst_whole, nearest(views, R));
    worst_paper = std::max(worst_paper, nearest(paper_views, R));
  }
  EXPECT_LT(worst_whole, 10.f);  // the lattice's spacing (about 10 degrees) and the 10-degree step
  EXPECT_GT(worst_paper, 25.f);  // 34 degrees with this seed

  params.full_turn_within_deg = 91.f;
  EXPECT_THROW(validateViewSampling(params), InputError);
  params.full_turn_within_deg = -1.f;
  EXPECT_THROW(validateViewSampling(params), InputError);
  params.full_turn_within_deg = 40.f;
  params.inplane_deg = {0.f, 0.05f, 0.01f};
  EXPECT_THROW(validateViewSampling(params), InputError);
}

// dropTurnsShownAlready keeps the whole turn's views that no view of the range shows (they
// fill the gaps) and drops the rest. A near-symmetry drops more: a hex nut's 60 degrees about
// its up axis turns the views nearest the pole into one another (farther from it, a turn about
// the up axis moves the camera round the axis rather than turning the image).
TEST(ViewSampling, TurnsShownAlreadyAreDroppedAndTheGapsStayFilled) {
  ViewSamplingParams params;
  params.radii = {0.4f, 0.5f, 0.1f};
  params.full_turn_within_deg = 40.f;
  const auto views = sampleViews(params, Eigen::Vector3f::Zero());
  const auto in_range = [](const TrainingView& v) { return v.inplane_deg >= -60.f && v.inplane_deg <= 60.f; };
  const auto angle = [](const Eigen::Matrix3f& a, const Eigen::Matrix3f& b) {
    return std::acos(std::clamp(((a.transpose() * b).trace() - 1.f) / 2.f, -1.f, 1.f)) * 180.f / 3.14159265f;
  };
  std::vector<Eigen::Matrix3f> range;
  for (const TrainingView& v : views)
    if (in_range(v)) range.push_back(v.R);
  const auto nearest_in_range = [&](const Eigen::Matrix3f& R) {
    float best = 180.f;
    for (const Eigen::Matrix3f& b : range) best = std::min(best, angle(b, R));
    return best;
  };

  const auto kept = dropTurnsShownAlready(views, params.inplane_deg, {}, 10.f);
  std::size_t extras = 0, kept_extras = 0;
  for (const TrainingView& v : views) extras += in_range(v) ? 0 : 1;
  for (const TrainingView& v : kept) {
    if (in_range(v)) continue;
    ++kept_extras;
    EXPECT_GE(nearest_in_range(v.R), 10.f - 1e-2f) << v.viewpoint << " " << v.inplane_deg;  // a gap it fills
  }
  EXPECT_EQ(kept.size() - kept_extras, range.size());  // the range is never touched
  EXPECT_GT(kept_extras, 0u);
  EXPECT_LT(kept_extras, extras);
  // What was dropped is within the tolerance of a view of the range.
  std::size_t checked = 0;
  for (std::size_t i = 0; i < views.size() && checked < 40; i += 7) {
    if (in_range(views[i]) || std::any_of(kept.begin(), kept.end(), [&](const TrainingView& k) {
          return k.viewpoint == views[i].viewpoint && k.inplane_deg == views[i].inplane_deg;
        }))
      continue;
    EXPECT_LT(nearest_in_range(views[i].R), 10.f + 1e-2f);
    ++checked;
  }
  EXPECT_GT(checked, 0u);

  NearSymmetry hex;
  hex.axis = Eigen::Vector3f::UnitZ();
  hex.angle_deg = 60.f;
  const auto nut = dropTurnsShownAlready(views, params.inplane_deg, {hex}, 10.f);
  std::size_t nut_extras = 0;
  for (const TrainingView& v : nut) nut_extras += in_range(v) ? 0 : 1;
  EXPECT_LT(nut_extras, kept_extras);
  EXPECT_EQ(nut.size() - nut_extras, range.size());
}

TEST(ViewSampling, RangesParseAndRejectNonsense) {
  EXPECT_EQ(parseSteppedRange("0.6:1.0:0.1", "radii").values().size(), 5u);
  EXPECT_EQ(parseSteppedRange("-60:60:10", "inplane").values().size(), 13u);
  EXPECT_EQ(parseSteppedRange("0.7", "radii").values().size(), 1u);
  EXPECT_THROW(parseSteppedRange("1:0:0.1", "radii"), InputError);
  EXPECT_THROW(parseSteppedRange("0:1:0", "radii"), InputError);
  EXPECT_THROW(parseSteppedRange("a:b", "radii"), InputError);
  ViewSamplingParams p;
  p.radii = {0.f, 0.f, 1.f};
  EXPECT_THROW(validateViewSampling(p), InputError);
  p = {};
  p.viewpoints = 0;
  EXPECT_THROW(validateViewSampling(p), InputError);
}

}  // namespace
}  // namespace vkpose
