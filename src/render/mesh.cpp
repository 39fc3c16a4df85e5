#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <stdexcept>
#include <string_view>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

// assimp 5.2 as Debian builds it keeps its internal checks (ai_assert) on, and their handler
// aborts the process: a PLY whose face list does not match its header reaches one in the
// triangulation step (fuzz_mesh). assimp calls the handler through its PLT, so this
// definition replaces it for the process and turns a failed check into an exception, which
// assimp's Importer::ReadFile catches and reports as a failed import (an InputError below).
namespace Assimp {
void aiAssertViolation(const char* failed, const char* file, int line) {
  throw std::runtime_error(fmt::format("assimp's internal check '{}' failed ({}:{})", failed, file, line));
}
}  // namespace Assimp

namespace vkpose {

MeshUnits parseMeshUnits(const std::string& text) {
  if (text == "mm") return MeshUnits::Millimetres;
  if (text == "m") return MeshUnits::Metres;
  if (text == "auto") return MeshUnits::Auto;
  throw InputError(fmt::format("unknown mesh units '{}': use mm, m or auto", text));
}

uint64_t fnv1a64(const void* data, std::size_t size, uint64_t seed) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  uint64_t h = seed;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= bytes[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

float exactDiameter(const std::vector<Eigen::Vector3f>& points) {
  if (points.size() < 2) return 0.f;
  Eigen::Vector3f lo = points[0], hi = points[0];
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3f c = 0.5f * (lo + hi);
  // Lower bound: the extreme points along 13 directions (axes, face and body diagonals).
  float best = 0.f;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = 0; dz <= 1; ++dz) {
        const Eigen::Vector3f d(static_cast<float>(dx), static_cast<float>(dy), static_cast<float>(dz));
        if (dz == 0 && (dy < 0 || (dy == 0 && dx <= 0))) continue;  // one of each +-d pair
        std::size_t imin = 0, imax = 0;
        for (std::size_t i = 1; i < points.size(); ++i) {
          const float s = d.dot(points[i]);
          if (s < d.dot(points[imin])) imin = i;
          if (s > d.dot(points[imax])) imax = i;
        }
        best = std::max(best, (points[imax] - points[imin]).norm());
      }
  // Exact search: |p - q| <= |p - c| + |q - c|, so with points sorted by distance from c,
  // the inner loop stops as soon as the two radii cannot beat the best pair found.
  std::vector<std::pair<float, std::size_t>> radii(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) radii[i] = {(points[i] - c).norm(), i};
  std::sort(radii.begin(), radii.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  float best_sq = best * best;
  for (std::size_t i = 0; i < radii.size(); ++i) {
    if (radii[i].first + radii[0].first < best) break;
    const Eigen::Vector3f& p = points[radii[i].second];
    for (std::size_t j = i + 1; j < radii.size(); ++j) {
      if (radii[i].first + radii[j].first < best) break;
      const float d2 = (p - points[radii[j].second]).squaredNorm();
      if (d2 > best_sq) {
        best_sq = d2;
        best = std::sqrt(d2);
      }
    }
  }
  return best;
}

namespace {
/// What every mesh must satisfy before it can be measured.
void checkMeshData(const Mesh& mesh) {
  if (mesh.faces.empty() || mesh.vertices.empty()) throw InputError(fmt::format("mesh '{}' has no triangles", mesh.name));
  const int n = static_cast<int>(mesh.vertices.size());
  for (const auto& v : mesh.vertices)
    if (!v.allFinite()) throw InputError(fmt::format("mesh '{}' has a NaN or infinite vertex", mesh.name));
  for (const auto& f : mesh.faces)
    if (f.minCoeff() < 0 || f.maxCoeff() >= n)
      throw InputError(fmt::format("mesh '{}' has a face with a vertex index out of range", mesh.name));
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.vertices.size())
    throw InputError(fmt::format("mesh '{}': {} normals for {} vertices", mesh.name, mesh.normals.size(), n));
  if (!mesh.colours.empty() && mesh.colours.size() != mesh.vertices.size())
    throw InputError(fmt::format("mesh '{}': {} colours for {} vertices", mesh.name, mesh.colours.size(), n));
}
}  // namespace

void finishMesh(Mesh& mesh) {
  checkMeshData(mesh);
  const int n = static_cast<int>(mesh.vertices.size());
  mesh.bbox_min = mesh.bbox_max = mesh.vertices[0];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& v : mesh.vertices) {
    mesh.bbox_min = mesh.bbox_min.cwiseMin(v);
    mesh.bbox_max = mesh.bbox_max.cwiseMax(v);
    sum += v.cast<double>();
  }
  mesh.centroid = (sum / n).cast<float>();
  mesh.diameter = exactDiameter(mesh.vertices);
  if (!(mesh.diameter > 0.f)) throw InputError(fmt::format("mesh '{}' has zero size", mesh.name));
  for (auto& nrm : mesh.normals) {
    const float len = nrm.norm();
    nrm = len > 0.f && std::isfinite(len) ? Eigen::Vector3f(nrm / len) : Eigen::Vector3f::Zero();
  }
}

namespace {
std::vector<char> readFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(fmt::format("{}: no such mesh file", path));
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw InputError(fmt::format("{}: cannot read the file", path));
  if (bytes.empty()) throw InputError(fmt::format("{}: the mesh file is empty", path));
  return bytes;
}

/// The bytes of a PLY scalar type; 0 for a name this check does not know.
std::size_t plyScalarBytes(std::string_view name) {
  std::string type(name);  // assimp reads the type names in any case
  std::transform(type.begin(), type.end(), type.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  uint64_t least = 0;       // bytes (binary) or values (ASCII) one instance takes at least
  std::vector<bool> lists;  // per property: a list (a count, then that many values)?
};

/// A refused header line as the error message quotes it: its tokens, at most 60 characters.
std::string quoted(const std::vector<std::string_view>& tokens) {
  return fmt::format("{}", fmt::join(tokens, " ")).substr(0, 60);
}

/// An "element" or "property" line of a PLY header, added to `elements`; a malformed one is
/// refused. Other lines are skipped, as assimp skips them.
void readPlyDeclaration(const std::vector<std::string_view>& t, bool ascii, const std::string& path,
                        std::vector<PlyElement>& elements) {
  if (t[0] == "element") {
    // A count assimp would read some other way (fuzz_mesh: digits run into the name, and
    // no count) is refused rather than left to it: it allocated 23 GB for one.
    PlyElement e;
    bool counted = t.size() == 3;
    if (counted) {
      const char* end = t[2].data() + t[2].size();
      const auto [ptr, ec] = std::from_chars(t[2].data(), end, e.count);
      counted = ec == std::errc{} && ptr == end;
    }
    if (!counted)
      throw InputError(fmt::format("{}: a PLY header line reads '{}', not 'element NAME COUNT'", path, quoted(t)));
    e.name = std::string(t[1]);
    elements.push_back(e);
  } else if (t[0] == "property") {
    // "property TYPE NAME", or "property list COUNT_TYPE ITEM_TYPE NAME": a list takes its
    // count at least (it may be empty). Anything else is refused, as a malformed element
    // line is: assimp read such a header its own way and then wild memory (fuzz_mesh).
    const bool list = t.size() == 5 && t[1] == "list";
    const std::size_t size = t.size() == 3 || list ? plyScalarBytes(list ? t[2] : t[1]) : 0;
    if (elements.empty() || size == 0 || (list && plyScalarBytes(t[3]) == 0))
      throw InputError(fmt::format("{}: a PLY header line reads '{}', not 'property TYPE NAME' or 'property list "
                                   "COUNT_TYPE TYPE NAME' of an element",
                                   path, quoted(t)));
    elements.back().least += ascii ? 1 : size;
    elements.back().lists.push_back(list);
  }
}

/// Whether the bytes after the header can hold the elements it declares.
void checkPlyRoom(const std::vector<PlyElement>& elements, uint64_t data, bool ascii, const std::string& path) {
  // ASCII: n values of a character each need n - 1 separators too, so n <= (bytes + 1) / 2.
  uint64_t room = ascii ? (data + 1) / 2 : data;
  for (const PlyElement& e : elements) {
    if (e.least == 0) continue;
    if (e.count > room / e.least)
      throw InputError(fmt::format("{}: the PLY header declares {} '{}' elements, more than the {} bytes after the "
                                   "header can hold (a truncated or corrupt file)",
                                   path, e.count, e.name, data));
    room -= e.count * e.least;
  }
}

/// Whether the tokens of an ASCII data line are exactly one instance of an element whose
/// properties are `lists` (true: a list, its count then that many values).
bool isOnePlyInstance(const std::vector<std::string_view>& t, const std::vector<bool>& lists) {
  std::size_t k = 0;
  for (const bool list : lists) {
    if (k >= t.size()) return false;
    uint64_t n = 0;
    if (list) {
      const auto [ptr, ec] = std::from_chars(t[k].data(), t[k].data() + t[k].size(), n);
      if (ec != std::errc{} || ptr != t[k].data() + t[k].size() || n > t.size() - k - 1) return false;
    }
    k += 1 + n;
  }
  return k == t.size();
}

/// Refuses kinds of PLY on which assimp 5.2 hangs or crashes instead of failing, found by
/// fuzz_mesh: a header without its end_header line (assimp loops at the end of the file for
/// ever), a malformed element or property line, a header declaring more element instances than
/// the data after it can hold (assimp sizes its arrays and loops by the declared counts
/// before it finds the data missing: 100 bytes declaring 50 million vertices take 600 MB and
/// half a minute), and ASCII data whose lines do not match the header. A file without a
/// format line it knows is left to assimp.
void checkPlyHeader(const std::vector<char>& bytes, const std::string& path) {
  const std::string_view text(bytes.data(), bytes.size());
  // assimp's own test: the first three bytes, in any case.
  if (text.size() < 3 || std::tolower(static_cast<unsigned char>(text[0])) != 'p' ||
      std::tolower(static_cast<unsigned char>(text[1])) != 'l' ||
      std::tolower(static_cast<unsigned char>(text[2])) != 'y')
    return;
  std::size_t pos = 0, line_number = 0;
  auto nextLine = [&](std::vector<std::string_view>& tokens) {
    if (pos >= text.size()) return false;
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    tokens.clear();
    for (std::size_t i = pos; i < end;) {
      if (std::isspace(static_cast<unsigned char>(text[i]))) {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < end && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
      tokens.push_back(text.substr(i, j - i));
      i = j;
    }
    pos = end + 1;
    ++line_number;
    return true;
  };
  std::vector<PlyElement> elements;
  bool ascii = false, known_format = false;
  std::vector<std::string_view> t;
  nextLine(t);  // the magic line
  for (;;) {
    if (!nextLine(t))
      throw InputError(fmt::format("{}: the PLY header has no end_header line (a truncated or corrupt file)", path));
    if (!t.empty() && t[0] == "end_header") break;
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "format" && t.size() >= 2) {
      ascii = t[1] == "ascii";
      known_format = ascii || t[1] == "binary_little_endian" || t[1] == "binary_big_endian";
    } else {
      readPlyDeclaration(t, ascii, path, elements);
    }
    // Other lines are skipped, as assimp skips them (Blender once wrote a bare text line).
  }
  if (!known_format) return;
  checkPlyRoom(elements, text.size() - std::min(pos, text.size()), ascii, path);
  if (!ascii) return;
  // assimp reads an ASCII instance from each line, and a line with fewer values than a
  // list's count makes it read face indices that are not there (fuzz_mesh: an invalid read
  // in a post-processing step). Every instance must be one line of exactly its values.
  for (const PlyElement& e : elements)
    for (uint64_t i = 0; i < e.count; ++i) {
      if (!nextLine(t))
        throw InputError(fmt::format("{}: the PLY data ends after {} of its {} '{}' elements", path, i, e.count, e.name));
      if (!isOnePlyInstance(t, e.lists))
        throw InputError(fmt::format("{}: line {} ('{}') is not one '{}' element as the PLY header declares it", path,
                                     line_number, fmt::format("{}", fmt::join(t, " ")).substr(0, 60), e.name));
    }
}
}  // namespace

Mesh loadMesh(const std::string& path, MeshUnits units, MeshLoadReport* report) {
  const std::vector<char> bytes = readFile(path);
  const std::string ext = std::filesystem::path(path).extension().string();
  Assimp::Importer importer;
  // STL stores one normal per facet: dropping it lets identical vertices join, and the
  // renderer then uses flat face normals, which is what a facetted STL means.
  std::string lower_ext = ext;
  std::transform(lower_ext.begin(), lower_ext.end(), lower_ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  const bool drop_normals = lower_ext == ".stl";
  // The STL and OBJ importers, which assimp picks by these extensions, never read a file as
  // PLY; any other name may reach assimp's PLY importer by the file's first bytes.
  if (lower_ext != ".stl" && lower_ext != ".obj") checkPlyHeader(bytes, path);
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, drop_normals ? static_cast<int>(aiComponent_NORMALS) : 0);
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                         aiProcess_SortByPType | aiProcess_ValidateDataStructure |
                         (drop_normals ? aiProcess_RemoveComponent : 0u);
  const aiScene* scene =
      importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags, lower_ext.empty() ? "" : lower_ext.c_str() + 1);
  if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode)
    throw InputError(fmt::format("{}: not a readable mesh ({})", path, importer.GetErrorString()));

  Mesh mesh;
  mesh.name = std::filesystem::path(path).stem().string();
  mesh.file_hash = fnv1a64(bytes.data(), bytes.size());
  bool all_normals = true, all_colours = true;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    all_normals = all_normals && am->HasNormals();
    all_colours = all_colours && am->HasVertexColors(0);
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const int base = static_cast<int>(mesh.vertices.size());
    for (unsigned i = 0; i < am->mNumVertices; ++i) {
      const aiVector3D& v = am->mVertices[i];
      mesh.vertices.emplace_back(v.x, v.y, v.z);
      if (all_normals) mesh.normals.emplace_back(am->mNormals[i].x, am->mNormals[i].y, am->mNormals[i].z);
      if (all_colours) {
        const aiColor4D& c = am->mColors[0][i];
        mesh.colours.emplace_back(std::clamp(c.r, 0.f, 1.f), std::clamp(c.g, 0.f, 1.f), std::clamp(c.b, 0.f, 1.f));
      }
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.faces.emplace_back(base + static_cast<int>(face.mIndices[0]), base + static_cast<int>(face.mIndices[1]),
                              base + static_cast<int>(face.mIndices[2]));
    }
  }
  // Checked and measured in the file's own units, which decide the unit when it is Auto;
  // millimetres are then scaled, measurements included.
  try {
    finishMesh(mesh);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path, e.what()));
  }
  const float file_diameter = mesh.diameter;
  MeshUnits used = units;
  if (units == MeshUnits::Auto) used = file_diameter > 10.f ? MeshUnits::Millimetres : MeshUnits::Metres;
  if (used == MeshUnits::Millimetres) {
    for (auto& v : mesh.vertices) v *= 0.001f;
    mesh.bbox_min *= 0.001f;
    mesh.bbox_max *= 0.001f;
    mesh.centroid *= 0.001f;
    mesh.diameter *= 0.001f;
  }
  if (mesh.diameter < 1e-3f || mesh.diameter > 10.f)
    throw InputError(fmt::format("{}: the object is {:.4g} m across in {}; vkpose handles 1 mm to 10 m (check --units)",
                                 path, mesh.diameter, used == MeshUnits::Millimetres ? "millimetres" : "metres"));
  if (report) *report = {used, units == MeshUnits::Auto, file_diameter};
  return mesh;
}

}  // namespace vkpose
