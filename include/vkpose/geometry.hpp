#pragma once
// The geometry every stage shares: object meshes (loaded with assimp; metres internally, the
// file's unit explicit or inferred from the object's size), object-to-camera poses, and pinhole
// camera intrinsics (read from BOP-style camera files).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace vkpose {

// ---- meshes ----------------------------------------------------------------------------

enum class MeshUnits { Auto, Millimetres, Metres };

/// Parses "mm", "m" or "auto"; throws InputError otherwise.
MeshUnits parseMeshUnits(const std::string& text);

/// A triangle mesh in metres. Vertices are shared between faces (identical vertices joined).
struct Mesh {
  std::string name;                      ///< the file's stem: the object's name in outputs
  std::vector<Eigen::Vector3f> vertices;  ///< metres, object frame
  std::vector<Eigen::Vector3f> normals;   ///< unit, one per vertex
  std::vector<Eigen::Vector3f> colours;   ///< RGB in 0..1, one per vertex; empty: no colour
  std::vector<Eigen::Vector3i> faces;     ///< counter-clockwise vertex indices
  uint64_t file_hash = 0;                 ///< FNV-1a 64 of the file's bytes (0 for generated meshes)
  float diameter = 0.f;                   ///< largest distance between two vertices, metres
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  ///< mean of the vertices
  Eigen::Vector3f bbox_min = Eigen::Vector3f::Zero(), bbox_max = Eigen::Vector3f::Zero();
  Eigen::Vector3f bboxCentre() const { return 0.5f * (bbox_min + bbox_max); }
};

/// What loadMesh decided about units, for the caller to tell the user.
struct MeshLoadReport {
  MeshUnits units = MeshUnits::Metres;  ///< the unit used (never Auto)
  bool inferred = false;                ///< true when Auto chose it
  float file_diameter = 0.f;            ///< diameter in the file's own units
};

/// Loads STL (binary or ASCII), PLY (vertex colours and normals are kept) or OBJ with assimp.
/// Auto units: a diameter over 10 file units means millimetres (no object vkpose handles is
/// 10 m across), otherwise metres. Throws InputError naming the file when it is missing or
/// unreadable, has no triangles, or has NaN/infinite vertices or a zero-size extent.
Mesh loadMesh(const std::string& path, MeshUnits units = MeshUnits::Auto, MeshLoadReport* report = nullptr);

/// Fills diameter (exact), centroid and bounding box, and makes the normals unit length. It
/// does not invent missing normals: a mesh without them (an STL) renders with flat face
/// normals, which is what a facetted file means. Throws InputError on an empty or non-finite
/// mesh.
void finishMesh(Mesh& mesh);

/// Exact largest distance between two points: candidates are pruned with a lower bound from
/// extreme points, the rest compared pairwise (exact, typically far below n^2 work).
float exactDiameter(const std::vector<Eigen::Vector3f>& points);

/// FNV-1a 64-bit hash of bytes, used for mesh identity and bank checksums.
uint64_t fnv1a64(const void* data, std::size_t size, uint64_t seed = 0xcbf29ce484222325ull);

// ---- poses and cameras ----------------------------------------------------------------

/// Object-to-camera pose: x_cam = R x_obj + t (metres).
struct Pose {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
};

/// compose(a_T_b, b_T_c) = a_T_c: x maps to a.R (b.R x + b.t) + a.t.
inline Pose compose(const Pose& a, const Pose& b) { return {a.R * b.R, a.R * b.t + a.t}; }
/// invert(a_T_b) = b_T_a.
inline Pose invert(const Pose& p) { return {p.R.transpose(), -(p.R.transpose() * p.t)}; }

/// Pinhole intrinsics rounded to float: what the GPU kernels take (push constants, e.g.
/// gpu::ScorePush) and what their CPU twins compute with. One rounding of each double, so a
/// kernel and its twin start from the same floats.
struct FloatIntrinsics {
  float fx = 0.f, fy = 0.f;  ///< focal lengths, pixels
  float cx = 0.f, cy = 0.f;  ///< principal point, pixels

  /// Pixel of camera-frame point p in float arithmetic, in this order: fx x / z + cx.
  Eigen::Vector2f project(const Eigen::Vector3f& p) const { return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy}; }
  /// The viewing ray through pixel (x, y) at depth 1 as the raster kernels compute it: times
  /// the focal lengths' float reciprocals, which is not always the float that dividing by
  /// them gives.
  Eigen::Vector3f ray(int x, int y) const {
    return {(static_cast<float>(x) - cx) * (1.0f / fx), (static_cast<float>(y) - cy) * (1.0f / fy), 1.0f};
  }
};

struct Camera {
  double fx = 572.4114, fy = 573.57043;  ///< focal lengths, pixels (default: the LINEMOD Kinect)
  double cx = 325.2611, cy = 242.04899;  ///< principal point, pixels
  int width = 640, height = 480;         ///< image size, pixels
  double depth_scale = 1.0;              ///< millimetres per depth-PNG unit (BOP)

  Eigen::Vector2f project(const Eigen::Vector3f& p) const {
    return {static_cast<float>(fx * p.x() / p.z() + cx), static_cast<float>(fy * p.y() / p.z() + cy)};
  }
  /// The intrinsics rounded to float (for GPU kernels and their CPU twins).
  FloatIntrinsics floatIntrinsics() const {
    return {static_cast<float>(fx), static_cast<float>(fy), static_cast<float>(cx), static_cast<float>(cy)};
  }
  /// Pixels spanned along the image's x axis by a length of size_m metres facing the camera at
  /// depth_m metres (float, in this order: size fx / depth): a projected diameter or radius.
  float pixelsAcross(float size_m, float depth_m) const { return size_m * static_cast<float>(fx) / depth_m; }
  /// Width and height, metres, that the whole image spans at depth depth_m (each image side
  /// over its focal length computed in double, rounded to float once).
  Eigen::Vector2f viewExtent(float depth_m) const {
    return {depth_m * static_cast<float>(width / fx), depth_m * static_cast<float>(height / fy)};
  }
  /// The viewing ray through pixel (x, y): the camera-frame point at depth 1 there (computed
  /// in double, rounded to float once).
  Eigen::Vector3f ray(double x, double y) const {
    return {static_cast<float>((x - cx) / fx), static_cast<float>((y - cy) / fy), 1.f};
  }
  /// The camera-frame point at pixel (x, y) with depth z (metres along the optical axis): the
  /// inverse of project.
  Eigen::Vector3f backProject(double x, double y, float z) const {
    const Eigen::Vector3f r = ray(x, y);
    return {r.x() * z, r.y() * z, z};
  }
};

/// Throws InputError when a focal length is not positive and finite, the principal point is
/// not finite, the size is not 1..16384, or the depth scale is not positive.
void validateCamera(const Camera& camera, const std::string& source = "camera");

/// Reads a BOP camera.json ({"fx", "fy", "cx", "cy", "width", "height", "depth_scale"} or
/// {"cam_K": [9 numbers], ...}) or one entry of a scene_camera.json (`entry`: its key; empty:
/// the first entry). Throws InputError naming the file and the missing or bad field.
Camera loadCamera(const std::string& path, const std::string& entry = "");

}  // namespace vkpose
