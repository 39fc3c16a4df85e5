#pragma once
// Object meshes for training and rendering (DESIGN.md stage 0). Metres internally; the file's
// unit is explicit or inferred from the object's size.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace vkpose {

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

}  // namespace vkpose
