#include "mesh_support.hpp"

#include <map>

namespace vkpose::test {

Mesh boxMesh(const Eigen::Vector3f& size, const Eigen::Vector3f& centre) {
  Mesh m;
  m.name = "box";
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back(centre + 0.5f * Eigen::Vector3f((i & 1) ? size.x() : -size.x(), (i & 2) ? size.y() : -size.y(),
                                                         (i & 4) ? size.z() : -size.z()));
  // Two triangles per face, counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.faces.emplace_back(q[0], q[1], q[2]);
    m.faces.emplace_back(q[0], q[2], q[3]);
  }
  finishMesh(m);
  return m;
}

Mesh icosphere(float radius, int subdivisions) {
  const float p = (1.f + std::sqrt(5.f)) / 2.f;
  std::vector<Eigen::Vector3f> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                                    {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (auto& x : v) x.normalize();
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                    {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& t : f) {
      const int a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      next.insert(next.end(), {{t[0], a, c}, {t[1], b, a}, {t[2], c, b}, {a, b, c}});
    }
    f = std::move(next);
  }
  Mesh m;
  m.name = "sphere";
  for (const auto& x : v) {
    m.vertices.push_back(radius * x);
    m.normals.push_back(x);
  }
  m.faces = f;
  finishMesh(m);
  return m;
}

void appendMesh(Mesh& a, const Mesh& b) {
  const int base = static_cast<int>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& f : b.faces) a.faces.push_back(f + Eigen::Vector3i::Constant(base));
  a.normals.clear();
  a.colours.clear();
  finishMesh(a);
}

Mesh lShapeMesh() {
  Mesh m = boxMesh({0.12f, 0.03f, 0.03f}, {0.0f, 0.0f, 0.0f});
  appendMesh(m, boxMesh({0.03f, 0.08f, 0.03f}, {0.045f, 0.055f, 0.0f}));
  m.name = "lshape";
  return m;
}

}  // namespace vkpose::test
