// A program that uses vkpose through its public headers only (include/vkpose/), as a user's
// own code would: it renders a small synthetic dataset of a mesh, trains a template bank of
// the mesh, detects the object in the first image and scores every image with the paper's
// protocol. Built with the project (target vkpose_example) and run by ctest
// (Example.TrainDetectEvaluate), which is what keeps the public API sufficient.
//
//   vkpose_example MESH OUT_DIR      (e.g. ../shared/data/meshes/coffee_cup.stl)
#include <cstdio>
#include <exception>
#include <map>

#include "vkpose/vkpose.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s MESH OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    vkpose::GpuContext ctx;  // a GPU when there is one, lavapipe otherwise
    std::printf("vkpose %s on %s\n", vkpose::version().c_str(), ctx.device().name.c_str());

    // 1. Two synthetic table scenes of the mesh (BOP format, obj_id 1), reproducible from the seed.
    vkpose::SynthParams synth;
    synth.meshes = {argv[1]};
    synth.units = vkpose::MeshUnits::Auto;  // millimetres or metres, inferred from the size
    synth.images = 2;
    synth.seed = 7;
    synth.clutter = 2;
    synth.placement.upright_only = true;  // standing, as the upper-hemisphere templates see it
    const std::string dataset_dir = std::string(argv[2]) + "/dataset";
    vkpose::generateSyntheticDataset(ctx, synth, dataset_dir, /*overwrite=*/true);
    const vkpose::BopDataset dataset = vkpose::loadBopDataset(dataset_dir);

    // 2. A small bank: 40 viewpoints instead of the paper's 216, for the dataset's camera.
    vkpose::TrainingParams training;
    training.views.viewpoints = 40;
    training.camera = dataset.camera;
    const vkpose::Mesh mesh = vkpose::loadMesh(argv[1], vkpose::MeshUnits::Auto);
    vkpose::TemplateBank bank = vkpose::trainTemplates(ctx, mesh, training);
    vkpose::saveBank(bank, std::string(argv[2]) + "/object.vkpb");
    std::printf("trained %zu templates of %s (diameter %.3f m)\n", bank.templates.size(), bank.object.c_str(),
                bank.diameter);

    // 3. Detection on the first image, with the default stage parameters.
    const vkpose::BopImage& image = dataset.images.front();
    const vkpose::LinemodFrame frame = vkpose::loadFrame(image.rgb_path, image.depth_path, image.camera.depth_scale);
    vkpose::Detector detector(ctx, {bank}, vkpose::DetectorParams{});
    const vkpose::DetectionResult result = detector.detect(frame, image.camera);
    std::printf("image %d: %zu detections\n", image.image_id, result.detections.size());
    for (const vkpose::Detection& d : result.detections)
      std::printf("  %s score %.2f t = (%.3f, %.3f, %.3f) m\n", d.object.c_str(), d.score, d.pose.t.x(), d.pose.t.y(),
                  d.pose.t.z());

    // 4. The paper's protocol on every image (vkpose alone, not the baselines).
    vkpose::EvalRunParams eval;
    eval.methods = {vkpose::EvalMethod::Vkpose};
    const vkpose::EvalReport report = vkpose::runEvaluation(ctx, dataset, {{1, bank}}, eval);
    const vkpose::ObjectScores& scores = report.methods.front().summary.mean;
    std::printf("evaluated %d images: precision %.2f recall %.2f F1 %.2f\n", report.images, scores.precision,
                scores.recall, scores.f1);
    return 0;
  } catch (const vkpose::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  } catch (const vkpose::DeviceError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 3;
  }
}
