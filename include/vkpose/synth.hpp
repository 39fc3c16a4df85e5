#pragma once
// Synthetic multi-instance RGB-D datasets in BOP format (`vkpose synth`): meshes at poses from
// Tejani et al.'s pose files or at random physically plausible placements on a table or in a
// bin, with clutter that is not in the ground truth, lighting variation and a structured-light
// sensor's noise; the same parameters and seed give byte-identical files. And `vkpose demo`:
// the whole pipeline on three objects built in code, piled in synthetic bins.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/picking.hpp"

namespace vkpose {

// ---- the sensor and the layout ---------------------------------------------------------

/// Structured-light depth noise: axial Gaussian noise growing with distance squared,
/// quantization, dropouts at depth edges and at grazing angles, and random holes (dark or
/// shiny patches the projector's pattern does not come back from). Grazing dropouts and holes
/// are off by default, which keeps the frames of callers that predate them as they were.
struct DepthNoiseParams {
  float axial_sigma_at_1m = 0.0015f;  ///< metres at 1 m; sigma(z) = this * z^2 (Kinect-like)
  float quantization_m = 0.001f;      ///< the sensor's depth step (16-bit PNG in mm)
  float edge_jump_m = 0.02f;          ///< a neighbour this much nearer or farther marks an edge
  float edge_dropout = 0.5f;          ///< chance that an edge pixel reads nothing
  float colour_sigma = 3.f;           ///< Gaussian noise on each colour channel, grey levels
  /// Surfaces seen more obliquely than this (angle between normal and viewing ray) start to
  /// lose readings; the chance grows linearly to grazing_dropout at 90 degrees.
  float grazing_start_deg = 70.f;
  float grazing_dropout = 0.f;        ///< chance of no reading at 90 degrees (0: off)
  int holes = 0;                      ///< random elliptic holes per frame (0: off)
  float hole_radius_px[2] = {3.f, 12.f};  ///< smallest and largest hole semi-axis, pixels
  float max_range_m = 0.f;            ///< readings farther than this are lost (0: no limit)
  /// A stereo or structured-light camera correlates a window of this many pixels a side: its
  /// depth at a pixel is the window's median surface (0 or 1: off). Corners come out rounded,
  /// depth edges ragged, and anything thinner than about half the window (a screw's shank, a
  /// wire) merges into what lies behind it.
  int matching_window_px = 0;
  /// Bare metal mirrors the projector's pattern away from the camera, or back into it so
  /// brightly that it saturates: where a metal surface faces the camera within this angle (the
  /// projector sits beside the lens), the chance of no reading is specular_dropout.
  float specular_lobe_deg = 20.f;
  float specular_dropout = 0.f;       ///< on metal only (SceneRendering::metal); 0: off
  /// Scattered dropouts all over metal (the pattern's dots lost on shiny, curved surfaces), in
  /// blobs of 2-4 pixels: this share of a metal surface reads nothing.
  float metal_dropout = 0.f;
};

enum class Layout { Table, Bin };

struct PlacementParams {
  Layout layout = Layout::Table;
  Eigen::Vector2f bin_inner_m{0.40f, 0.30f};  ///< inside of the bin along world x and y, centred at the origin
  float bin_wall_height_m = 0.15f;            ///< above the bin's floor (z = 0)
  float bin_wall_thickness_m = 0.01f;
  float gap_m = 0.002f;          ///< smallest clearance between two boxes
  float image_margin = 0.1f;     ///< table: objects stand this share of the image inside its border
  int tries = 200;               ///< positions tried per object before leaving it out
  float drop_step_m = 0.002f;    ///< bin: height step of the drop-and-settle search
  float bin_max_tilt_deg = 35.f; ///< bin: resting orientations tipped by up to this much
  float max_pile_m = 0.2f;       ///< bin: an object whose bottom settles higher than this is left out
  /// Only the resting orientation the mesh is modelled in (+z up), when it is stable: parts
  /// that were stacked standing (a tray of cups) rather than tipped out of a box.
  bool upright_only = false;
};

/// Where the camera may be: height of its centre above the table and tilt of its optical axis
/// from the vertical (a camera over a workcell: 0.6 to 1.2 m, tilted up to 35 degrees, the
/// table layout's camera).
struct CameraRange {
  float min_height_m = 0.6f, max_height_m = 1.2f;
  /// When max_distance_m > 0, the camera's distance along its optical axis to the point it
  /// looks at is drawn from [min_distance_m, max_distance_m] instead of its height (the height
  /// follows from the tilt): a bin-picking cell seeing small parts from 0.3-0.45 m.
  float min_distance_m = 0.f, max_distance_m = 0.f;
  float max_tilt_deg = 35.f;
  float max_roll_deg = 10.f;  ///< turn about the optical axis either way
  float target_jitter_m = 0.05f;  ///< the point looked at is this far from the origin at most
};

/// `synth --camera-distance FROM:TO`: the table camera's tilts and roll, with its distance along
/// the optical axis to the point it looks at drawn from [near_m, far_m] (metres) instead of its
/// height: the same draws as before the bin layout had a camera of its own, so such datasets come
/// out as they did.
CameraRange cameraAtDistances(float near_m, float far_m);

/// The bin layout's camera: a bin-picking cell's, mounted over the bin and looking down at it
/// (tilted up to 15 degrees), 0.8 to 1.0 m from the bin floor's centre, so that the parts in
/// the bin lie within the distances a bank trained at train's default --radii finds (its
/// 0.55-1.05 m). The table layout's camera, tilted up to 35 degrees and up to 1.2 m high,
/// sees a bin's far parts from 1.1-1.35 m and its near ones over the walls from 0.45 m.
CameraRange binCellCamera();

// ---- datasets -------------------------------------------------------------------------

/// The PrimeSense camera of Tejani et al.'s sequences, whose poses the shared data holds.
Camera tejaniCamera();

/// A structured-light sensor's noise as synth adds it: DepthNoiseParams' defaults plus grazing
/// dropouts from 65 degrees, eight holes a frame and a 4 m range.
DepthNoiseParams synthNoise();
/// The same with a sensor profile's axial noise and depth step (config.hpp's sensorProfile());
/// a noiseless profile ("ideal") also reads every pixel: no dropout at edges or grazing angles, no holes.
DepthNoiseParams synthNoise(const SensorParams& sensor);
/// `synth --sensor NAME`: synthNoise(sensorProfile(NAME)), and for "close-range" the rest of
/// closeRangeNoise().
DepthNoiseParams synthNoise(const std::string& sensor_name_or_file);
/// A D415-class active stereo camera over a bin at 0.3-0.5 m (`--sensor close-range`;
/// docs/evaluation.md says what each effect is based on): the profile's 2 mm at 1 m and 1 mm
/// step, a 9-pixel matching window (thin parts and corners lost), half of the depth-edge pixels
/// lost, holes where metal faces the camera and 15 % scattered dropouts on metal.
DepthNoiseParams closeRangeNoise();

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
  /// Bin layout: shrink the bin (inside and walls) to the parts and to what the camera sees
  /// from its nearest distance (fitBinToParts); off: placement's sizes as they are.
  bool fit_bin_to_parts = true;
  /// Random: where the camera may be; unset: the layout's own (CameraRange's defaults over a
  /// table, binCellCamera() over a bin). cameraRangeOf() says which.
  std::optional<CameraRange> camera_range;
  /// The parts (not the clutter, bin or table) are bare metal: grey, dim in diffuse light,
  /// with bright highlights from the light and from a lamp beside the lens, and, with a
  /// sensor that has them (closeRangeNoise), specular holes in their depth.
  bool metal_parts = false;
  /// A monochrome camera: the colour image's three channels are the same grey.
  bool greyscale = false;
  /// Random: per image, this many copies of the parts (a random mesh each) scaled by 0.8-0.9 or
  /// 1.1-1.2, placed among them and not in the ground truth: the next screw size, a smaller cup,
  /// look-alikes a detector must not report as the part. SCENE/scaled/IMAGE.json says where
  /// (loadScaledCopies); `vkpose eval` counts those reported.
  int scaled_copies = 0;
};

/// A copy of a part at another scale (SynthParams::scaled_copies): the mesh of `obj_id` scaled
/// about its own origin by `scale`, at `pose` (object-to-camera).
struct ScaledCopy {
  int obj_id = 0;
  float scale = 1.f;
  Pose pose;
};
/// The scaled copies synth wrote for an image of its dataset (SCENE/scaled/IMAGE.json), none
/// when it wrote none. InputError for a file that is not one.
std::vector<ScaledCopy> loadScaledCopies(const BopImage& image);
/// Of `copies`, how many a detection reports as the part: a detection of the copy's object
/// (banks_by_obj_id: obj_id -> index of its bank in `banks`) with a score of `min_score` or
/// more whose model centre lies within a quarter of the diameter of the copy's.
int scaledCopiesReported(const std::vector<ScaledCopy>& copies, const std::vector<Detection>& detections,
                         const std::vector<TemplateBank>& banks, const std::map<int, int>& banks_by_obj_id,
                         float min_score);

/// InputError for parameters no dataset can come from (no mesh, images < 1, instances or
/// clutter out of range, a --symmetric obj_id without a mesh, poses neither "random" nor a
/// folder, the bin layout with pose files, a bad camera). Files are checked when read.
void validateSynthParams(const SynthParams& params);

/// Where `params`' random camera may be: its camera_range, or its layout's own when unset.
CameraRange cameraRangeOf(const SynthParams& params);

/// A bin for parts of `diameter` metres (the largest) seen by `camera` from no nearer than
/// `range` allows: at most `placement`'s size, at least four parts across, and filling about 70 %
/// of the view there; the walls shrink with it (to 4 cm at the least). Sizes that fit already
/// (the default bin from 0.6 m and farther) come back unchanged.
PlacementParams fitBinToParts(const PlacementParams& placement, float diameter, const Camera& camera,
                              const CameraRange& range);

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
  /// The ground-truth instances' distances from the camera (their box centres, the point
  /// training's views look at), metres: what a bank's --radii must cover to find them all.
  float nearest_m = 0.f, farthest_m = 0.f;
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
  std::optional<BinBox> bin;  ///< the bin layout's bin
};
/// The bin `synth --layout bin` wrote for an image of its dataset (SCENE/bin/IMAGE.json, beside
/// rgb/ and depth/), when there is one.
std::optional<BinBox> loadSynthBin(const BopImage& image);

SynthImage synthesizeImage(const GpuContext& ctx, const SynthParams& params, const std::vector<Mesh>& models,
                           int index);

// ---- the demo -------------------------------------------------------------------------

struct DemoParams {
  std::string out_dir = "vkpose-demo";
  bool overwrite = false;  ///< replace out_dir's contents even when no earlier demo wrote it
  std::string cache_dir;   ///< where banks are cached; empty: no cache
  int images = 3;          ///< bin scenes
  uint32_t seed = 1;
  int min_instances = 2, max_instances = 2;  ///< of each object per scene
  /// Training views: the upper hemisphere's viewpoints within max_view_angle_deg of the top
  /// (the parts stand in the bin and the camera looks down), every in-plane turn.
  ViewSamplingParams views{216, false, {0.55f, 0.85f, 0.1f}, {-180.f, 170.f, 10.f}};
  float max_view_angle_deg = 40.f;
  DetectorParams detector;
};

/// InputError for parameters out of range (images < 1 or > 100, bad instance counts, ...).
void validateDemoParams(const DemoParams& params);

/// What each step reports as it goes, for the command line to print; every member may be empty.
struct DemoCallbacks {
  std::function<void(const std::string&)> step;                 ///< a step starts: "Training lidded_cup"
  std::function<void(std::size_t, std::size_t)> progress;       ///< within the step: (done, total)
  std::function<void(const std::string&)> info;                 ///< a line of detail
};

struct DemoObject {
  int obj_id = 0;
  std::string name, mesh_path, bank_path;
  std::size_t templates = 0;
  bool bank_from_cache = false;
  double train_s = 0;  ///< training (or reading the cached bank), seconds
};

struct DemoImageResult {
  int image_id = 0;
  std::string overlay_path, json_path;
  DetectionResult result;
};

struct DemoReport {
  std::string device;
  std::vector<DemoObject> objects;
  std::vector<DemoImageResult> images;
  EvalReport evaluation;
  int instances = 0;  ///< ground-truth instances in all scenes
  double synth_s = 0, train_s = 0, detect_s = 0, total_s = 0;
  std::string overlay_path, json_path, report_path;  ///< the first image's overlay and JSON, the score report
  std::vector<TemplateBank> banks;  ///< the objects' banks (obj_id order: a detection's bank index)
};

/// Runs the demo into params.out_dir: meshes/ (the objects, PLY), dataset/ (the bin scenes in
/// BOP format), overlays/ and detections/ (per image), overlay.png and detections.json (the
/// first image's, for a quick look), report.json (the scores) and results_vkpose.csv (BOP).
/// An out_dir that exists, is not empty and was not written by an earlier demo is an
/// InputError unless params.overwrite.
DemoReport runDemo(GpuContext& ctx, const DemoParams& params, const DemoCallbacks& callbacks = {});

/// `vkpose demo --pick`: each scene's picks, parallel to report.images: the demo's grasps are a
/// suction cup on the middle of each face of a part's box (faceSuctionGrasps), the bin the one
/// synth wrote into out_dir's dataset. Writes overlays/NNNNNN_picks.png and _picks.json.
std::vector<PickPlan> planDemoPicks(const DemoReport& report, const std::string& out_dir);

/// The demo's three objects (a lidded cup, a gable-top carton, an angle bracket with a hole),
/// built in code, metres, with vertex colours.
std::vector<Mesh> demoMeshes();

/// Writes demoMeshes() into `dir` (created if need be) as NAME.ply in millimetres, as the demo
/// and assets/meshes/ hold them; returns the paths. InputError when a file exists and
/// `overwrite` is false.
std::vector<std::string> writeDemoMeshes(const std::string& dir, bool overwrite);

/// Four small bare-metal parts of a pile, built in code, metres, steel grey: an M6 hex nut
/// (12.5 mm across), an M3 cap screw 48 mm long, a 58 mm nozzle and a 170 mm spark-plug key.
/// What issue 51's real frames held, for synthetic piles (`synth --sensor close-range --metal`).
std::vector<Mesh> partMeshes();
/// Writes partMeshes() into `dir` as writeDemoMeshes does (assets/parts/ holds them).
std::vector<std::string> writePartMeshes(const std::string& dir, bool overwrite);

}  // namespace vkpose
