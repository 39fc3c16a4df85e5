#pragma once
// Datasets with ground truth, for evaluation (DESIGN.md "Evaluation protocol"): the BOP format
// (https://github.com/thodan/bop_toolkit/blob/master/docs/bop_datasets_format.md) and the pose
// files of Tejani et al.'s multi-instance sequences. Files are in millimetres; everything
// returned here is in metres, poses object-to-camera (x_cam = R x_obj + t).
//
// Every reader throws InputError naming the file and, where there is one, the image, the
// instance and the field when a file is missing, is not valid JSON, or holds a wrong type, a
// missing field or a nonsense value (a rotation that is not one, a non-positive diameter).
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "vkpose/camera.hpp"
#include "vkpose/render.hpp"

namespace vkpose {

/// One annotated object instance of an image (BOP scene_gt.json, with visib_fract from
/// scene_gt_info.json when the dataset has it).
struct GroundTruthPose {
  int obj_id = 0;
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  ///< object-to-camera rotation (cam_R_m2c)
  Eigen::Vector3f t = Eigen::Vector3f::Zero();      ///< object-to-camera translation, metres
  float visib_fract = 1.f;                          ///< visible share of the object's silhouette, 0..1
};

/// One entry of a BOP scene_gt_info.json (the same order as the image's scene_gt.json list).
struct GroundTruthInfo {
  cv::Rect bbox_obj;        ///< box of the whole silhouette, pixels ([-1 -1 -1 -1] in BOP: none)
  cv::Rect bbox_visib;      ///< box of the visible part, pixels
  int px_count_all = 0;     ///< pixels of the whole silhouette
  int px_count_valid = 0;   ///< ... of which with a valid depth
  int px_count_visib = 0;   ///< visible pixels
  float visib_fract = 1.f;  ///< px_count_visib / px_count_all
};

/// One object of BOP's models_info.json.
struct ModelInfo {
  int obj_id = 0;
  float diameter = 0.f;                                 ///< largest distance between two model points, metres
  Eigen::Vector3f bbox_min = Eigen::Vector3f::Zero();   ///< min_x, min_y, min_z, metres
  Eigen::Vector3f bbox_size = Eigen::Vector3f::Zero();  ///< size_x, size_y, size_z, metres
  /// The file lists discrete or continuous symmetries: poses are scored with ADI, not ADD.
  bool symmetric = false;
};

/// One image of a BOP split with its camera and ground truth.
struct BopImage {
  int scene_id = 0, image_id = 0;
  std::string rgb_path, depth_path;  ///< rgb/%06d.png (or .jpg), depth/%06d.png
  Camera camera;                     ///< scene_camera.json's cam_K and depth_scale, size from camera.json
  std::vector<GroundTruthPose> gt;
  std::vector<GroundTruthInfo> gt_info;  ///< parallel to gt; empty when the scene has no scene_gt_info.json
};

/// A BOP dataset: models and the images of one split that have ground truth.
struct BopDataset {
  std::string root;
  std::string split;
  Camera camera;                    ///< the dataset's camera.json
  std::map<int, ModelInfo> models;  ///< by obj_id
  std::vector<BopImage> images;     ///< sorted by (scene_id, image_id)

  std::string modelPath(int obj_id) const;  ///< root/models/obj_%06d.ply
  /// root/models_eval/obj_%06d.ply (BOP's decimated models for pose errors) when it exists,
  /// otherwise modelPath(obj_id).
  std::string evalModelPath(int obj_id) const;
};

/// scene_gt.json: image id -> instances, in the file's order. visib_fract stays 1.
std::map<int, std::vector<GroundTruthPose>> loadSceneGt(const std::string& path);

/// scene_gt_info.json: image id -> per-instance visibility, in the file's order.
std::map<int, std::vector<GroundTruthInfo>> loadSceneGtInfo(const std::string& path);

/// scene_camera.json: image id -> camera. cam_K gives fx, fy, cx, cy and depth_scale the
/// depth scale when present; the image size and a missing depth_scale come from `base`.
std::map<int, Camera> loadSceneCamera(const std::string& path, const Camera& base = {});

/// models_info.json: obj_id -> diameter, box and symmetry flag, in metres.
std::map<int, ModelInfo> loadModelsInfo(const std::string& path);

/// Reads root/camera.json, root/models/models_info.json and every scene root/split/%06d/ with
/// its scene_gt.json and scene_camera.json (scene_gt_info.json optional: visib_fract 1 without
/// it). Images are those of scene_gt.json; each needs its camera entry, a depth PNG and an rgb
/// PNG or JPG, and every annotated obj_id must be in models_info.json.
BopDataset loadBopDataset(const std::string& root, const std::string& split = "test");

/// A pose file of Tejani et al. 2014 (posesN.txt): the number of instances on the first line,
/// then that many 4x4 row-major object-to-camera matrices, translation in metres. Throws
/// InputError with the file and the line when the count does not match the matrices, a value
/// is not a finite number, the last row is not 0 0 0 1, or R is not a rotation
/// (an entry of R^T R - I over 1e-2, or det R < 0). Rotations are returned as read, not
/// re-orthonormalized.
std::vector<Pose> loadTejaniPoses(const std::string& path);

}  // namespace vkpose
