// The demo and what it is made of: procedural meshes, upright placement, views from above,
// the bank cache, the config file, and the demo end to end on a small template set.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <tuple>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "eval/baselines.hpp"
#include "match/matcher.hpp"
#include "synth/placement.hpp"
#include "synth/procedural_meshes.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/picking.hpp"
#include "vkpose/synth.hpp"

using namespace vkpose;
namespace fs = std::filesystem;

namespace {
fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("vkpose_{}_{}", name, ::getpid());
  fs::remove_all(dir);
  return dir;
}
}  // namespace

TEST(ProceduralMeshes, SizesAndOutwardNormals) {
  const std::vector<Mesh> meshes = demoMeshes();
  ASSERT_EQ(meshes.size(), 3u);
  for (const Mesh& m : meshes) {
    SCOPED_TRACE(m.name);
    EXPECT_GT(m.diameter, 0.10f);
    EXPECT_LT(m.diameter, 0.25f);
    EXPECT_NEAR(m.bbox_min.z(), 0.f, 1e-4f) << "stands on its base at z = 0";
    ASSERT_EQ(m.normals.size(), m.vertices.size());
    ASSERT_EQ(m.colours.size(), m.vertices.size());
    // Each face's winding agrees with its vertices' normals (both point outwards), and the
    // mesh is closed enough that the signed volume is that of a solid.
    int agree = 0;
    double volume = 0;
    for (const auto& f : m.faces) {
      const Eigen::Vector3f a = m.vertices[f[0]], b = m.vertices[f[1]], c = m.vertices[f[2]];
      const Eigen::Vector3f n = (b - a).cross(c - a);
      agree += n.dot(m.normals[f[0]] + m.normals[f[1]] + m.normals[f[2]]) > 0.f;
      volume += a.dot(b.cross(c)) / 6.0;
    }
    EXPECT_GT(agree, 0.99 * static_cast<double>(m.faces.size()));
    EXPECT_GT(volume, 1e-4) << "a solid of more than 100 cm^3";
  }
}

TEST(ProceduralMeshes, PartsOfAPileHaveTheirSizesAndAreSolids) {
  // name, diameter (metres, +-5 %), and the volume of the solid (m^3, +-10 %).
  const std::vector<std::tuple<std::string, float, double>> expected = {
      {"hex_nut", 0.0125f, 2.598 * std::pow(5.77e-3, 2) * 5e-3 - 2.598 * std::pow(3.2e-3, 2) * 5e-3},
      {"cap_screw", 0.048f, M_PI * (2.75e-3 * 2.75e-3 * 3e-3 + 1.5e-3 * 1.5e-3 * 45e-3)},
      {"nozzle", 0.059f, M_PI * (49e-6 * 8e-3 + 100e-6 * 4e-3 + 42.25e-6 * 33e-3) + M_PI / 3 * 13e-3 * (42.25e-6 + 19.5e-6 + 9e-6)},
      {"spark_plug_key", 0.171f, M_PI * (121e-6 * 70e-3 + 64e-6 * 20e-3 + 25e-6 * 170e-3)},
  };
  const std::vector<Mesh> parts = partMeshes();
  ASSERT_EQ(parts.size(), expected.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Mesh& m = parts[i];
    const auto& [name, diameter, volume] = expected[i];
    SCOPED_TRACE(name);
    EXPECT_EQ(m.name, name);
    EXPECT_NEAR(m.diameter, diameter, 0.05f * diameter);
    EXPECT_NEAR(m.bbox_min.z(), 0.f, 1e-4f) << "stands on its base at z = 0";
    ASSERT_EQ(m.colours.size(), m.vertices.size());
    double v = 0;
    for (const auto& f : m.faces) v += m.vertices[f[0]].dot(m.vertices[f[1]].cross(m.vertices[f[2]])) / 6.0;
    EXPECT_GT(v, 0.0) << "outward faces";
    if (name != "spark_plug_key") {  // the key's bar and neck overlap
      EXPECT_NEAR(v, volume, 0.1 * volume);
    }
  }
  EXPECT_TRUE(isSmallPart(parts[0].diameter) && !isSmallPart(parts[3].diameter));
}

TEST(ProceduralMeshes, LatheIsClosedAroundItsAxis) {
  const Mesh cylinder = procedural::lathe({{0.f, 0.f}, {0.05f, 0.f}, {0.05f, 0.1f}, {0.f, 0.1f}}, 64, {1, 1, 1});
  EXPECT_NEAR(cylinder.diameter, std::hypot(0.1f, 0.1f), 1e-3f);
  double volume = 0;
  for (const auto& f : cylinder.faces)
    volume += cylinder.vertices[f[0]].dot(cylinder.vertices[f[1]].cross(cylinder.vertices[f[2]])) / 6.0;
  EXPECT_NEAR(volume, M_PI * 0.05 * 0.05 * 0.1, 0.01 * M_PI * 0.05 * 0.05 * 0.1);
  EXPECT_THROW(procedural::lathe({{0.f, 0.f}}, 64, {1, 1, 1}), InputError);
}

TEST(DemoPlacement, UprightOnlyKeepsPartsStanding) {
  const Mesh cup = liddedCupMesh();
  const std::vector<const Mesh*> meshes(6, &cup);
  PlacementParams params;
  params.layout = Layout::Bin;
  params.upright_only = true;
  params.bin_max_tilt_deg = 5.f;
  std::mt19937 rng(3);
  const auto poses = placeObjects(meshes, binWalls(params), params, tejaniCamera(), randomCamera({}, rng), rng);
  for (const auto& p : poses) {
    ASSERT_TRUE(p);
    EXPECT_GT(p->R(2, 2), std::cos(5.1f * M_PI / 180.f)) << "the cup's +z stays within 5 degrees of up";
  }
}

TEST(DemoViews, ViewsAboveKeepOnlyTheCone) {
  ViewSamplingParams v;
  v.inplane_deg = {0.f, 0.f, 1.f};
  v.radii = {0.7f, 0.7f, 0.1f};
  const auto all = sampleViews(v, Eigen::Vector3f::Zero());
  const auto above = viewsAbove(all, Eigen::Vector3f::Zero(), 40.f);
  // A Fibonacci lattice is equal-area: the 40-degree cap holds (1 - cos 40) of the hemisphere.
  EXPECT_NEAR(static_cast<double>(above.size()) / all.size(), 1.0 - std::cos(40.0 * M_PI / 180.0), 0.03);
  for (const auto& view : above) {
    const Eigen::Vector3f camera = -(view.R.transpose() * view.t);
    EXPECT_GE(camera.normalized().z(), std::cos(40.f * M_PI / 180.f) - 1e-5f);
  }
  EXPECT_THROW(viewsAbove(all, Eigen::Vector3f::Zero(), 0.f), InputError);
}

TEST(BankCache, SecondCallReadsTheBankAndOtherParamsTrainAgain) {
  const fs::path cache = freshDir("bank_cache");
  const Mesh mesh = gableCartonMesh();
  TrainingParams params;
  params.views = {6, false, {0.7f, 0.7f, 0.1f}, {0.f, 0.f, 10.f}};
  const auto views = sampleViews(params.views, mesh.bboxCentre());
  const CachedBank first = loadOrTrainBank(test::context(), mesh, params, views, cache.string());
  EXPECT_FALSE(first.from_cache);
  ASSERT_TRUE(fs::exists(first.path));
  const CachedBank second = loadOrTrainBank(test::context(), mesh, params, views, cache.string());
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(second.path, first.path);
  EXPECT_EQ(second.bank.templates.size(), first.bank.templates.size());

  TrainingParams other = params;
  other.features_per_modality = 40;
  EXPECT_NE(trainingKey(mesh, other, views), trainingKey(mesh, params, views));
  EXPECT_NE(trainingKey(liddedCupMesh(), params, views), trainingKey(mesh, params, views));

  // A damaged cache file is trained again and replaced, not an error.
  { std::ofstream(first.path, std::ios::binary | std::ios::trunc) << "not a bank"; }
  const CachedBank third = loadOrTrainBank(test::context(), mesh, params, views, cache.string());
  EXPECT_FALSE(third.from_cache);
  EXPECT_NO_THROW(loadBank(first.path));
  fs::remove_all(cache);
}

TEST(Demo, SolvesBinScenesEndToEnd) {
  const fs::path out = freshDir("demo");
  DemoParams params;
  params.out_dir = out.string();
  params.images = 2;
  params.cache_dir = std::string(VKPOSE_TEST_CACHE_DIR) + "/demo";
  // A quarter of the demo's templates (two distances, 20-degree in-plane steps), to keep the
  // test's training under a minute.
  params.views.radii = {0.6f, 0.8f, 0.2f};
  params.views.inplane_deg = {-180.f, 160.f, 20.f};
  const DemoReport report = runDemo(test::context(), params);
  ASSERT_EQ(report.objects.size(), 3u);
  ASSERT_EQ(report.images.size(), 2u);
  EXPECT_EQ(report.instances, 12);
  for (const char* f : {"overlay.png", "detections.json", "report.json", "results_vkpose.csv", "meshes/lidded_cup.ply"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const EvalSummary& s = report.evaluation.methods.front().summary;
  EXPECT_GE(s.mean.precision, 0.8) << "few false positives";
  EXPECT_GE(s.mean.recall, 0.4);

  // The picks (demo --pick): every scene has one, and its first is a right pose whose suction
  // gripper hits neither the bin nor another true part.
  const std::vector<PickPlan> picks = planDemoPicks(report, out.string());
  ASSERT_EQ(picks.size(), report.images.size());
  const BopDataset dataset = loadBopDataset((out / "dataset").string());
  for (std::size_t i = 0; i < picks.size(); ++i) {
    EXPECT_FALSE(picks[i].picks.empty()) << "scene " << i;
    const BopImage& im = dataset.images[i];
    std::vector<TruthInstance> truth;
    for (const GroundTruthPose& g : im.gt) truth.push_back({g.obj_id - 1, {g.R, g.t}});
    const std::optional<BinBox> bin = loadSynthBin(im);
    ASSERT_TRUE(bin) << "synth --layout bin writes each image's bin";
    EXPECT_EQ(firstPickProblem(picks[i], report.images[i].result.detections, report.banks, truth, bin), "")
        << "scene " << i;
    EXPECT_TRUE(fs::exists(out / "overlays" / fmt::format("{:06d}_picks.png", im.image_id)));
  }

  // A second run replaces its own folder and reads every bank from the cache.
  const DemoReport again = runDemo(test::context(), params);
  for (const auto& o : again.objects) EXPECT_TRUE(o.bank_from_cache) << o.name;
  EXPECT_DOUBLE_EQ(again.evaluation.methods.front().summary.mean.f1, s.mean.f1) << "same seed, same result";

  // A folder the demo did not write is not touched without --force.
  const fs::path mine = freshDir("demo_mine");
  fs::create_directories(mine);
  { std::ofstream(mine / "notes.txt") << "mine"; }
  params.out_dir = mine.string();
  EXPECT_THROW(runDemo(test::context(), params), InputError);
  EXPECT_TRUE(fs::exists(mine / "notes.txt"));
  fs::remove_all(out);
  fs::remove_all(mine);
}
