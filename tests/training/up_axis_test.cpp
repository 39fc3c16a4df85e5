// The up axis (issue 20): found from the mesh, the views sampled above it with image up along
// it, and stored in the bank.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Geometry>

#include "mesh_support.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/synth.hpp"

namespace vkpose {
namespace {

Mesh turned(Mesh mesh, const Eigen::Matrix3f& R) {
  for (auto& v : mesh.vertices) v = R * v;
  for (auto& n : mesh.normals) n = R * n;
  finishMesh(mesh);
  return mesh;
}

void expectUp(const Mesh& mesh, const Eigen::Vector3f& up, const std::string& what) {
  const UpAxisChoice choice = findUpAxis(mesh);
  EXPECT_TRUE(choice.found) << what << ": " << choice.reason;
  EXPECT_LT((choice.up - up).norm(), 1e-5f) << what << ": found " << upAxisName(choice.up) << ", expected "
                                            << upAxisName(up) << " (" << choice.reason << ")";
}

TEST(UpAxis, NamesAndParsing) {
  for (const char* name : {"+x", "-x", "+y", "-y", "+z", "-z"}) EXPECT_EQ(upAxisName(parseUpAxis(name)), name);
  EXPECT_EQ(parseUpAxis("-y"), Eigen::Vector3f(0, -1, 0));
  EXPECT_EQ(upAxisName(Eigen::Vector3f(0, 0.6f, 0.8f)), "(0.000, 0.600, 0.800)");
  EXPECT_THROW(parseUpAxis("z"), InputError);
  EXPECT_THROW(parseUpAxis("up"), InputError);
}

TEST(UpAxis, TheSharedMeshesStandTheirWayUp) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string d = test::sharedData() + "/meshes/";
  // milk.stl is modelled with +z pointing down into the jug (its cap at z = -0.248 m).
  expectUp(loadMesh(d + "milk.stl"), -Eigen::Vector3f::UnitZ(), "milk");
  expectUp(loadMesh(d + "coffee_cup.stl"), Eigen::Vector3f::UnitZ(), "coffee cup");
  expectUp(loadMesh(d + "juicecarton.stl"), Eigen::Vector3f::UnitZ(), "juice carton");
  // LM-O's models stand on +z in its scenes (every ground-truth pose there has it up).
  for (int id : {1, 5, 6, 8, 9, 10, 11, 12}) {
    const std::string path = test::sharedData() + "/lmo_scene2_frame3/models/obj_" +
                             std::string(6 - std::to_string(id).size(), '0') + std::to_string(id) + ".ply";
    expectUp(loadMesh(path, MeshUnits::Millimetres), Eigen::Vector3f::UnitZ(), path);
  }
}

TEST(UpAxis, FollowsTheMeshWhateverAxisItWasModelledAlong) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string d = test::sharedData() + "/meshes/";
  const Mesh milk = loadMesh(d + "milk.stl"), cup = loadMesh(d + "coffee_cup.stl");
  const Eigen::Matrix3f y_up = Eigen::AngleAxisf(-EIGEN_PI / 2, Eigen::Vector3f::UnitX()).toRotationMatrix();
  const Eigen::Matrix3f x_up = Eigen::AngleAxisf(EIGEN_PI / 2, Eigen::Vector3f::UnitY()).toRotationMatrix();
  const Eigen::Matrix3f flipped = Eigen::AngleAxisf(EIGEN_PI, Eigen::Vector3f::UnitX()).toRotationMatrix();
  // Modelled y-up (OBJ's and glTF's habit), x-up, or the other way up.
  for (const Eigen::Matrix3f& R : {y_up, x_up, flipped}) expectUp(turned(milk, R), -(R * Eigen::Vector3f::UnitZ()), "milk");
  for (const Eigen::Matrix3f& R : {y_up, x_up}) expectUp(turned(cup, R), R * Eigen::Vector3f::UnitZ(), "cup");
  // What the mesh cannot tell: a cup modelled upside down stands on its rim (a stable, broad
  // base), and a carton modelled y-up lies on a side broader than its base. The modeller's +z
  // wins; --up overrides it (docs/pipeline.md, stage 0).
  EXPECT_EQ(upAxisName(findUpAxis(turned(cup, flipped)).up), "+z");
  EXPECT_EQ(upAxisName(findUpAxis(turned(demoMeshes()[1], y_up)).up), "+z");
}

TEST(UpAxis, ViewsAreAboveItWithImageUpAlongIt) {
  ViewSamplingParams params;
  params.viewpoints = 60;
  params.radii = {0.7f, 0.7f, 1.f};
  params.inplane_deg = {0.f, 0.f, 1.f};
  const Eigen::Vector3f centre(0.01f, 0.02f, -0.1f);
  for (const char* name : {"+z", "-z", "+y", "-x"}) {
    params.up = parseUpAxis(name);
    const auto views = sampleViews(params, centre);
    ASSERT_EQ(views.size(), 60u);
    for (const TrainingView& v : views) {
      const Eigen::Vector3f camera = -(v.R.transpose() * v.t);
      const Eigen::Vector3f dir = (camera - centre).normalized();
      EXPECT_GT(dir.dot(params.up), 0.f) << name;
      // Image up (-y) is the up axis projected, unless the camera looks straight down it.
      const Eigen::Vector3f up_cam = v.R * params.up;
      if (std::abs(dir.dot(params.up)) < 0.99f) {
        EXPECT_LT(up_cam.y(), 0.f) << name;
      }
      EXPECT_NEAR(up_cam.x(), 0.f, 1e-4f) << name;
    }
    // viewsAbove measures from the up axis too.
    EXPECT_EQ(viewsAbove(views, centre, 90.f).size(), views.size());
    EXPECT_LT(viewsAbove(views, centre, 30.f).size(), views.size() / 2);
  }
  // +z is what it always was: the same views as the hemisphere about +z gave before.
  params.up = Eigen::Vector3f::UnitZ();
  const auto dirs = sphereViewpoints(params.viewpoints, false);
  const auto views = sampleViews(params, centre);
  for (std::size_t i = 0; i < views.size(); ++i) {
    const TrainingView same = lookAtView(dirs[i], centre, 0.7f, 0.f);
    EXPECT_EQ(views[i].R, same.R);
    EXPECT_EQ(views[i].t, same.t);
  }
  params.up = Eigen::Vector3f(0.f, 0.f, 2.f);
  EXPECT_THROW(validateViewSampling(params), InputError);
}

std::vector<std::string> names(const std::vector<Eigen::Vector3f>& ups) {
  std::vector<std::string> out;
  for (const auto& u : ups) out.push_back(upAxisName(u));
  return out;
}

TEST(UpAxis, OtherRestingPosesAreTheSidesItLiesOnThatNoNearSymmetryCovers) {
  using Names = std::vector<std::string>;
  // A brick stands on all six faces; its half-turns about x, y and z map each face onto the
  // opposite one, so one face of each pair is enough.
  const Mesh brick = test::boxMesh({0.08f, 0.05f, 0.12f});
  const UpAxisChoice brick_choice = findUpAxis(brick);
  const auto brick_turns = findNearSymmetries(brick, 0.03f * brick.diameter);
  EXPECT_EQ(names(otherRestingUps(brick_choice, brick_choice.up, brick_turns)), (Names{"+y", "+x"}));
  EXPECT_EQ(names(otherRestingUps(brick_choice, brick_choice.up, {})), (Names{"-z", "+y", "-y", "+x", "-x"}));
  // A square prism's quarter-turns about its axis: its four sides are one.
  const Mesh prism = test::boxMesh({0.06f, 0.06f, 0.2f});
  const UpAxisChoice prism_choice = findUpAxis(prism);
  EXPECT_EQ(names(otherRestingUps(prism_choice, prism_choice.up, findNearSymmetries(prism, 0.03f * prism.diameter))),
            (Names{"+y"}));
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string d = test::sharedData() + "/meshes/";
  for (const char* file : {"juicecarton.stl", "coffee_cup.stl", "milk.stl"}) {
    const Mesh mesh = loadMesh(d + file);
    const UpAxisChoice choice = findUpAxis(mesh);
    const auto others = otherRestingUps(choice, choice.up, findNearSymmetries(mesh, 0.03f * mesh.diameter));
    for (const Eigen::Vector3f& u : others) EXPECT_LT(u.dot(choice.up), 0.99f) << file;
    // The carton lies on a side (one for all four), the cup stands on its rim, the jug lies on its flanks.
    EXPECT_GE(others.size(), 1u) << file;
    if (std::string(file) == "juicecarton.stl") {
      EXPECT_EQ(others.size(), 1u) << fmt::format("{}", fmt::join(names(others), " "));
    }
  }
}

// --resting auto (train's default): a part smaller than 10 cm lies any way up in a bin, and so
// does any part trained nearer than 0.5 m (a bin-picking cell's distance), so training covers
// its other resting poses; a larger object seen from farther is trained standing.
TEST(UpAxis, RestingAutoTrainsEveryPoseOfASmallPartOrOneTrainedForABin) {
  EXPECT_TRUE(trainsOtherRestingPoses("auto", 0.04f, 0.6f));
  EXPECT_FALSE(trainsOtherRestingPoses("auto", 0.1f, 0.6f));
  EXPECT_FALSE(trainsOtherRestingPoses("auto", 0.25f, 0.5f));
  EXPECT_TRUE(trainsOtherRestingPoses("auto", 0.17f, 0.3f));
  EXPECT_TRUE(trainsOtherRestingPoses("auto", 0.25f, 0.49f));
  EXPECT_TRUE(trainsOtherRestingPoses("all", 0.25f, 0.6f));
  EXPECT_FALSE(trainsOtherRestingPoses("up", 0.04f, 0.3f));
  EXPECT_THROW(trainsOtherRestingPoses("sideways", 0.04f, 0.6f), InputError);
}

// The size evidence `vkpose train` prints and refuses on: with LINEMOD's Kinect (f about 572
// px) and its two levels of T 4 and 8 (16 pixels a coarse cell), a nut 12 mm across at 0.3-0.5 m
// spans 14-24 pixels, 0.9-1.5 cells: too small to tell from a screw head. A 40 mm bracket at
// 0.3-0.45 m (3.7-5.5 cells) is not, and a screw 3 mm thick at 0.45 m is 3.8 pixels: thin in depth.
TEST(UpAxis, SizeEvidenceRefusesAPartTooSmallToTellFromItsNeighbourhood) {
  TrainingParams params;
  params.views.radii = {0.3f, 0.5f, 0.05f};
  const PartSizeEvidence nut = partSizeEvidence(test::boxMesh({0.008f, 0.008f, 0.005f}), params);
  EXPECT_NEAR(nut.pixels_near, 572.f * nut.diameter_m / 0.3f, 2.f);
  EXPECT_NEAR(nut.cells_near, nut.pixels_near / 16.f, 1e-3f);
  EXPECT_TRUE(nut.too_small()) << nut.summary();
  EXPECT_NE(nut.refusal().find("--allow-small"), std::string::npos);
  EXPECT_NE(nut.summary().find("0.50-0.30 m"), std::string::npos) << nut.summary();

  params.views.radii = {0.3f, 0.45f, 0.05f};
  const PartSizeEvidence bracket = partSizeEvidence(test::boxMesh({0.04f, 0.02f, 0.012f}), params);
  EXPECT_FALSE(bracket.too_small()) << bracket.summary();
  EXPECT_GT(bracket.cells_far, 2.5f);
  EXPECT_FALSE(bracket.thin_in_depth()) << bracket.summary();

  // A screw 50 mm long is long enough, but 3 mm wide it is a line to the coarse level (0.36
  // cells at 0.3 m): refused, and told where it would be trained (within 0.11 m).
  const PartSizeEvidence screw = partSizeEvidence(test::boxMesh({0.003f, 0.003f, 0.05f}), params);
  EXPECT_GT(screw.cells_near, kMinPartCells);
  EXPECT_NEAR(screw.width_m, 0.003f, 1e-4f);
  EXPECT_TRUE(screw.line_like());
  EXPECT_TRUE(screw.too_small()) << screw.summary();
  EXPECT_NE(screw.refusal().find("3.0 mm wide at 0.30 m is 0.4 cells"), std::string::npos) << screw.refusal();
  EXPECT_NE(screw.refusal().find("within 0.11 m"), std::string::npos) << screw.refusal();
  EXPECT_NE(screw.refusal().find("--allow-small"), std::string::npos);
  EXPECT_TRUE(screw.thin_in_depth());
  EXPECT_NE(screw.summary().find("thinnest side, 3.0 mm"), std::string::npos) << screw.summary();
  // A flat plate is thin from one side only: wide enough seen from above.
  const PartSizeEvidence plate = partSizeEvidence(test::boxMesh({0.04f, 0.03f, 0.002f}), params);
  EXPECT_FALSE(plate.line_like()) << plate.summary();
  EXPECT_FALSE(plate.too_small());
}

// planTraining: what `vkpose train` and vkpose.train() decide before rendering. A brick 4 cm
// long is a small part, so "auto" trains its other resting poses besides the up axis found;
// "up" finds and reports them without training them; the full sphere has none; an up axis
// given is kept.
TEST(UpAxis, TrainingPlanTakesTheUpAxisFoundAndTrainsRestingPosesAsAsked) {
  const Mesh brick = test::boxMesh({0.04f, 0.02f, 0.012f});
  const auto plan = [&](bool auto_up, const std::string& resting, bool full_sphere, TrainingParams& params) {
    params.views.viewpoints = 30;
    params.views.radii = {0.3f, 0.4f, 0.1f};
    params.views.inplane_deg = {0.f, 0.f, 10.f};
    params.views.full_sphere = full_sphere;
    return planTraining(brick, params, auto_up, resting, 80.f);
  };
  const UpAxisChoice found = findUpAxis(brick);
  ASSERT_TRUE(found.found) << found.reason;

  TrainingParams automatic;
  const TrainingPlan a = plan(true, "auto", false, automatic);
  EXPECT_EQ(upAxisName(automatic.views.up), upAxisName(found.up));
  EXPECT_EQ(upAxisName(a.found.up), upAxisName(found.up));
  ASSERT_FALSE(a.other_ups.empty());
  EXPECT_EQ(names(automatic.views.other_ups), names(a.other_ups));
  for (const Eigen::Vector3f& u : a.other_ups) EXPECT_LT(u.dot(automatic.views.up), 0.99f);
  // Each hemisphere's views, the same as sampling them by hand.
  const auto by_hand = dropTurnsShownAlready(sampleViews(automatic.views, brick.bboxCentre()),
                                             automatic.views.inplane_deg,
                                             findNearSymmetries(brick, automatic.near_symmetry_tolerance * brick.diameter),
                                             fullTurnStep(automatic.views.inplane_deg));
  EXPECT_EQ(a.views.size(), viewsAbove(by_hand, brick.bboxCentre(), 80.f).size());
  std::set<std::string> ups;
  for (const TrainingView& v : a.views) ups.insert(upAxisName(v.up));
  EXPECT_EQ(ups.size(), 1u + a.other_ups.size());

  TrainingParams standing;
  const TrainingPlan s = plan(true, "up", false, standing);
  EXPECT_EQ(names(s.other_ups), names(a.other_ups));  // found and reported, not trained
  EXPECT_TRUE(standing.views.other_ups.empty());
  EXPECT_LT(s.views.size(), a.views.size());

  TrainingParams given;
  given.views.up = parseUpAxis("-x");
  const TrainingPlan g = plan(false, "up", false, given);
  EXPECT_EQ(upAxisName(given.views.up), "-x");  // kept as the user gave it
  EXPECT_EQ(upAxisName(g.found.up), upAxisName(found.up));

  TrainingParams sphere;
  const TrainingPlan f = plan(true, "all", true, sphere);
  EXPECT_TRUE(f.other_ups.empty());
  EXPECT_TRUE(sphere.views.other_ups.empty());

  // A part in a bin is seen from above at any turn: the whole turn near each pole, unless the
  // caller says otherwise; a standing part keeps the range.
  EXPECT_FLOAT_EQ(automatic.views.full_turn_within_deg, kPileFullTurnWithinDeg);
  EXPECT_FLOAT_EQ(standing.views.full_turn_within_deg, 0.f);
  TrainingParams asked;
  asked.views.viewpoints = 30;
  asked.views.radii = {0.3f, 0.4f, 0.1f};
  asked.views.inplane_deg = {0.f, 0.f, 10.f};
  const TrainingPlan none = planTraining(brick, asked, true, "auto", 80.f, 0.f);
  EXPECT_FLOAT_EQ(asked.views.full_turn_within_deg, 0.f);
  EXPECT_LT(none.views.size(), a.views.size());
  planTraining(brick, asked, true, "up", 80.f, 20.f);
  EXPECT_FLOAT_EQ(asked.views.full_turn_within_deg, 20.f);

  TrainingParams bad;
  EXPECT_THROW(plan(true, "sideways", false, bad), InputError);
}

TEST(UpAxis, EachRestingPoseHasAHemisphereOfViews) {
  ViewSamplingParams params;
  params.viewpoints = 40;
  params.radii = {0.7f, 0.8f, 0.1f};
  params.inplane_deg = {-10.f, 10.f, 10.f};
  params.up = parseUpAxis("+z");
  params.other_ups = {parseUpAxis("+x"), parseUpAxis("-y")};
  const Eigen::Vector3f centre(0.01f, 0.02f, -0.1f);
  const auto views = sampleViews(params, centre);
  ASSERT_EQ(views.size(), 3u * 40u * 2u * 3u);
  std::set<int> viewpoints;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const TrainingView& v = views[i];
    const Eigen::Vector3f expected_up = i < 240 ? params.up : params.other_ups[i < 480 ? 0 : 1];
    EXPECT_LT((v.up - expected_up).norm(), 1e-6f) << i;
    const Eigen::Vector3f camera = -(v.R.transpose() * v.t);
    EXPECT_GT((camera - centre).normalized().dot(v.up), 0.f) << i;
    viewpoints.insert(v.viewpoint);
  }
  EXPECT_EQ(viewpoints.size(), 120u);  // numbered on from one hemisphere to the next
  // The first hemisphere is the one-up sampling, unchanged.
  ViewSamplingParams one = params;
  one.other_ups.clear();
  const auto first = sampleViews(one, centre);
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_EQ(first[i].R, views[i].R);
  // viewsAbove measures each view from its own hemisphere's up.
  EXPECT_EQ(viewsAbove(views, centre, 90.f).size(), views.size());
  const auto near_top = viewsAbove(views, centre, 30.f);
  EXPECT_LT(near_top.size(), views.size() / 2);
  for (const auto& v : {parseUpAxis("+z"), parseUpAxis("+x"), parseUpAxis("-y")})
    EXPECT_TRUE(std::any_of(near_top.begin(), near_top.end(), [&](const TrainingView& t) { return t.up == v; }));
  // Nonsense is refused.
  params.full_sphere = true;
  EXPECT_THROW(validateViewSampling(params), InputError);
  params.full_sphere = false;
  params.other_ups = {Eigen::Vector3f(0.f, 0.f, 0.f)};
  EXPECT_THROW(validateViewSampling(params), InputError);
  params.other_ups.assign(6, Eigen::Vector3f::UnitX());
  EXPECT_THROW(validateViewSampling(params), InputError);
}

TEST(UpAxis, TheBankKeepsIt) {
  const Mesh carton = demoMeshes()[1];
  TrainingParams params;
  params.views.viewpoints = 3;
  params.views.radii = {0.6f, 0.6f, 1.f};
  params.views.inplane_deg = {0.f, 0.f, 1.f};
  params.views.up = parseUpAxis("-y");
  params.views.other_ups = {parseUpAxis("+x")};
  params.views.full_turn_within_deg = 25.f;  // none of the 3 viewpoints is that near a pole
  const TemplateBank bank = trainTemplates(test::context(), carton, params);
  const std::string path = (std::filesystem::temp_directory_path() / "vkpose_up_axis_test.vkpb").string();
  saveBank(bank, path);
  const TemplateBank back = loadBank(path);
  std::filesystem::remove(path);
  EXPECT_EQ(upAxisName(back.params.views.up), "-y");
  ASSERT_EQ(back.params.views.other_ups.size(), 1u);
  EXPECT_EQ(upAxisName(back.params.views.other_ups[0]), "+x");
  EXPECT_FLOAT_EQ(back.params.views.full_turn_within_deg, 25.f);
  // Every template was rendered from above -y, then from above +x.
  ASSERT_EQ(back.templates.size(), 6u);
  for (std::size_t i = 0; i < back.templates.size(); ++i) {
    const BankTemplate& t = back.templates[i];
    const Eigen::Vector3f camera = -(t.pose.R.transpose() * t.pose.t);
    EXPECT_GT((camera - back.centre).dot(i < 3 ? params.views.up : params.views.other_ups[0]), 0.f) << i;
  }
}

}  // namespace
}  // namespace vkpose
