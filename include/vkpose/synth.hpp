#pragma once
// Synthetic multi-instance RGB-D datasets in BOP format (issue 6, `vkpose synth`): meshes at
// poses from Tejani et al.'s pose files or at random physically plausible placements, with a
// table, clutter that is not in the ground truth, lighting variation and a structured-light
// sensor's noise. The same parameters and seed give byte-identical files.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vkpose/camera.hpp"
#include "vkpose/gpu_context.hpp"
#include "vkpose/mesh.hpp"
#include "vkpose/placement.hpp"
#include "vkpose/scene.hpp"

namespace vkpose {

/// The PrimeSense camera of Tejani et al.'s sequences, whose poses the shared data holds.
Camera tejaniCamera();

/// A structured-light sensor's noise as synth adds it: DepthNoiseParams' defaults plus grazing
/// dropouts from 65 degrees, eight holes a frame and a 4 m range.
DepthNoiseParams synthNoise();

struct SynthParams {
  std::vector<std::string> meshes;          ///< obj_id = 1 + index
  MeshUnits units = MeshUnits::Auto;
  std::string poses = "random";             ///< "random", or a folder of Tejani pose files
  int images = 0;                           ///< 1 or more
  uint32_t seed = 0;
  int min_instances = 1, max_instances = 3;  ///< random: instances of each mesh per image
  int clutter = 4;                          ///< boxes and cylinders per image, not in the ground truth
  std::vector<int> symmetric;               ///< obj_ids with a continuous symmetry about their z axis
  Camera camera = tejaniCamera();
  DepthNoiseParams noise = synthNoise();
  PlacementParams placement;                ///< layout (table or bin) and its sizes
  CameraRange camera_range;                 ///< random: where the camera may be
};

/// InputError for parameters no dataset can come from (no mesh, images < 1, instances or
/// clutter out of range, a --symmetric obj_id without a mesh, poses neither "random" nor a
/// folder, the bin layout with pose files, a bad camera). Files are checked when read.
void validateSynthParams(const SynthParams& params);

/// The pose files for each mesh, sorted by their number N (posesN.txt): `dir` itself when it
/// holds pose files (one mesh only), otherwise the subfolder of `dir` named like each mesh's
/// stem, ignoring case, '_' and '-' (juicecarton.stl takes juice_carton/). InputError naming
/// the folder when a mesh has no folder or a folder no pose files.
std::vector<std::vector<std::string>> tejaniPoseFiles(const std::string& dir, const std::vector<std::string>& mesh_names);

/// What a run made.
struct SynthSummary {
  int images = 0;
  int instances = 0;        ///< ground-truth instances written
  int left_out = 0;         ///< random: instances that found no free place
  double ms_per_image = 0;  ///< rendering, noise and writing, per image
  std::vector<MeshLoadReport> mesh_reports;  ///< per mesh: the unit used and whether it was inferred
};

/// Writes the dataset under out_dir: models/obj_%06d.ply (mm) and models_info.json,
/// camera.json, and test/000001/ with rgb/, depth/ (16-bit PNG, mm, depth_scale 1),
/// scene_gt.json, scene_camera.json and scene_gt_info.json, images numbered from 0.
/// Tejani poses: image i shows mesh i % M at the poses of its (i / M)-th pose file, verbatim.
/// Random: each image a new camera, table or bin, instances, clutter, light and noise, from a
/// generator seeded with (seed, image). An out_dir that exists and is not empty is an
/// InputError unless `overwrite`, which first removes the paths synth writes there (models/,
/// test/000001/, camera.json) and nothing else. `progress(done, total)` after each image.
SynthSummary generateSyntheticDataset(const GpuContext& ctx, const SynthParams& params, const std::string& out_dir,
                                      bool overwrite, const std::function<void(int, int)>& progress = {});

/// One image of a random-placement dataset (poses "random"), made in memory from meshes
/// already loaded (metres): what generateSyntheticDataset would render as image `index` of
/// these meshes, drawn from the same generator seeded with (seed, index). Meshes without
/// vertex colours get synth's albedos. For benchmarks and tests that need a frame of a bank's
/// own mesh (TemplateBank::mesh) without writing files. InputError as validateSynthParams.
struct SynthImage {
  LinemodFrame frame;        ///< depth in millimetres
  Camera camera;             ///< params.camera, depth_scale 1
  std::vector<int> obj_ids;  ///< per ground-truth instance: 1 + index into the meshes
  std::vector<Pose> poses;   ///< per ground-truth instance: object-to-camera
};
SynthImage synthesizeImage(const GpuContext& ctx, const SynthParams& params, const std::vector<Mesh>& models,
                           int index);

}  // namespace vkpose
