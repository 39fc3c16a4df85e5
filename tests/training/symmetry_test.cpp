// Near-symmetries (issue 20, deliverable 2): found from the mesh at training, stored in the
// bank, and decided by appearance after ICP.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <filesystem>

#include "mesh_support.hpp"
#include "pose/appearance.hpp"
#include "render/render.hpp"
#include "synth/procedural_meshes.hpp"
#include "synth/scene.hpp"
#include "test_support.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/synth.hpp"

namespace vkpose {
namespace {

bool hasTurn(const std::vector<NearSymmetry>& found, const Eigen::Vector3f& axis, float angle_deg) {
  for (const auto& s : found)
    if (std::abs(std::abs(s.axis.dot(axis)) - 1.f) < 1e-3f &&
        (std::abs(s.angle_deg - angle_deg) < 0.5f || (s.axis.dot(axis) < 0 && std::abs(360.f - s.angle_deg - angle_deg) < 0.5f)))
      return true;
  return false;
}

TEST(NearSymmetries, ASquarePrismTurnsByQuartersAboutItsAxisAndHalvesAcross) {
  const Mesh prism = test::boxMesh({0.06f, 0.06f, 0.2f}, {0.01f, -0.02f, 0.1f});
  const auto found = findNearSymmetries(prism, 0.002f, 16);
  for (const float a : {90.f, 180.f, 270.f}) EXPECT_TRUE(hasTurn(found, Eigen::Vector3f::UnitZ(), a)) << a;
  EXPECT_TRUE(hasTurn(found, Eigen::Vector3f::UnitX(), 180.f));
  EXPECT_TRUE(hasTurn(found, Eigen::Vector3f::UnitY(), 180.f));
  EXPECT_FALSE(hasTurn(found, Eigen::Vector3f::UnitX(), 90.f));  // the long side would stick out
  EXPECT_FALSE(hasTurn(found, Eigen::Vector3f::UnitZ(), 60.f));
  for (const auto& s : found) {
    EXPECT_LT(s.deviation_m, 0.002f) << describe(s);
    // The turn keeps the box where it is: its centre maps onto itself.
    const Pose t = s.transform();
    EXPECT_LT((t.R * prism.bboxCentre() + t.t - prism.bboxCentre()).norm(), 1e-4f) << describe(s);
  }
}

TEST(NearSymmetries, AFlatBoxOnlyHalfTurnsAndAnLShapeNone) {
  const auto flat = findNearSymmetries(test::boxMesh({0.04f, 0.08f, 0.2f}), 0.002f, 16);
  EXPECT_TRUE(hasTurn(flat, Eigen::Vector3f::UnitZ(), 180.f));
  EXPECT_FALSE(hasTurn(flat, Eigen::Vector3f::UnitZ(), 90.f));
  EXPECT_EQ(flat.size(), 3u);  // 180 about each axis
  EXPECT_TRUE(findNearSymmetries(test::lShapeMesh(), 0.002f).empty());
  EXPECT_TRUE(findNearSymmetries(test::boxMesh({0.06f, 0.06f, 0.2f}), 0.f).empty());  // switched off
}

/// A mesh with its faces painted by the axis they face (as scripts/paint_mesh.py paints):
/// vertices repeated per face so that each keeps its colour.
Mesh painted(const Mesh& mesh) {
  static const Eigen::Vector3f colours[6] = {{0.78f, 0.16f, 0.16f}, {0.16f, 0.67f, 0.24f}, {0.2f, 0.31f, 0.82f},
                                             {0.9f, 0.78f, 0.16f},  {0.92f, 0.92f, 0.92f}, {0.47f, 0.24f, 0.59f}};
  Mesh out;
  out.name = mesh.name;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3f a = mesh.vertices[f[0]], b = mesh.vertices[f[1]], c = mesh.vertices[f[2]];
    const Eigen::Vector3f n = (b - a).cross(c - a);
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    const int base = static_cast<int>(out.vertices.size());
    for (const auto& v : {a, b, c}) {
      out.vertices.push_back(v);
      out.colours.push_back(colours[2 * axis + (n[axis] >= 0 ? 0 : 1)]);
    }
    out.faces.emplace_back(base, base + 1, base + 2);
  }
  finishMesh(out);
  return out;
}

// Exact symmetries (what synth writes as BOP's symmetries_discrete): turns that map every vertex
// onto a vertex of its colour. The spark-plug key's half-turn about its socket; a plain box's
// three half-turns, but none of the same box painted by face; none of an L.
TEST(NearSymmetries, ExactSymmetriesAreTurnsThatGiveTheSamePicture) {
  const Mesh key = partMeshes()[3];
  ASSERT_EQ(key.name, "spark_plug_key");
  const auto key_turns = exactSymmetries(key, 0.002f * key.diameter);
  ASSERT_EQ(key_turns.size(), 1u);
  EXPECT_TRUE(hasTurn(key_turns, Eigen::Vector3f::UnitZ(), 180.f)) << describe(key_turns[0]);
  const Mesh box = test::boxMesh({0.04f, 0.08f, 0.2f});
  EXPECT_EQ(exactSymmetries(box, 1e-4f).size(), 3u);
  EXPECT_TRUE(exactSymmetries(painted(box), 1e-4f).empty());
  EXPECT_TRUE(exactSymmetries(test::lShapeMesh(), 1e-4f).empty());
  // The cup's turns about its axis fit 90 % of its surface; its handle is no symmetry.
  const Mesh cup = test::meshOrStandIn("meshes/coffee_cup.stl", MeshUnits::Metres);
  EXPECT_TRUE(exactSymmetries(cup, 0.002f * cup.diameter).empty());
}

/// The scene a camera sees of `mesh` at `pose`: its colours shaded by how squarely each face
/// meets the camera and tinted (a light that is not white), on a far wall.
struct SeenScene {
  cv::Mat bgr, depth;
};
SeenScene seen(const Mesh& mesh, const Camera& camera, const Pose& pose) {
  const Rendering r = renderReference(mesh, camera, pose);
  SeenScene s;
  s.depth = cv::Mat(r.depth.size(), CV_32FC1, cv::Scalar(1.5f));
  s.bgr = cv::Mat(r.bgr.size(), CV_8UC3, cv::Scalar(90, 90, 90));
  for (int y = 0; y < r.depth.rows; ++y)
    for (int x = 0; x < r.depth.cols; ++x) {
      if (r.depth.at<float>(y, x) <= 0.f) continue;
      s.depth.at<float>(y, x) = r.depth.at<float>(y, x);
      const float shade = 0.5f + 0.5f * std::abs(r.normals.at<cv::Vec3f>(y, x)[2]);
      const cv::Vec3b c = r.bgr.at<cv::Vec3b>(y, x);
      const float tint[3] = {0.8f, 0.95f, 1.f};  // B, G, R
      for (int k = 0; k < 3; ++k) s.bgr.at<cv::Vec3b>(y, x)[k] = cv::saturate_cast<uint8_t>(c[k] * shade * tint[k]);
    }
  return s;
}

TEST(Appearance, ColourTellsAPaintedPrismsTurnsApartAndDepthCannot) {
  const Mesh grey = test::boxMesh({0.06f, 0.06f, 0.16f});
  const Mesh prism = painted(grey);
  const Camera camera;  // 640x480
  Pose truth;
  truth.R = (Eigen::AngleAxisf(0.5f, Eigen::Vector3f::UnitX()) * Eigen::AngleAxisf(0.6f, Eigen::Vector3f::UnitZ()))
                .toRotationMatrix();
  truth.t = {0.02f, -0.01f, 0.7f};
  const SeenScene scene = seen(prism, camera, truth);
  const cv::Rect frame(0, 0, camera.width, camera.height);
  const auto compare = [&](const Mesh& mesh, const Pose& pose) {
    return appearanceAgreement(renderReference(mesh, camera, pose), frame, scene.bgr, scene.depth, 0.01f,
                               meshChromaSpread(mesh) >= kMinChromaSpread);
  };
  const AppearanceAgreement right = compare(prism, truth);
  EXPECT_TRUE(right.colour_informative);
  EXPECT_GT(right.depth_fit, 0.98f);
  EXPECT_GT(right.colour, 0.95f);
  for (const auto& s : findNearSymmetries(grey, 0.002f, 16)) {
    const Pose turned = compose(truth, s.transform());
    const AppearanceAgreement wrong = compare(prism, turned);
    EXPECT_GT(wrong.depth_fit, 0.95f) << describe(s);  // the shape cannot tell
    EXPECT_LT(wrong.colour, 0.6f) << describe(s);
    EXPECT_GT(right.score, wrong.score + 0.15f) << describe(s);
    // Uncoloured, the mesh renders grey: nothing to compare but depth, and the turns tie.
    const AppearanceAgreement blind = compare(grey, turned);
    EXPECT_FALSE(blind.colour_informative);
    EXPECT_NEAR(blind.score, compare(grey, truth).score, 0.05f) << describe(s);
  }
  // Seen square-on, a face shows one colour: the means tell the faces apart (a box lying
  // down shows one painted side), on the same scale as the painted alternatives above.
  Pose face_on;
  face_on.R = Eigen::AngleAxisf(EIGEN_PI / 2, Eigen::Vector3f::UnitX()).toRotationMatrix();
  face_on.t = {0.f, 0.f, 0.6f};
  const SeenScene face_scene = seen(prism, camera, face_on);
  const auto compareFace = [&](const Pose& pose) {
    return appearanceAgreement(renderReference(prism, camera, pose), frame, face_scene.bgr, face_scene.depth, 0.01f,
                               true);
  };
  const AppearanceAgreement face_right = compareFace(face_on);
  EXPECT_GT(face_right.colour, 0.7f);
  for (const float angle : {90.f, 180.f}) {
    const Pose turned = compose(face_on, Pose{Eigen::AngleAxisf(angle * EIGEN_PI / 180.f, Eigen::Vector3f::UnitZ())
                                                  .toRotationMatrix(),
                                              Eigen::Vector3f::Zero()});
    const AppearanceAgreement face_wrong = compareFace(turned);
    EXPECT_GT(face_wrong.depth_fit, 0.95f) << angle;
    EXPECT_LT(face_wrong.colour, 0.4f) << angle;
    EXPECT_GT(face_right.score, face_wrong.score + 0.15f) << angle;
  }
  // Something in front hides the object: hidden pixels do not count against it.
  SeenScene occluded = scene;
  occluded.depth(cv::Rect(0, 0, camera.width / 2 + 20, camera.height)).setTo(0.3f);
  const AppearanceAgreement half =
      appearanceAgreement(renderReference(prism, camera, truth), frame, occluded.bgr, occluded.depth, 0.01f, true);
  EXPECT_LT(half.pixels, right.pixels);
  EXPECT_GT(half.depth_fit, 0.98f);
  EXPECT_THROW(appearanceAgreement(renderReference(prism, camera, truth), cv::Rect(0, 0, 10, 10), scene.bgr,
                                   scene.depth, 0.01f, true),
               InputError);
}

TEST(NearSymmetries, TheBankKeepsThem) {
  const Mesh prism = painted(test::boxMesh({0.06f, 0.06f, 0.16f}));
  TrainingParams params;
  params.views.viewpoints = 3;
  params.views.radii = {0.6f, 0.6f, 1.f};
  params.views.inplane_deg = {0.f, 0.f, 1.f};
  const TemplateBank bank = trainTemplates(test::context(), prism, params);
  // A square prism's seven turns: 90, 180, 270 about z; 180 about x, y and the two diagonals.
  ASSERT_EQ(bank.near_symmetries.size(), 7u);
  const std::string path = (std::filesystem::temp_directory_path() / "vkpose_symmetry_test.vkpb").string();
  saveBank(bank, path);
  const TemplateBank back = loadBank(path);
  std::filesystem::remove(path);
  ASSERT_EQ(back.near_symmetries.size(), bank.near_symmetries.size());
  for (std::size_t i = 0; i < bank.near_symmetries.size(); ++i) {
    EXPECT_EQ(back.near_symmetries[i].axis, bank.near_symmetries[i].axis);
    EXPECT_EQ(back.near_symmetries[i].point, bank.near_symmetries[i].point);
    EXPECT_EQ(back.near_symmetries[i].angle_deg, bank.near_symmetries[i].angle_deg);
  }
  params.near_symmetry_tolerance = 0.f;
  EXPECT_TRUE(trainTemplates(test::context(), prism, params).near_symmetries.empty());
  params.near_symmetry_tolerance = 0.5f;
  EXPECT_THROW(validateTrainingParams(params), InputError);
}

float angleDeg(const Eigen::Matrix3f& a, const Eigen::Matrix3f& b) {
  return Eigen::AngleAxisf(a.transpose() * b).angle() * 180.f / static_cast<float>(EIGEN_PI);
}

// The case: a juice carton, almost a square prism, painted so that its faces differ.
// ICP lands turned about the long axis about as often as not; colour turns it back.
TEST(NearSymmetries, ColourTurnsThePaintedCartonsBackAfterIcp) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const Mesh carton = painted(loadMesh(test::sharedData() + "/meshes/juicecarton.stl", MeshUnits::Metres));
  TrainingParams params;
  params.views.viewpoints = 100;
  params.views.radii = {0.7f, 0.9f, 0.1f};
  params.views.inplane_deg = {-20.f, 20.f, 10.f};
  params.views.up = findUpAxis(carton).up;
  const TemplateBank bank = test::cachedBank(carton, params);
  ASSERT_FALSE(bank.near_symmetries.empty());

  // Three cartons standing on a table, turned about their long axes, seen from 0.8 m at 45 degrees.
  const Camera camera = tejaniCamera();
  const Mesh table = planeMesh(1.2f);
  const TrainingView view = lookAtView(Eigen::Vector3f(0.f, -1.f, 1.f).normalized(), Eigen::Vector3f::Zero(), 0.8f, 0.f);
  const Pose world{view.R, view.t};
  std::vector<Pose> truth;
  std::vector<SceneObject> objects{{&table, world}};
  const float yaws[3] = {0.4f, 2.1f, 3.9f};
  const Eigen::Vector3f at[3] = {{-0.12f, 0.02f, 0.f}, {0.f, -0.05f, 0.f}, {0.13f, 0.03f, 0.f}};
  for (int k = 0; k < 3; ++k) {
    const Pose on_table{Eigen::AngleAxisf(yaws[k], Eigen::Vector3f::UnitZ()).toRotationMatrix(),
                        at[k] - Eigen::Vector3f(0.f, 0.f, carton.bbox_min.z())};
    truth.push_back(compose(world, on_table));
  }
  for (const auto& p : truth) objects.push_back({&carton, p});
  SceneRendering scene = renderScene(test::context(), objects, camera);
  Lighting light;
  light.direction = Eigen::Vector3f(0.3f, 0.5f, 1.f).normalized();
  light.gain = {0.9f, 1.f, 1.1f};
  applyLighting(scene, light);
  const LinemodFrame frame = sensorFrame(scene, synthNoise(), 7);

  const auto detectWith = [&](bool resolve) {
    DetectorParams dp;
    dp.verify.resolve_symmetries = resolve;
    if (!resolve) dp.verify.min_colour_agreement = -1.f;  // turned poses would fail it
    Detector detector(test::context(), {bank}, dp);
    return detector.detect(frame, camera);
  };
  const DetectionResult result = detectWith(true);
  int found = 0;
  for (const Detection& d : result.detections) {
    ASSERT_EQ(d.symmetry_alternatives.size(), 1 + bank.near_symmetries.size());
    EXPECT_GE(d.symmetry_chosen, 0);
    for (std::size_t k = 0; k < truth.size(); ++k) {
      if ((d.pose.t - truth[k].t).norm() > 0.02f) continue;
      ++found;
      EXPECT_LT(angleDeg(d.pose.R, truth[k].R), 10.f) << "carton " << k << ": chose alternative " << d.symmetry_chosen
                                                      << " by " << d.symmetry_margin;
      EXPECT_FALSE(d.ambiguous_symmetry);
    }
  }
  EXPECT_GE(found, 2) << result.detections.size() << " detections";
  const std::string json = detectionJson(result, {});
  EXPECT_NE(json.find("\"ambiguous_symmetry\": false"), std::string::npos);
  EXPECT_NE(json.find("\"alternatives\""), std::string::npos);

  // Without the check: how many cartons ICP left turned (for the record; not asserted, ICP's
  // basin decides).
  int turned = 0;
  for (const Detection& d : detectWith(false).detections)
    for (const auto& t : truth)
      if ((d.pose.t - t.t).norm() < 0.02f && angleDeg(d.pose.R, t.R) > 45.f) ++turned;
  std::printf("without the check, %d of 3 cartons stay turned\n", turned);

  // Look-alikes: the same cartons unpainted (a grey box of the carton's shape) fit the depth
  // as well, but none shows the bank's colours.
  const Mesh plain = loadMesh(test::sharedData() + "/meshes/juicecarton.stl", MeshUnits::Metres);
  for (std::size_t k = 1; k < objects.size(); ++k) objects[k].mesh = &plain;
  SceneRendering grey = renderScene(test::context(), objects, camera);
  applyLighting(grey, light);
  Detector detector(test::context(), {bank}, DetectorParams{});
  const DetectionResult look_alikes = detector.detect(sensorFrame(grey, synthNoise(), 7), camera);
  EXPECT_TRUE(look_alikes.detections.empty()) << look_alikes.detections.size() << " grey cartons taken for painted ones";
  int refused = 0;
  for (const Detection& d : look_alikes.rejected) refused += d.rejection.find("colours do not match") != std::string::npos;
  EXPECT_GE(refused, 2);
}

// What training finds at the default tolerance (3 % of the diameter): docs/pipeline.md, stage 0.
TEST(NearSymmetries, TheSharedMeshesAtTheDefaultTolerance) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string d = test::sharedData() + "/meshes/";
  const float share = TrainingParams{}.near_symmetry_tolerance;
  const auto find = [&](const char* name) {
    const Mesh mesh = loadMesh(d + name);
    return findNearSymmetries(mesh, share * mesh.diameter);
  };
  // The carton: a quarter, half and three-quarter turn about its long axis (z, a few degrees off).
  const auto carton = find("juicecarton.stl");
  ASSERT_EQ(carton.size(), 3u);
  for (const auto& s : carton) {
    EXPECT_GT(std::abs(s.axis.z()), 0.99f) << describe(s);
    EXPECT_TRUE(s.angle_deg == 90.f || s.angle_deg == 180.f || s.angle_deg == 270.f) << describe(s);
  }
  // The cup: turns about its axis (the handle is under a tenth of its surface).
  const auto cup = find("coffee_cup.stl");
  EXPECT_GE(cup.size(), 4u);
  for (const auto& s : cup) EXPECT_GT(std::abs(s.axis.z()), 0.99f) << describe(s);
  // The milk carton's gable top and spout break its half turn (9 mm off).
  EXPECT_TRUE(find("milk.stl").empty());
}

// Look-alike half-turns: beyond the near-symmetry tolerance, within 6 % of the diameter.
TEST(NearSymmetries, LookAlikeHalfTurnsAreTheCartonEndForEndAndTheJugFlankForFlank) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const std::string d = test::sharedData() + "/meshes/";
  const auto find = [&](const char* name) {
    const Mesh mesh = loadMesh(d + name);
    return findLookAlikeTurns(mesh, 0.03f * mesh.diameter, 0.06f * mesh.diameter);
  };
  // The carton end for end: a half-turn across its long axis (its gable top is not its base).
  const auto carton = find("juicecarton.stl");
  ASSERT_FALSE(carton.empty());
  for (const auto& s : carton) {
    EXPECT_EQ(s.angle_deg, 180.f);
    EXPECT_LT(std::abs(s.axis.z()), 0.1f) << describe(s);
  }
  // The jug flank for flank: a half-turn about its upright axis (the spout is off it).
  const auto milk = find("milk.stl");
  ASSERT_FALSE(milk.empty());
  EXPECT_GT(std::abs(milk.front().axis.z()), 0.95f) << describe(milk.front());
  for (const auto& s : milk) EXPECT_GT(s.deviation_m, 0.03f * loadMesh(d + "milk.stl").diameter);
  // A square prism's half-turns are exact: near-symmetries, not look-alikes.
  const Mesh prism = test::boxMesh({0.06f, 0.06f, 0.16f});
  EXPECT_TRUE(findLookAlikeTurns(prism, 0.03f * prism.diameter, 0.06f * prism.diameter).empty());
  EXPECT_TRUE(findLookAlikeTurns(prism, 0.06f, 0.03f).empty());
}

// A small part's look-alikes (VerifyParams::small_part_look_alike_tolerance): the demo's angle
// bracket at 40 mm, turned over about any axis, is several millimetres off, too far for 6 % of
// its diameter, yet at 0.3-0.45 m LINEMOD takes one for the other (the bracket bins' flipped
// false positives). Within half the diameter, the check gets its half-turns.
TEST(NearSymmetries, ASmallBracketTurnedOverIsALookAlike) {
  Mesh bracket = angleBracketMesh();
  for (auto& v : bracket.vertices) v *= 0.3f;
  finishMesh(bracket);
  ASSERT_LT(bracket.diameter, kSmallPartDiameterM);
  const DetectorParams defaults;
  const float from = 0.03f * bracket.diameter;
  EXPECT_TRUE(findLookAlikeTurns(bracket, from, defaults.verify.look_alike_tolerance * bracket.diameter).empty());
  const auto turns = findLookAlikeTurns(bracket, from, defaults.verify.small_part_look_alike_tolerance * bracket.diameter);
  ASSERT_GE(turns.size(), 2u);
  EXPECT_LE(turns.size(), 3u);
  for (const auto& s : turns) {
    EXPECT_EQ(s.angle_deg, 180.f);
    EXPECT_GT(s.deviation_m, 0.06f * bracket.diameter) << describe(s);
  }
}

// The lying carton (--resting all's +y hemisphere): its templates cannot tell the gable top
// from the flat base, so stage 6 settles either way up; the look-alike check turns it back.
TEST(NearSymmetries, LyingCartonsEndForEndAreTurnedBack) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const Mesh carton = painted(loadMesh(test::sharedData() + "/meshes/juicecarton.stl", MeshUnits::Metres));
  TrainingParams params;
  params.views.viewpoints = 100;
  params.views.radii = {0.7f, 0.9f, 0.1f};
  params.views.inplane_deg = {-20.f, 20.f, 10.f};
  params.views.up = Eigen::Vector3f::UnitY();
  const TemplateBank bank = test::cachedBank(carton, params);

  // Three cartons lying on their +y sides, turned every way on the table, seen from 0.8 m.
  const Camera camera = tejaniCamera();
  const Mesh table = planeMesh(1.2f);
  const TrainingView view = lookAtView(Eigen::Vector3f(0.f, -0.5f, 1.f).normalized(), Eigen::Vector3f::Zero(), 0.8f, 0.f);
  const Pose world{view.R, view.t};
  std::vector<Pose> truth;
  std::vector<SceneObject> objects{{&table, world}};
  const float yaws[3] = {0.3f, 2.4f, 4.4f};
  const Eigen::Vector3f at[3] = {{-0.14f, 0.05f, 0.f}, {0.03f, -0.08f, 0.f}, {0.15f, 0.06f, 0.f}};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Matrix3f R = Eigen::AngleAxisf(yaws[k], Eigen::Vector3f::UnitZ()).toRotationMatrix() *
                              Eigen::AngleAxisf(static_cast<float>(EIGEN_PI) / 2, Eigen::Vector3f::UnitX());
    truth.push_back(compose(world, Pose{R, at[k] - Eigen::Vector3f(0.f, 0.f, carton.bbox_min.y())}));
  }
  for (const auto& p : truth) objects.push_back({&carton, p});
  SceneRendering scene = renderScene(test::context(), objects, camera);
  Lighting light;
  light.direction = Eigen::Vector3f(0.3f, 0.5f, 1.f).normalized();
  applyLighting(scene, light);
  const LinemodFrame frame = sensorFrame(scene, synthNoise(), 11);

  const auto detectWith = [&](float look_alike_tolerance) {
    DetectorParams dp;
    dp.verify.look_alike_tolerance = look_alike_tolerance;
    Detector detector(test::context(), {bank}, dp);
    return detector.detect(frame, camera);
  };
  const DetectionResult result = detectWith(DetectorParams{}.verify.look_alike_tolerance);
  int found = 0;
  for (const Detection& d : result.detections) {
    ASSERT_GE(d.look_alike_alternatives.size(), 2u);  // the pose and at least one turn
    EXPECT_EQ(d.look_alike_alternatives.front().angle_deg, 0.f);
    EXPECT_EQ(d.look_alike_alternatives[1].angle_deg, 180.f);
    for (std::size_t k = 0; k < truth.size(); ++k) {
      if ((d.pose.t - truth[k].t).norm() > 0.02f) continue;
      ++found;
      EXPECT_LT(angleDeg(d.pose.R, truth[k].R), 10.f)
          << "carton " << k << ": look-alike " << d.look_alike_chosen << " by " << d.look_alike_margin;
    }
  }
  EXPECT_GE(found, 2) << result.detections.size() << " detections";
  EXPECT_NE(detectionJson(result, {}).find("\"look_alike_turns\""), std::string::npos);

  // Without it (for the record; stage 6 decides which way up ICP starts).
  int flipped = 0;
  for (const Detection& d : detectWith(0.f).detections) {
    EXPECT_TRUE(d.look_alike_alternatives.empty());
    for (const auto& t : truth)
      if ((d.pose.t - t.t).norm() < 0.03f && angleDeg(d.pose.R, t.R) > 45.f) ++flipped;
  }
  std::printf("without the look-alike check, %d of 3 lying cartons are found the wrong way round\n", flipped);
}

}  // namespace
}  // namespace vkpose
