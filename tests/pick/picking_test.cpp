// Bin picking: grasp files are checked value by value; a symmetric part's grasp is offered at
// every angle the part lies at; grasps are refused where the gripper would hit the bin's wall,
// another detection or the scene, with the reason; the first pick is checked against the truth.
// Geometry built in code: no data needed.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "synth/procedural_meshes.hpp"
#include "mesh_support.hpp"
#include "test_support.hpp"
#include "vkpose/picking.hpp"

namespace vkpose {
namespace {

/// A bank holding only what picking uses: a 8 cm wide, 10 cm tall cylinder ("can"), symmetric
/// about +z through the origin.
TemplateBank canBank() {
  TemplateBank bank;
  bank.object = "can";
  bank.mesh = procedural::lathe({{0.f, -0.05f}, {0.04f, -0.05f}, {0.04f, 0.05f}, {0.f, 0.05f}}, 48, {0.5f, 0.5f, 0.5f});
  finishMesh(bank.mesh);
  bank.diameter = bank.mesh.diameter;
  bank.symmetric = true;
  return bank;
}

const char* kSideGrasp = R"({"object": "can",
  "gripper": {"shape": "cylinder", "radius_mm": 15, "length_mm": 120},
  "grasps": [{"name": "side", "priority": 1, "position_mm": [40, 0, 0], "approach": [-1, 0, 0], "x": [0, 0, 1],
              "approach_distance_mm": 80, "retreat_distance_mm": 80, "suction_radius_mm": 10}]})";

Detection detectionAt(const Pose& pose) {
  Detection d;
  d.object = "can";
  d.score = 0.9f;
  d.pose = pose;
  return d;
}

/// The can lying on its side (axis along the camera's x) at 0.8 m, turned about its axis by `roll`.
Pose lyingCan(float roll_deg, float x = 0.f) {
  Pose p;
  p.R = Eigen::AngleAxisf(roll_deg * 3.14159265f / 180.f, Eigen::Vector3f::UnitX()).toRotationMatrix() *
        Eigen::AngleAxisf(3.14159265f / 2, Eigen::Vector3f::UnitY()).toRotationMatrix();
  p.t = {x, 0.f, 0.8f};
  return p;
}

Camera camera() {
  Camera c;
  c.width = 640, c.height = 480;
  return c;
}

TEST(Picking, GraspFilesAreCheckedValueByValue) {
  const GraspSet set = parseGrasps(kSideGrasp, "can.json");
  ASSERT_EQ(set.object, "can");
  ASSERT_EQ(set.grasps.size(), 1u);
  const Grasp& g = set.grasps[0];
  EXPECT_TRUE(g.pose.R.col(2).isApprox(Eigen::Vector3f(-1, 0, 0)));  // z is the approach
  EXPECT_TRUE(g.pose.t.isApprox(Eigen::Vector3f(0.04f, 0, 0)));      // millimetres read as such
  EXPECT_FLOAT_EQ(g.gripper.radius, 0.015f);
  EXPECT_FLOAT_EQ(g.suction_radius_m, 0.01f);

  auto bad = [](const std::string& grasp) {
    return R"({"object": "can", "grasps": [)" + grasp + "]}";
  };
  test::expectInputError([&] { parseGrasps(bad(R"({"name": "a", "position_mm": [0,0,0], "approach": [0,0,2], "opening_mm": 5})"), "f.json"); },
                         {"f.json", "grasp 'a'", "not a unit vector"});
  test::expectInputError([&] { parseGrasps(bad(R"({"name": "a", "position_mm": [0,"nan",0], "approach": [0,0,1], "opening_mm": 5})"), "f.json"); },
                         {"grasp 'a'", "position_mm", "not a number"});
  test::expectInputError([&] { parseGrasps(bad(R"({"name": "a", "position_mm": [0,0,0], "approach": [0,0,1]})"), "f.json"); },
                         {"opening", "suction_radius"});
  test::expectInputError([&] { parseGrasps(bad(R"({"name": "a", "position_mm": [0,0,0], "approach": [0,0,1], "x": [0,1,1], "opening_mm": 5})"), "f.json"); },
                         {"'x'"});
  test::expectInputError([&] { parseGrasps(bad(R"({"name": "a", "position_m": [0,0,0], "approach": [0,0,1], "opening_mm": -5})"), "f.json"); },
                         {"negative"});
  test::expectInputError([] { parseGrasps(R"({"object": "can", "grasps": []})", "f.json"); }, {"at least one grasp"});
  test::expectInputError([] { parseGrasps(R"({"grasps": []})", "f.json"); }, {"\"object\""});
  test::expectInputError([] { parseGrasps("{not json", "f.json"); }, {"f.json", "not JSON"});
  test::expectInputError([] { parsePickOrder("random"); }, {"combined, height, score or visible"});
}

TEST(Picking, ASymmetricPartsGraspIsOfferedAtEveryAngleItLiesAt) {
  const TemplateBank bank = canBank();
  const std::vector<Grasp> side = parseGrasps(kSideGrasp, "can.json").grasps;
  const std::vector<Grasp> expanded = expandBySymmetry(side, bank, 36);
  EXPECT_EQ(expanded.size(), 36u);
  PickParams params;
  for (int roll = 0; roll < 360; roll += 25) {
    const std::vector<Detection> dets = {detectionAt(lyingCan(static_cast<float>(roll)))};
    const PickPlan with = planPicks(dets, {bank}, {expanded}, cv::Mat(), camera(), std::nullopt, params);
    ASSERT_EQ(with.picks.size(), 1u) << "roll " << roll;
    EXPECT_LE(with.picks[0].grasp.tilt_deg, 5.01f) << "roll " << roll;  // a copy every 10 degrees
    // Its tool centre point stays on the can's surface, facing the camera.
    EXPECT_NEAR((with.picks[0].grasp.pose.t - dets[0].pose.t).norm(), 0.04f, 1e-4f);
  }
  // Without the copies most angles are refused, for the tilt, with the reason.
  const PickPlan without = planPicks({detectionAt(lyingCan(120.f))}, {bank}, {side}, cv::Mat(), camera(), std::nullopt,
                                     params);
  EXPECT_TRUE(without.picks.empty());
  ASSERT_EQ(without.detections[0].refused.size(), 1u);
  EXPECT_NE(without.detections[0].refused[0].reason.find("tilted"), std::string::npos);
}

TEST(Picking, ABodyOfRevolutionTrainedWithoutTheFlagGetsEveryAngleToo) {
  // The can again, its bank not --symmetric: the training's near-symmetries (every turn about
  // its axis) show it is a body of revolution, so its grasp is copied all round as well.
  TemplateBank bank = canBank();
  bank.symmetric = false;
  bank.near_symmetries = findNearSymmetries(bank.mesh, 0.03f * bank.diameter);
  const auto axis = revolutionAxis(bank.near_symmetries);
  ASSERT_TRUE(axis.has_value());
  EXPECT_GT(std::abs(axis->axis.normalized().z()), 0.99f);
  const std::vector<Grasp> side = parseGrasps(kSideGrasp, "can.json").grasps;
  const std::vector<Grasp> expanded = expandBySymmetry(side, bank, 36);
  PickParams params;
  for (int roll = 0; roll < 360; roll += 25) {
    const PickPlan plan =
        planPicks({detectionAt(lyingCan(static_cast<float>(roll)))}, {bank}, {expanded}, cv::Mat(), camera(),
                  std::nullopt, params);
    ASSERT_EQ(plan.picks.size(), 1u) << "roll " << roll;
    EXPECT_LE(plan.picks[0].grasp.tilt_deg, 5.5f) << "roll " << roll;
  }
  // A square prism passes 90, 180 and 270 degrees about its axis, not 60 or 120: no body of
  // revolution, and its grasps are copied by those turns alone.
  TemplateBank prism = bank;
  prism.mesh = test::boxMesh({0.06f, 0.06f, 0.1f});
  prism.near_symmetries = findNearSymmetries(prism.mesh, 0.03f * prism.mesh.diameter);
  EXPECT_FALSE(prism.near_symmetries.empty());
  EXPECT_FALSE(revolutionAxis(prism.near_symmetries).has_value());
  EXPECT_EQ(expandBySymmetry(side, prism, 36).size(), 1 + prism.near_symmetries.size());
  // Nor is a hexagonal prism (sixths only).
  Mesh hexagon = procedural::lathe({{0.f, -0.05f}, {0.04f, -0.05f}, {0.04f, 0.05f}, {0.f, 0.05f}}, 6, {0.5f, 0.5f, 0.5f});
  finishMesh(hexagon);
  const auto hex_turns = findNearSymmetries(hexagon, 0.03f * hexagon.diameter);
  EXPECT_FALSE(hex_turns.empty());
  EXPECT_FALSE(revolutionAxis(hex_turns).has_value());
}

TEST(Picking, TiltIsMeasuredDownIntoTheBinWhereThereIsOne) {
  // A bin seen at 30 degrees (its z, up out of it, tilted towards the camera) and a can
  // standing on its floor, taken by a suction cup on its lid straight down into the bin.
  BinBox bin;
  bin.pose.R = Eigen::AngleAxisf(150.f * 3.14159265f / 180.f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  bin.pose.t = {0.f, 0.f, 0.9f};
  EXPECT_NEAR(approachAxis({}, bin).dot(-bin.pose.R.col(2)), 1.f, 1e-6f);
  EXPECT_EQ(approachAxis({}, std::nullopt), Eigen::Vector3f::UnitZ());
  PickParams given;
  given.approach_axis = Eigen::Vector3f(0.f, 0.f, 2.f);  // the robot's axis wins, as a unit vector
  EXPECT_NEAR((approachAxis(given, bin) - Eigen::Vector3f::UnitZ()).norm(), 0.f, 1e-6f);
  given.approach_axis = Eigen::Vector3f::Zero();
  EXPECT_NE(test::inputErrorOf([&] { approachAxis(given, bin); }).find("approach axis"), std::string::npos);

  const TemplateBank bank = canBank();
  const std::vector<Grasp> top = parseGrasps(R"({"object": "can",
    "gripper": {"shape": "cylinder", "radius_mm": 15, "length_mm": 120},
    "grasps": [{"name": "top", "position_mm": [0, 0, 50], "approach": [0, 0, -1], "x": [1, 0, 0],
                "approach_distance_mm": 80, "retreat_distance_mm": 80, "suction_radius_mm": 10}]})",
                                             "can.json")
                                     .grasps;
  Pose standing;
  standing.R = bin.pose.R;
  standing.t = bin.pose.t + bin.pose.R * Eigen::Vector3f(0.f, 0.f, 0.0505f);
  PickParams params;
  params.max_tilt_deg = 20.f;
  const PickPlan in_bin = planPicks({detectionAt(standing)}, {bank}, {top}, cv::Mat(), camera(), bin, params);
  ASSERT_EQ(in_bin.picks.size(), 1u);
  EXPECT_LT(in_bin.picks[0].grasp.tilt_deg, 0.1f);
  // Measured from the camera's view instead, the same grasp is 30 degrees off, and refused.
  params.approach_axis = Eigen::Vector3f::UnitZ();
  const PickPlan from_camera = planPicks({detectionAt(standing)}, {bank}, {top}, cv::Mat(), camera(), bin, params);
  EXPECT_TRUE(from_camera.picks.empty());
  ASSERT_EQ(from_camera.detections[0].refused.size(), 1u);
  EXPECT_NE(from_camera.detections[0].refused[0].reason.find("tilted 30 degrees"), std::string::npos);
}

TEST(Picking, ANarrowWindowOfApproachesIsFoundWhateverAngleThePartLiesAt) {
  // A can lying turned 5 degrees about its axis, and approaches allowed within 2 degrees of
  // the camera's axis: every copy of its side grasp 10 degrees apart is 5 degrees off, so
  // copies every 10 degrees refuse it; the default copies (every 2.5 degrees) find the one
  // straight down. A neighbour or a wall beside a part leaves such gaps.
  const TemplateBank bank = canBank();
  const std::vector<Grasp> side = parseGrasps(kSideGrasp, "can.json").grasps;
  PickParams params;
  params.max_tilt_deg = 2.f;
  EXPECT_GE(params.symmetry_steps, 144);
  const Detection can = detectionAt(lyingCan(5.f));
  const PickPlan coarse =
      planPicks({can}, {bank}, {expandBySymmetry(side, bank, 36)}, cv::Mat(), camera(), std::nullopt, params);
  EXPECT_TRUE(coarse.picks.empty());
  ASSERT_EQ(coarse.detections[0].refused.size(), 1u);
  EXPECT_NE(coarse.detections[0].refused[0].reason.find("tilted 5 degrees"), std::string::npos)
      << coarse.detections[0].refused[0].reason;
  const PickPlan fine = planPicks({can}, {bank}, {expandBySymmetry(side, bank, params.symmetry_steps)}, cv::Mat(),
                                  camera(), std::nullopt, params);
  ASSERT_EQ(fine.picks.size(), 1u);
  EXPECT_LT(fine.picks[0].grasp.tilt_deg, 0.1f);
}

TEST(Picking, AGraspKeepsItsDistanceFromANeighbour) {
  // A can lying on its side, and a second one lying beside and above it (centre 56 mm across
  // and 80 mm nearer the camera): the suction gripper (15 mm radius) coming straight down
  // onto the first passes 1 mm from the second.
  const TemplateBank bank = canBank();
  const std::vector<Grasp> grasps = expandBySymmetry(parseGrasps(kSideGrasp, "can.json").grasps, bank, 144);
  Pose neighbour = lyingCan(0.f);
  neighbour.t = {0.f, 0.056f, 0.72f};
  const std::vector<Detection> cans = {detectionAt(lyingCan(0.f)), detectionAt(neighbour)};
  PickParams params;
  params.max_tilt_deg = 2.f;  // only the straight approach
  const PickPlan close = planPicks(cans, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, params);
  EXPECT_TRUE(close.detections[0].valid.empty());  // within the 3 mm a neighbour's pose may be off
  ASSERT_EQ(close.detections[0].refused.size(), 1u);
  EXPECT_NE(close.detections[0].refused[0].reason.find("hits detection 2"), std::string::npos)
      << close.detections[0].refused[0].reason;
  params.neighbour_margin_m = 0.f;
  const PickPlan grazing = planPicks(cans, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, params);
  ASSERT_EQ(grazing.detections[0].valid.size(), 1u);
  EXPECT_LT(grazing.detections[0].valid[0].clearance_m, 0.003f);
  // Allowed 45 degrees, the copy chosen is not the least tilted but one turned away from the
  // neighbour, with room around it.
  params = PickParams{};
  const PickPlan roomy = planPicks(cans, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, params);
  ASSERT_EQ(roomy.detections[0].valid.size(), 1u);
  EXPECT_GT(roomy.detections[0].valid[0].tilt_deg, 2.f);
  EXPECT_GT(roomy.detections[0].valid[0].clearance_m, 0.005f);
}

TEST(Picking, GraspsThatHitTheBinOrANeighbourAreRefusedWithTheReason) {
  const TemplateBank bank = canBank();
  const std::vector<Grasp> grasps = expandBySymmetry(parseGrasps(kSideGrasp, "can.json").grasps, bank, 36);
  // A bin seen from 0.8 m above its floor centre, 30 x 20 cm, walls 15 cm high: the camera looks
  // down its -z (bin frame z up).
  BinBox bin;
  bin.pose.R = Eigen::AngleAxisf(3.14159265f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  bin.pose.t = {0.f, 0.f, 0.84f};
  bin.inner = {0.3f, 0.2f, 0.15f};
  bin.wall_thickness_m = 0.01f;
  PickParams params;
  // A can in the middle of the floor: clear.
  const PickPlan clear = planPicks({detectionAt(lyingCan(0.f))}, {bank}, {grasps}, cv::Mat(), camera(), bin, params);
  ASSERT_EQ(clear.picks.size(), 1u);
  EXPECT_GT(clear.picks[0].height, 0.f);
  // The same grasp with a gripper 30 cm wide reaches the walls.
  std::vector<Grasp> wide = grasps;
  for (Grasp& g : wide) g.gripper.radius = 0.15f;
  const PickPlan walls = planPicks({detectionAt(lyingCan(0.f))}, {bank}, {wide}, cv::Mat(), camera(), bin, params);
  EXPECT_TRUE(walls.picks.empty());
  ASSERT_EQ(walls.detections[0].refused.size(), 1u);
  EXPECT_NE(walls.detections[0].refused[0].reason.find("hits the bin's wall"), std::string::npos)
      << walls.detections[0].refused[0].reason;
  // A second can lying across the first one's approach, nearer the camera.
  Pose above = lyingCan(0.f);
  above.t.z() = 0.72f;
  const PickPlan blocked = planPicks({detectionAt(lyingCan(0.f)), detectionAt(above)}, {bank}, {grasps}, cv::Mat(),
                                     camera(), std::nullopt, params);
  ASSERT_EQ(blocked.detections.size(), 2u);
  EXPECT_TRUE(blocked.detections[0].valid.empty());
  EXPECT_NE(blocked.detections[0].refused[0].reason.find("hits detection 2"), std::string::npos)
      << blocked.detections[0].refused[0].reason;
  ASSERT_EQ(blocked.picks.size(), 1u);  // the one on top is picked
  EXPECT_EQ(blocked.picks[0].detection, 1);
  // The one on top with a pose too uncertain to pick (a third of its outline on the image's
  // edges) blocks nothing: it is as uncertain an obstacle (what the depth image shows of it
  // still would be, as below).
  Detection doubtful = detectionAt(above);
  doubtful.outline_on_edges = 0.3f;
  const PickPlan past = planPicks({detectionAt(lyingCan(0.f)), doubtful}, {bank}, {grasps}, cv::Mat(), camera(),
                                  std::nullopt, params);
  ASSERT_EQ(past.picks.size(), 1u);
  EXPECT_EQ(past.picks[0].detection, 0);
  EXPECT_TRUE(past.detections[1].valid.empty());
  // Scene points in the way (a board 5 cm above the can, seen in the depth image) refuse it.
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(0.70f));
  const PickPlan board = planPicks({detectionAt(lyingCan(0.f))}, {bank}, {grasps}, depth, camera(), std::nullopt, params);
  EXPECT_TRUE(board.picks.empty());
  EXPECT_NE(board.detections[0].refused[0].reason.find("scene points"), std::string::npos);
  // The plan as JSON.
  const auto doc = nlohmann::json::parse(pickPlanJson(blocked));
  EXPECT_EQ(doc.at("picks").size(), 1u);
  EXPECT_EQ(doc.at("grasps").at(0).at("refused").at(0).at("name"), "side");
  EXPECT_TRUE(doc.at("picks").at(0).at("grasp").contains("approach_point"));
}

TEST(Picking, FingersLeaveRoomBesideThePartThatAPalmWouldTake) {
  // Jaws 10 cm apart under a palm 6 cm in radius; the gripper frame is the camera frame here.
  Grasp g = parseGrasps(R"({"object": "can", "gripper": {"radius_mm": 60, "length_mm": 150, "finger_length_mm": 60,
    "finger_width_mm": 20, "finger_thickness_mm": 10}, "grasps": [{"name": "jaws", "position_mm": [0, 0, 0],
    "approach": [0, 0, 1], "x": [1, 0, 0], "opening_mm": 100}]})",
                        "jaws.json")
                  .grasps[0];
  EXPECT_FLOAT_EQ(g.gripper.finger_length, 0.06f);
  // Beside the part, between the fingers' planes (y 3 cm, 2 cm back): clear of the fingers.
  const std::vector<std::vector<Eigen::Vector3f>> beside = {{Eigen::Vector3f(0.f, 0.03f, -0.02f)}};
  EXPECT_EQ(gripperCollision(g, Pose{}, std::nullopt, beside, {"a neighbour"}), "");
  // On a finger's path (x 5.5 cm), or behind the fingers where the palm passes: hit.
  EXPECT_EQ(gripperCollision(g, Pose{}, std::nullopt, {{Eigen::Vector3f(0.055f, 0.f, -0.02f)}}, {"a neighbour"}),
            "hits a neighbour");
  EXPECT_EQ(gripperCollision(g, Pose{}, std::nullopt, {{Eigen::Vector3f(0.f, 0.03f, -0.1f)}}, {"a neighbour"}),
            "hits a neighbour");
  // Without fingers the palm's cylinder reaches down to the tool centre point.
  g.gripper.finger_length = 0.f;
  EXPECT_EQ(gripperCollision(g, Pose{}, std::nullopt, beside, {"a neighbour"}), "hits a neighbour");
}

TEST(Picking, TheFirstPickIsCheckedAgainstTheTruth) {
  const TemplateBank bank = canBank();
  const std::vector<Grasp> grasps = expandBySymmetry(parseGrasps(kSideGrasp, "can.json").grasps, bank, 36);
  const std::vector<Detection> dets = {detectionAt(lyingCan(10.f))};
  const PickPlan plan = planPicks(dets, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, {});
  // The truth at another roll: the same instance for a symmetric can (ADI).
  EXPECT_EQ(firstPickProblem(plan, dets, {bank}, {{0, lyingCan(70.f)}}, std::nullopt), "");
  EXPECT_NE(firstPickProblem(plan, dets, {bank}, {{0, lyingCan(0.f, 0.05f)}}, std::nullopt).find("no true instance"),
            std::string::npos);
  // A true neighbour the detector missed, across the approach: the gripper would hit it.
  Pose above = lyingCan(0.f);
  above.t.z() = 0.72f;
  EXPECT_NE(firstPickProblem(plan, dets, {bank}, {{0, lyingCan(10.f)}, {0, above}}, std::nullopt).find("hits true instance 1"),
            std::string::npos);
  EXPECT_EQ(firstPickProblem({}, dets, {bank}, {}, std::nullopt), "no pick");
}

TEST(Picking, APoseWhoseOutlineStraysFromTheImagesEdgesIsNotPicked) {
  const TemplateBank bank = canBank();
  const std::vector<Grasp> grasps = expandBySymmetry(parseGrasps(kSideGrasp, "can.json").grasps, bank, 36);
  // Three cans side by side along their axes, 20 cm apart.
  Detection loose = detectionAt(lyingCan(0.f, -0.2f)), firm = detectionAt(lyingCan(0.f)),
            unmeasured = detectionAt(lyingCan(0.f, 0.2f));
  loose.outline_on_edges = 0.3f;
  firm.outline_on_edges = 0.8f;
  const PickPlan plan = planPicks({loose, firm, unmeasured}, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, {});
  ASSERT_EQ(plan.detections.size(), 3u);
  EXPECT_TRUE(plan.detections[0].valid.empty());
  ASSERT_EQ(plan.detections[0].refused.size(), 1u);
  EXPECT_EQ(plan.detections[0].refused[0].name, "side");
  EXPECT_NE(plan.detections[0].refused[0].reason.find("outline lies on the image's edges for 30.0 %"), std::string::npos)
      << plan.detections[0].refused[0].reason;
  EXPECT_FALSE(plan.detections[1].valid.empty()) << "0.8 of its outline on edges";
  EXPECT_FALSE(plan.detections[2].valid.empty()) << "not measured: not held back";
  PickParams off;
  off.min_outline_on_edges = 0.f;
  EXPECT_FALSE(planPicks({loose}, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, off).picks.empty());
}

TEST(Picking, APoseWhoseColourDisagreesWithItsModelIsNotPicked) {
  const TemplateBank bank = canBank();
  const std::vector<Grasp> grasps = expandBySymmetry(parseGrasps(kSideGrasp, "can.json").grasps, bank, 36);
  // A cylinder of another colour taken for the can: its outline fits, its colour does not.
  Detection other = detectionAt(lyingCan(0.f, -0.2f)), same = detectionAt(lyingCan(0.f)),
            uncoloured = detectionAt(lyingCan(0.f, 0.2f));
  other.outline_on_edges = same.outline_on_edges = 0.9f;
  other.colour_agreement = 0.3f;
  same.colour_agreement = 0.85f;  // uncoloured keeps 1: a mesh without colours measures nothing
  other.colour_measured = same.colour_measured = true;
  const PickPlan plan = planPicks({other, same, uncoloured}, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, {});
  ASSERT_EQ(plan.detections.size(), 3u);
  EXPECT_TRUE(plan.detections[0].valid.empty());
  ASSERT_EQ(plan.detections[0].refused.size(), 1u);
  EXPECT_NE(plan.detections[0].refused[0].reason.find("colour agrees with the model's 0.30 (a pick needs 0.68)"),
            std::string::npos)
      << plan.detections[0].refused[0].reason;
  EXPECT_FALSE(plan.detections[1].valid.empty());
  EXPECT_FALSE(plan.detections[2].valid.empty());
  for (const Pick& p : plan.picks) EXPECT_NE(p.detection, 0);
  PickParams off;
  off.min_colour_agreement = 0.f;
  EXPECT_FALSE(planPicks({other}, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, off).picks.empty());
}

TEST(Picking, AColourThatPassedLetsLessOfTheOutlineSitOnEdges) {
  const TemplateBank bank = canBank();
  const std::vector<Grasp> grasps = expandBySymmetry(parseGrasps(kSideGrasp, "can.json").grasps, bank, 36);
  // A part partly under others, 45 % of its outline on the image's edges (the gate is 50 %).
  Detection coloured = detectionAt(lyingCan(0.f));
  coloured.outline_on_edges = 0.45f;
  Detection uncoloured = coloured, too_loose = coloured;
  coloured.colour_measured = too_loose.colour_measured = true;
  coloured.colour_agreement = too_loose.colour_agreement = 0.85f;
  too_loose.outline_on_edges = 0.3f;  // under the gate less the allowance (0.156 at 0.85)
  const auto refusal = [&](const Detection& d, const PickParams& params) {
    const PickPlan plan = planPicks({d}, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, params);
    return plan.detections.at(0).valid.empty() ? plan.detections.at(0).refused.at(0).reason : std::string();
  };
  EXPECT_EQ(refusal(coloured, {}), "") << "its colour was measured and passed: 34 % of the outline is enough";
  EXPECT_NE(refusal(uncoloured, {}).find("for 45.0 % of it (a pick needs 50 %)"), std::string::npos)
      << "no colour measured (a mesh without colours): the whole gate";
  EXPECT_NE(refusal(too_loose, {}).find("for 30.0 % of it (a pick needs 34 %, its colour having passed)"),
            std::string::npos)
      << refusal(too_loose, {});
  // The allowance grows with the colour's agreement: all of it at 1, none at 0.6.
  Detection full = too_loose, barely = coloured;
  full.colour_agreement = 1.f;
  EXPECT_EQ(refusal(full, {}), "") << "colours that agree fully: 25 % of the outline is enough";
  PickParams low_gate;  // a gate under the allowance's start: a colour that passed it at 0.6 earns nothing
  low_gate.min_colour_agreement = 0.5f;
  barely.colour_agreement = 0.6f;
  EXPECT_NE(refusal(barely, low_gate).find("(a pick needs 50 %, its colour having passed)"), std::string::npos)
      << refusal(barely, low_gate);
  PickParams no_allowance;
  no_allowance.colour_outline_allowance = 0.f;
  EXPECT_NE(refusal(coloured, no_allowance), "");
  PickParams colour_gate_off;  // a colour that no gate asked about vouches for nothing
  colour_gate_off.min_colour_agreement = 0.f;
  EXPECT_NE(refusal(coloured, colour_gate_off), "");
  Detection failed = coloured;  // a colour that failed vouches for nothing either
  failed.colour_agreement = 0.3f;
  EXPECT_NE(refusal(failed, {}).find("(a pick needs 50 %)"), std::string::npos) << refusal(failed, {});
}

TEST(Picking, TheTruthTellsWhetherAnythingCouldBeTaken) {
  const TemplateBank bank = canBank();
  const std::vector<Grasp> grasps = expandBySymmetry(parseGrasps(kSideGrasp, "can.json").grasps, bank, 36);
  // A can in the open: the true pose can be taken.
  const PickPlan open = truthPickPlan({{0, lyingCan(0.f)}}, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, {});
  ASSERT_EQ(open.picks.size(), 1u);
  EXPECT_EQ(open.picks[0].detection, 0);
  EXPECT_EQ(open.detections.size(), 1u);
  // Under a board (the depth image 10 cm in front of it): nothing can be taken.
  const cv::Mat board(480, 640, CV_32F, cv::Scalar(0.70f));
  EXPECT_TRUE(truthPickPlan({{0, lyingCan(0.f)}}, {bank}, {grasps}, board, camera(), std::nullopt, {}).picks.empty());
  // Less visible than asked for: an obstacle only. The other can, in sight, is taken.
  const std::vector<TruthInstance> two = {{0, lyingCan(0.f), 0.3f}, {0, lyingCan(0.f, 0.2f), 0.9f}};
  const PickPlan seen = truthPickPlan(two, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, {}, 0.6f);
  ASSERT_EQ(seen.picks.size(), 1u);
  EXPECT_EQ(seen.picks[0].detection, 1);
  EXPECT_TRUE(truthPickPlan({two[0]}, {bank}, {grasps}, cv::Mat(), camera(), std::nullopt, {}, 0.6f).picks.empty());
}

}  // namespace
}  // namespace vkpose
