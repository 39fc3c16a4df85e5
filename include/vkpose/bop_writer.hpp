#pragma once
// Writing BOP datasets (https://github.com/thodan/bop_toolkit/blob/master/docs/bop_datasets_format.md),
// the counterpart of dataset.hpp's readers: metres and radians in, BOP's millimetres out. Every
// document is built in key order with fixed rounding, so the same data gives the same bytes.
#include <map>
#include <string>
#include <vector>

#include "vkpose/camera.hpp"
#include "vkpose/dataset.hpp"
#include "vkpose/mesh.hpp"

namespace vkpose {

/// A continuous rotational symmetry of a model (BOP's symmetries_continuous): the axis and a
/// point on it, object frame.
struct ContinuousSymmetry {
  Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f offset_m = Eigen::Vector3f::Zero();
};

/// One model of a dataset: its mesh (metres) and symmetries.
struct BopModel {
  int obj_id = 0;
  const Mesh* mesh = nullptr;
  std::vector<ContinuousSymmetry> symmetries;
};

/// Writes the mesh in millimetres as a binary little-endian PLY (x y z, nx ny nz, and red
/// green blue when it has colours; faces as uchar-counted int lists), what BOP's models/ hold.
/// InputError when the file exists and `overwrite` is false, or it cannot be written.
void writePlyMillimetres(const Mesh& mesh, const std::string& path, bool overwrite);

/// models_info.json: diameter, min_x.. and size_x.. in mm, and symmetries_continuous where
/// the model has any.
std::string modelsInfoJson(const std::vector<BopModel>& models);

/// camera.json: cx, cy, depth_scale, fx, fy, height, width.
std::string cameraJson(const Camera& camera);

/// scene_camera.json: per image cam_K (row-major 3x3) and depth_scale.
std::string sceneCameraJson(const std::map<int, Camera>& cameras);

/// scene_gt.json: per image the instances' cam_R_m2c (row-major), cam_t_m2c (mm) and obj_id.
std::string sceneGtJson(const std::map<int, std::vector<GroundTruthPose>>& gt);

/// scene_gt_info.json: per image the instances' bbox_obj, bbox_visib, px_count_all,
/// px_count_valid, px_count_visib and visib_fract.
std::string sceneGtInfoJson(const std::map<int, std::vector<GroundTruthInfo>>& info);

}  // namespace vkpose
