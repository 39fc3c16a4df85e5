// Training: in-plane rotations, LINEMOD feature selection from renderings, the orientation
// of templates (no mirrored or flipped views), the bank file, and detection with trained
// templates on the real LM-O frame.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "match/matcher.hpp"
#include "mesh_support.hpp"
#include "render/render.hpp"
#include "test_support.hpp"
#include "training/training.hpp"
#include "training/view_features.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

Camera squareCamera(int size) {
  Camera c;
  c.fx = c.fy = 573.0;
  c.cx = c.cy = size / 2;
  c.width = c.height = size;
  return c;
}

TEST(Training, InPlaneRotationOfARenderingEqualsRenderingTheRotatedView) {
  const Mesh l = test::lShapeMesh();
  MeshRenderer renderer(test::context(), l);
  const Camera cam = squareCamera(200);
  const TrainingView v0 = lookAtView({0.3f, -0.8f, 0.5f}, l.bboxCentre(), 0.6f, 0.f);
  const TrainingView v35 = lookAtView({0.3f, -0.8f, 0.5f}, l.bboxCentre(), 0.6f, 35.f);
  const auto r = renderer.render(cam, {{v0.R, v0.t}, {v35.R, v35.t}});
  const Rendering rotated = rotateInPlane(r[0], 35.f, cam.cx, cam.cy);
  int both = 0, either = 0, close = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const float a = rotated.depth.at<float>(y, x), b = r[1].depth.at<float>(y, x);
      either += a > 0 || b > 0;
      if (a > 0 && b > 0) {
        ++both;
        close += std::abs(a - b) < 1e-3f;
        const cv::Vec3f na = rotated.normals.at<cv::Vec3f>(y, x), nb = r[1].normals.at<cv::Vec3f>(y, x);
        close -= na.dot(nb) < 0.99f && std::abs(a - b) < 1e-3f;  // a face's normal turned wrongly
      }
    }
  ASSERT_GT(both, 2000);
  EXPECT_GT(both, either * 95 / 100) << "the rotated silhouette differs by more than its resampled edge";
  // Nearest-neighbour resampling moves depth steps and the box's 90-degree edges by up to a
  // pixel: the pixels next to them (about 1 in 20 on this small L) differ.
  EXPECT_GT(close, both * 90 / 100);
}

TEST(Training, FeaturesFollowLinemodSelection) {
  const Mesh cup = test::meshOrStandIn("meshes/coffee_cup.stl", MeshUnits::Metres);
  MeshRenderer renderer(test::context(), cup);
  const Camera cam = squareCamera(220);
  const TrainingView v = lookAtView({0.5f, -0.6f, 0.6f}, cup.bboxCentre(), 0.6f, 10.f);
  const Rendering r = renderer.render(cam, {{v.R, v.t}})[0];
  TrainingParams params;
  const ExtractedTemplate e = extractTemplate(r, params);
  ASSERT_TRUE(e.ok);
  ASSERT_EQ(e.linemod.levels.size(), 2u);
  cv::Mat mask = r.mask(), near_mask;
  cv::dilate(mask, near_mask, cv::Mat(), cv::Point(-1, -1), 2);
  for (std::size_t l = 0; l < 2; ++l) {
    const auto& level = e.linemod.levels[l];
    int colour = 0, depth = 0;
    for (const auto& f : level.features) {
      EXPECT_GE(f.x, 0);
      EXPECT_GE(f.y, 0);
      EXPECT_LE(f.x, level.width);
      EXPECT_LE(f.y, level.height);
      EXPECT_LT(f.bin, 8);
      const int x = (f.x << l) + e.origin_x, y = (f.y << l) + e.origin_y;
      if (f.modality == Modality::ColourGradient) {
        ++colour;
        EXPECT_GT(near_mask.at<uint8_t>(y, x), 0) << "colour feature away from the object";
      } else {
        ++depth;
        EXPECT_GT(mask.at<uint8_t>(y, x), 0) << "depth feature off the object";
      }
    }
    // 63 of each, unless the silhouette at half resolution has fewer 5x5 maxima than that
    // (OpenCV then refuses the whole view; vkpose keeps the template with what there is).
    if (l == 0) {
      EXPECT_EQ(colour, 63);
    }
    EXPECT_GE(colour, 16) << "level " << l;
    EXPECT_EQ(depth, 63) << "level " << l;
  }
  // Spread out: the 63 level-0 colour features are not bunched (mean nearest-neighbour
  // distance above a few pixels on a ~150 px object).
  double sum = 0;
  std::vector<cv::Point> pts;
  for (const auto& f : e.linemod.levels[0].features)
    if (f.modality == Modality::ColourGradient) pts.emplace_back(f.x, f.y);
  for (const auto& p : pts) {
    double best = 1e9;
    for (const auto& q : pts)
      if (p != q) best = std::min(best, cv::norm(p - q));
    sum += best;
  }
  EXPECT_GT(sum / pts.size(), 4.0);
}

// Every level's labels and magnitudes equal, bit for bit.
void expectSameQuantization(const QuantizedView& a, const QuantizedView& b, const std::string& what) {
  ASSERT_EQ(a.colour.size(), b.colour.size()) << what;
  auto same = [&](const cv::Mat& x, const cv::Mat& y, const std::string& name) {
    ASSERT_EQ(x.size(), y.size()) << what << " " << name;
    ASSERT_EQ(x.type(), y.type()) << what << " " << name;
    cv::Mat diff;
    cv::compare(x, y, diff, cv::CMP_NE);
    EXPECT_EQ(cv::countNonZero(diff), 0) << what << " " << name << " differs";
  };
  for (std::size_t l = 0; l < a.colour.size(); ++l) {
    const std::string level = fmt::format("level {}", l);
    same(a.colour[l], b.colour[l], level + " colour labels");
    same(a.magnitude[l], b.magnitude[l], level + " magnitudes");
    same(a.depth[l], b.depth[l], level + " depth labels");
  }
}

TEST(Training, GpuQuantizationOfPackedCropsEqualsTheReferenceOneByOne) {
  // Crops of several sizes (three distances, two objects, in-plane turns), packed into small
  // atlases so that they fill several shelves and several atlases.
  const Mesh cup = test::meshOrStandIn("meshes/coffee_cup.stl", MeshUnits::Metres);
  const Mesh l = test::lShapeMesh();
  const Camera cam = squareCamera(260);
  FeatureParams params;
  std::vector<Rendering> crops;
  for (const Mesh* mesh : {&cup, &l}) {
    MeshRenderer renderer(test::context(), *mesh);
    for (float distance : {0.5f, 0.7f, 0.9f}) {
      const TrainingView v = lookAtView({0.4f, -0.7f, 0.6f}, mesh->bboxCentre(), distance, 0.f);
      const Rendering r = renderer.render(cam, {{v.R, v.t}})[0];
      for (float turn : {0.f, 35.f}) {
        const Rendering turned = rotateInPlane(r, turn, cam.cx, cam.cy);
        const cv::Rect roi = featureCrop(cv::boundingRect(turned.mask()), {cam.width, cam.height}, params.T.size());
        crops.push_back({turned.depth(roi).clone(), turned.normals(roi).clone(), turned.bgr(roi).clone()});
      }
    }
  }
  std::vector<LinemodFrame> frames;
  for (const auto& c : crops) frames.push_back({c.bgr, depthMillimetres(c.depth)});
  ViewQuantizer quantizer(test::context(), params, 2048 * 400);
  const auto gpu = quantizer.quantize(frames);
  ASSERT_EQ(gpu.size(), crops.size());
  for (std::size_t i = 0; i < crops.size(); ++i)
    expectSameQuantization(gpu[i], quantizeView(crops[i], params), fmt::format("crop {}", i));
  // The quantizer keeps its buffers: a second, smaller call gives the same again.
  const auto again = quantizer.quantize({frames[3]});
  expectSameQuantization(again[0], gpu[3], "crop 3 quantized again");
}

TEST(Training, TheFeatureCropGivesTheWholeTilesTemplate) {
  // featureCrop's margin is small: the crop must still give what the whole tile gives.
  const Mesh cup = test::meshOrStandIn("meshes/coffee_cup.stl", MeshUnits::Metres);
  MeshRenderer renderer(test::context(), cup);
  const Camera cam = squareCamera(240);
  TrainingParams params;
  for (float turn : {0.f, 20.f, -50.f}) {
    const TrainingView v = lookAtView({-0.3f, -0.6f, 0.7f}, cup.bboxCentre(), 0.6f, 0.f);
    const Rendering r = rotateInPlane(renderer.render(cam, {{v.R, v.t}})[0], turn, cam.cx, cam.cy);
    const ExtractedTemplate cropped = extractTemplate(r, params);
    const cv::Rect whole(0, 0, cam.width, cam.height);
    const ExtractedTemplate full =
        selectFeatures(quantizeView(r, params.features), r.mask(), whole, cv::boundingRect(r.mask()), params);
    ASSERT_TRUE(cropped.ok);
    EXPECT_TRUE(cropped.linemod == full.linemod) << "turned " << turn;
    EXPECT_EQ(cropped.origin_x, full.origin_x);
    EXPECT_EQ(cropped.origin_y, full.origin_y);
  }
}

TEST(Training, TemplatesAreTheSameWhereverTheViewsAreQuantized) {
  const Mesh cup = test::meshOrStandIn("meshes/coffee_cup.stl", MeshUnits::Metres);
  TrainingParams params;
  params.views.viewpoints = 6;
  params.views.radii = {0.6f, 0.8f, 0.2f};
  params.views.inplane_deg = {-30.f, 30.f, 30.f};
  const auto views = sampleViews(params.views, cup.bboxCentre());
  const TemplateBank gpu = trainTemplatesWith(test::context(), cup, params, views, FeatureQuantization::gpu);
  const TemplateBank cpu = trainTemplatesWith(test::context(), cup, params, views, FeatureQuantization::cpu_reference);
  ASSERT_EQ(gpu.templates.size(), views.size());
  ASSERT_EQ(gpu.templates.size(), cpu.templates.size());
  for (std::size_t i = 0; i < gpu.templates.size(); ++i) {
    const BankTemplate &a = gpu.templates[i], &b = cpu.templates[i];
    EXPECT_TRUE(a.linemod == b.linemod) << "template " << i;
    EXPECT_EQ(a.anchor_x, b.anchor_x);
    EXPECT_EQ(a.anchor_y, b.anchor_y);
    EXPECT_EQ(a.crop.x0, b.crop.x0);
    EXPECT_EQ(a.crop.y0, b.crop.y0);
    EXPECT_EQ(a.crop.depth_01mm, b.crop.depth_01mm);
    EXPECT_EQ(a.crop.normals, b.crop.normals);
  }
}

TemplateBank smallLBank() {
  TrainingParams params;
  params.views.viewpoints = 10;
  params.views.radii = {0.5f, 0.6f, 0.1f};
  params.views.inplane_deg = {-40.f, 40.f, 20.f};
  params.features_per_modality = 30;
  return trainTemplates(test::context(), test::lShapeMesh(), params);
}

TEST(Training, TemplatesAreNotMirroredOrFlipped) {
  // Each template's pose, projected with the training focal length and the template's
  // anchor, must put the mesh's vertices onto the template's own rendered crop.
  const TemplateBank bank = smallLBank();
  const Mesh l = test::lShapeMesh();
  ASSERT_EQ(bank.templates.size(), 10u * 2u * 5u);
  const float f = static_cast<float>(0.5 * (bank.params.camera.fx + bank.params.camera.fy));
  for (const auto& t : bank.templates) {
    const TemplateCrop& c = t.crop;
    int on = 0;
    for (const auto& v : l.vertices) {
      const Eigen::Vector3f p = t.pose.R * v + t.pose.t;
      const float px = f * p.x() / p.z() + t.anchor_x, py = f * p.y() / p.z() + t.anchor_y;
      bool hit = false;
      const int cx = static_cast<int>(std::lround((px - c.x0) / c.stride)),
                cy = static_cast<int>(std::lround((py - c.y0) / c.stride));
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = cx + dx, y = cy + dy;
          if (x >= 0 && y >= 0 && x < c.cols && y < c.rows && c.depth_01mm[y * c.cols + x] > 0) hit = true;
        }
      on += hit;
    }
    EXPECT_EQ(on, static_cast<int>(l.vertices.size())) << "template at in-plane " << t.inplane_deg;
    // The centre's depth in the crop matches the training distance (within the object).
    EXPECT_NEAR(t.pose.t.norm(), t.distance, 0.1f);
  }
}

TEST(Bank, RoundTripsAndRejectsDamagedFiles) {
  const TemplateBank bank = smallLBank();
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/l.vkpb";
  saveBank(bank, path);
  const TemplateBank back = loadBank(path);
  EXPECT_EQ(back.object, bank.object);
  EXPECT_EQ(back.mesh_hash, bank.mesh_hash);
  EXPECT_FLOAT_EQ(back.diameter, bank.diameter);
  // The mesh travels with the bank (version 2): the pose stages render it.
  ASSERT_EQ(back.mesh.vertices.size(), bank.mesh.vertices.size());
  ASSERT_GT(back.mesh.faces.size(), 0u);
  EXPECT_EQ(back.mesh.faces, bank.mesh.faces);
  EXPECT_EQ(back.mesh.vertices, bank.mesh.vertices);
  EXPECT_FLOAT_EQ(back.mesh.diameter, bank.mesh.diameter);
  for (std::size_t i = 0; i < bank.templates.size(); ++i) {
    const auto &a = bank.templates[i], &b = back.templates[i];
    EXPECT_EQ(a.pose.R, b.pose.R);
    EXPECT_EQ(a.pose.t, b.pose.t);
    EXPECT_EQ(a.crop.depth_01mm, b.crop.depth_01mm);
    EXPECT_EQ(a.crop.normals, b.crop.normals);
    ASSERT_EQ(a.linemod.levels.size(), b.linemod.levels.size());
    for (std::size_t l = 0; l < a.linemod.levels.size(); ++l) {
      ASSERT_EQ(a.linemod.levels[l].features.size(), b.linemod.levels[l].features.size());
      EXPECT_EQ(a.linemod.levels[l].width, b.linemod.levels[l].width);
      for (std::size_t k = 0; k < a.linemod.levels[l].features.size(); ++k) {
        EXPECT_EQ(a.linemod.levels[l].features[k].x, b.linemod.levels[l].features[k].x);
        EXPECT_EQ(a.linemod.levels[l].features[k].bin, b.linemod.levels[l].features[k].bin);
      }
    }
  }
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto expectError = [&](const std::string& content, const std::string& words) {
    const std::string bad = dir + "/bad.vkpb";
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << content;
    try {
      loadBank(bad);
      ADD_FAILURE() << "expected an error mentioning '" << words << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.vkpb"), std::string::npos) << e.what();
    }
  };
  expectError(bytes.substr(0, bytes.size() / 2), "truncated");
  expectError(bytes.substr(0, 5), "truncated");
  expectError("", "not a vkpose template bank");
  expectError("solid cube\nendsolid\n", "not a vkpose template bank");
  std::string flipped = bytes;
  flipped[bytes.size() / 3] ^= 0x40;
  expectError(flipped, "checksum");
  std::string other_version = bytes;
  other_version[8] = 7;
  expectError(other_version, "version 7");
  expectError(bytes + "extra", "after its end");
  EXPECT_THROW(loadBank(dir + "/missing.vkpb"), InputError);
}

// ---- detection with trained templates on the real LM-O frame --------------------------

struct GroundTruth {
  int obj_id = 0;
  Pose pose;  // metres
  double visib_fract = 0;
};

std::vector<GroundTruth> lmoGroundTruth() {
  const std::string dir = test::sharedData() + "/lmo_scene2_frame3/test/000002";
  const auto gt = nlohmann::json::parse(std::ifstream(dir + "/scene_gt.json"))["3"];
  const auto info = nlohmann::json::parse(std::ifstream(dir + "/scene_gt_info.json"))["3"];
  std::vector<GroundTruth> out;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    GroundTruth g;
    g.obj_id = gt[i]["obj_id"];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) g.pose.R(r, c) = gt[i]["cam_R_m2c"][3 * r + c].get<float>();
      g.pose.t[r] = gt[i]["cam_t_m2c"][r].get<float>() / 1000.f;
    }
    g.visib_fract = info[i]["visib_fract"];
    out.push_back(g);
  }
  return out;
}

TEST(Training, LmoTemplatesFindTheirObjectsInTheRealFrame) {
  VKPOSE_REQUIRE_SHARED_DATA();
  const auto truth = lmoGroundTruth();
  const Camera camera = loadCamera(test::sharedData() + "/lmo_scene2_frame3/camera.json");
  const LinemodFrame frame = test::lmoFrame();
  // The views of a full-sphere bank (800 viewpoints, in-plane rotations 10 degrees apart) at
  // the object's true distance whose rotation is within 30 degrees of the truth: the
  // sampling a full bank has there, at a size a test trains in seconds.
  TrainingParams params;
  params.camera = camera;
  params.views.full_sphere = true;
  params.views.viewpoints = 800;
  params.views.inplane_deg = {-180.f, 170.f, 10.f};
  std::vector<TemplateBank> banks;
  std::vector<std::pair<std::size_t, std::size_t>> owner;  // (bank, template in it) per matcher id
  std::vector<LinemodTemplate> all;
  for (const auto& g : truth) {
    const Mesh mesh =
        loadMesh(fmt::format("{}/lmo_scene2_frame3/models/obj_{:06d}.ply", test::sharedData(), g.obj_id));
    const Eigen::Vector3f c = g.pose.R * mesh.bboxCentre() + g.pose.t;
    params.views.radii = {c.norm(), c.norm(), 1.f};
    std::vector<TrainingView> views;
    for (const auto& v : sampleViews(params.views, mesh.bboxCentre())) {
      const float angle = Eigen::AngleAxisf(Eigen::Matrix3f(v.R.transpose() * g.pose.R)).angle();
      if (angle < 30.f * 3.14159265f / 180.f) views.push_back(v);
    }
    ASSERT_FALSE(views.empty());
    banks.push_back(trainTemplatesFromViews(test::context(), mesh, params, views));
    for (std::size_t i = 0; i < banks.back().templates.size(); ++i) {
      all.push_back(banks.back().templates[i].linemod);
      owner.emplace_back(banks.size() - 1, i);
    }
  }
  MatchParams mp;
  mp.threshold = 80.f;
  LinemodMatcher matcher(test::context(), params.features, mp);
  matcher.setTemplates(all);
  const auto matches = matcher.match(frame);
  ASSERT_FALSE(matches.empty());
  int found = 0, visible = 0;
  for (std::size_t b = 0; b < banks.size(); ++b) {
    const GroundTruth& g = truth[b];
    const Eigen::Vector3f c = g.pose.R * banks[b].centre + g.pose.t;
    const Eigen::Vector2f centre = camera.project(c);
    // This object's matches, best first; the rank of the best one within 8 px of the truth.
    std::vector<float> scores;
    float best_near = -1;
    for (const auto& m : matches) {
      const auto [bank, index] = owner[m.template_id];
      if (bank != b) continue;
      scores.push_back(m.similarity);
      const auto& t = banks[b].templates[index];
      const float dx = m.x + t.anchor_x - centre.x(), dy = m.y + t.anchor_y - centre.y();
      if (dx * dx + dy * dy <= 64.f) best_near = std::max(best_near, m.similarity);
    }
    std::sort(scores.rbegin(), scores.rend());
    const std::size_t rank =
        best_near < 0 ? scores.size() : std::lower_bound(scores.begin(), scores.end(), best_near, std::greater<>()) - scores.begin();
    std::printf("obj %2d visible %3.0f%%: %5zu matches, best %.1f, best at the truth %.1f (rank %zu)\n", g.obj_id,
                100 * g.visib_fract, scores.size(), scores.empty() ? 0.f : scores[0], best_near, rank);
    // Half or more hidden (LM-O's ape at 20 %, the duck at 51 %): raw LINEMOD matching
    // cannot promise these; reported above, not asserted.
    if (g.visib_fract < 0.75) continue;
    ++visible;
    const bool among_best = best_near >= 0 && rank < std::max<std::size_t>(5, scores.size() / 20);
    EXPECT_TRUE(among_best) << "obj " << g.obj_id << ": the matches at its true position are not among its best";
    found += among_best;
  }
  EXPECT_EQ(visible, 6);
  EXPECT_EQ(found, visible);
}

}  // namespace
}  // namespace vkpose
