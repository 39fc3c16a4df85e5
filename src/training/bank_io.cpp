// The template bank file (.vkpb). Layout, little-endian:
//   "VKPOSEBK"  u32 version  u32 reserved  u64 payload bytes  payload  u64 FNV-1a 64 of all before
// The payload holds the object, its mesh (version 2: the pose stages render it, so a bank is
// all detection needs), the training parameters and every template (see writePayload()).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {

namespace {

constexpr char kMagic[8] = {'V', 'K', 'P', 'O', 'S', 'E', 'B', 'K'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8;

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void putString(const std::string& s) {
    put(static_cast<uint32_t>(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  template <class T>
  void putArray(const std::vector<T>& v) {
    const auto* p = reinterpret_cast<const char*>(v.data());
    bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
  }
  std::vector<char> bytes;
};

/// Reads the payload; every read is bounds-checked, so a damaged file is an error, not a crash.
class Reader {
 public:
  Reader(const char* data, std::size_t size, const std::string& path) : p_(data), end_(data + size), path_(path) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  std::string getString(uint32_t max_len = 4096) {
    const auto n = get<uint32_t>();
    if (n > max_len) fail(fmt::format("a name of {} bytes", n));
    need(n);
    std::string s(p_, n);
    p_ += n;
    return s;
  }
  template <class T>
  std::vector<T> getArray(std::size_t count) {
    if (count > static_cast<std::size_t>(end_ - p_) / sizeof(T)) fail("an array longer than the file");
    std::vector<T> v(count);
    // An empty vector's data() may be null, and memcpy from or to null is undefined even for
    // 0 bytes (UBSan, found by fuzz_bank: a bank whose mesh has no normals).
    if (count > 0) std::memcpy(v.data(), p_, count * sizeof(T));
    p_ += count * sizeof(T);
    return v;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: corrupt template bank ({})", path_, what));
  }
  bool done() const { return p_ == end_; }

 private:
  void need(std::size_t n) const {
    if (static_cast<std::size_t>(end_ - p_) < n) fail("it ends in the middle of a record");
  }
  const char* p_;
  const char* end_;
  std::string path_;
};

void writeRange(Writer& w, const SteppedRange& r) {
  w.put(r.from);
  w.put(r.to);
  w.put(r.step);
}

SteppedRange readRange(Reader& r) {
  SteppedRange s;
  s.from = r.get<float>();
  s.to = r.get<float>();
  s.step = r.get<float>();
  return s;
}

void writeMesh(Writer& w, const Mesh& mesh) {
  // Every array with its own count: normals and colours are optional or filled later.
  for (const auto* v : {&mesh.vertices, &mesh.normals, &mesh.colours}) {
    w.put(static_cast<uint32_t>(v->size()));
    w.putArray(*v);
  }
  w.put(static_cast<uint32_t>(mesh.faces.size()));
  w.putArray(mesh.faces);
}

/// count Eigen 3-vectors stored as 3 * count scalars.
template <class S>
std::vector<Eigen::Matrix<S, 3, 1>> getTriples(Reader& r, std::size_t count) {
  const std::vector<S> flat = r.getArray<S>(3 * count);
  std::vector<Eigen::Matrix<S, 3, 1>> out(count);
  for (std::size_t i = 0; i < count; ++i) out[i] = {flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]};
  return out;
}

Mesh readMesh(Reader& r, const std::string& name) {
  Mesh mesh;
  mesh.name = name;
  mesh.vertices = getTriples<float>(r, r.get<uint32_t>());
  mesh.normals = getTriples<float>(r, r.get<uint32_t>());
  mesh.colours = getTriples<float>(r, r.get<uint32_t>());
  mesh.faces = getTriples<int>(r, r.get<uint32_t>());
  const auto vertices = mesh.vertices.size();
  if (vertices < 3 || mesh.faces.empty())
    r.fail(fmt::format("a mesh with {} vertices and {} faces", vertices, mesh.faces.size()));
  if ((!mesh.normals.empty() && mesh.normals.size() != vertices) ||
      (!mesh.colours.empty() && mesh.colours.size() != vertices))
    r.fail("mesh normals or colours that do not match its vertices");
  for (const auto& f : mesh.faces)
    if ((f.array() < 0).any() || (f.array() >= static_cast<int>(vertices)).any())
      r.fail("a mesh face with a vertex index out of range");
  try {
    finishMesh(mesh);
  } catch (const InputError& e) {
    r.fail(e.what());
  }
  return mesh;
}

void writeParams(Writer& w, const TrainingParams& p) {
  w.put(static_cast<int32_t>(p.views.viewpoints));
  w.put(static_cast<uint8_t>(p.views.full_sphere));
  writeRange(w, p.views.radii);
  writeRange(w, p.views.inplane_deg);
  w.put(p.features.weak_threshold);
  w.put(static_cast<int32_t>(p.features.distance_threshold_mm));
  w.put(static_cast<int32_t>(p.features.difference_threshold_mm));
  w.put(static_cast<uint32_t>(p.features.T.size()));
  for (int T : p.features.T) w.put(static_cast<int32_t>(T));
  w.put(static_cast<uint8_t>(p.features.use_colour));
  w.put(static_cast<uint8_t>(p.features.use_depth));
  w.put(static_cast<int32_t>(p.features_per_modality));
  w.put(p.strong_threshold);
  for (double v : {p.camera.fx, p.camera.fy, p.camera.cx, p.camera.cy, p.camera.depth_scale}) w.put(v);
  w.put(static_cast<int32_t>(p.camera.width));
  w.put(static_cast<int32_t>(p.camera.height));
  for (int i = 0; i < 3; ++i) w.put(p.views.up[i]);  // version 3
  w.put(p.near_symmetry_tolerance);                   // version 4
  w.put(static_cast<uint32_t>(p.views.other_ups.size()));  // version 5
  for (const Eigen::Vector3f& up : p.views.other_ups)
    for (int i = 0; i < 3; ++i) w.put(up[i]);
  w.put(p.views.full_turn_within_deg);  // version 6
}

void writePayload(Writer& w, const TemplateBank& bank) {
  w.putString(bank.object);
  w.put(bank.mesh_hash);
  w.put(bank.diameter);
  w.put(static_cast<uint8_t>(bank.symmetric));
  for (int i = 0; i < 3; ++i) w.put(bank.centre[i]);
  writeMesh(w, bank.mesh);
  writeParams(w, bank.params);
  w.put(static_cast<uint32_t>(bank.templates.size()));
  for (const auto& t : bank.templates) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) w.put(t.pose.R(r, c));
    for (int i = 0; i < 3; ++i) w.put(t.pose.t[i]);
    w.put(t.distance);
    w.put(t.inplane_deg);
    w.put(static_cast<int32_t>(t.viewpoint));
    w.put(t.anchor_x);
    w.put(t.anchor_y);
    for (const auto& level : t.linemod.levels) {
      w.put(static_cast<int32_t>(level.width));
      w.put(static_cast<int32_t>(level.height));
      w.put(static_cast<uint32_t>(level.features.size()));
      for (const auto& f : level.features) {
        w.put(static_cast<int16_t>(f.x));
        w.put(static_cast<int16_t>(f.y));
        w.put(f.bin);
        w.put(static_cast<uint8_t>(f.modality));
      }
    }
    w.put(static_cast<int32_t>(t.crop.x0));
    w.put(static_cast<int32_t>(t.crop.y0));
    w.put(static_cast<int32_t>(t.crop.stride));
    w.put(static_cast<int32_t>(t.crop.cols));
    w.put(static_cast<int32_t>(t.crop.rows));
    w.putArray(t.crop.depth_01mm);
    w.putArray(t.crop.normals);
  }
  w.put(static_cast<uint32_t>(bank.near_symmetries.size()));  // version 4
  for (const auto& s : bank.near_symmetries) {
    for (int i = 0; i < 3; ++i) w.put(s.axis[i]);
    for (int i = 0; i < 3; ++i) w.put(s.point[i]);
    w.put(s.angle_deg);
    w.put(s.deviation_m);
  }
}

/// Template `i` of a bank of `levels` pyramid levels (saveBank's layout, docs/formats.md).
BankTemplate readTemplate(Reader& r, uint32_t i, uint32_t levels) {
  BankTemplate t;
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < 3; ++c) t.pose.R(row, c) = r.get<float>();
  for (int k = 0; k < 3; ++k) t.pose.t[k] = r.get<float>();
  t.distance = r.get<float>();
  t.inplane_deg = r.get<float>();
  t.viewpoint = r.get<int32_t>();
  t.anchor_x = r.get<float>();
  t.anchor_y = r.get<float>();
  t.linemod.levels.resize(levels);
  for (auto& level : t.linemod.levels) {
    level.width = r.get<int32_t>();
    level.height = r.get<int32_t>();
    const auto n = r.get<uint32_t>();
    if (n > 2 * 4096u) r.fail(fmt::format("template {} with {} features", i, n));
    level.features.resize(n);
    for (auto& f : level.features) {
      f.x = r.get<int16_t>();
      f.y = r.get<int16_t>();
      f.bin = r.get<uint8_t>();
      const auto m = r.get<uint8_t>();
      if (m >= kModalityCount) r.fail(fmt::format("template {}: modality {}", i, m));
      f.modality = static_cast<Modality>(m);
    }
  }
  t.crop.x0 = r.get<int32_t>();
  t.crop.y0 = r.get<int32_t>();
  t.crop.stride = r.get<int32_t>();
  t.crop.cols = r.get<int32_t>();
  t.crop.rows = r.get<int32_t>();
  // Training never makes a crop over kCropCells + 1 cells a side, and the cluster score's
  // kernel relies on it: its loops over a crop's cells run within lavapipe's 65,535-step
  // budget an invocation only for crops of about 180 x 180 cells or fewer (docs/measured.md).
  constexpr int max_cells = kCropCells + 1;
  if (t.crop.stride < 1 || t.crop.cols < 0 || t.crop.rows < 0 || t.crop.cols > max_cells || t.crop.rows > max_cells)
    r.fail(fmt::format("template {}: crop {}x{} stride {} (training makes at most {}x{})", i, t.crop.cols,
                       t.crop.rows, t.crop.stride, max_cells, max_cells));
  const std::size_t cells = static_cast<std::size_t>(t.crop.cols) * t.crop.rows;
  t.crop.depth_01mm = r.getArray<uint16_t>(cells);
  t.crop.normals = r.getArray<int8_t>(cells * 3);
  return t;
}

TemplateBank readPayload(Reader& r, const std::string& path, uint32_t version) {
  TemplateBank bank;
  bank.object = r.getString();
  bank.mesh_hash = r.get<uint64_t>();
  bank.diameter = r.get<float>();
  bank.symmetric = r.get<uint8_t>() != 0;
  for (int i = 0; i < 3; ++i) bank.centre[i] = r.get<float>();
  bank.mesh = readMesh(r, bank.object);
  bank.mesh.file_hash = bank.mesh_hash;
  TrainingParams& p = bank.params;
  p.views.viewpoints = r.get<int32_t>();
  p.views.full_sphere = r.get<uint8_t>() != 0;
  p.views.radii = readRange(r);
  p.views.inplane_deg = readRange(r);
  p.features.weak_threshold = r.get<float>();
  p.features.distance_threshold_mm = r.get<int32_t>();
  p.features.difference_threshold_mm = r.get<int32_t>();
  const auto levels = r.get<uint32_t>();
  if (levels < 1 || levels > 2) r.fail(fmt::format("{} pyramid levels", levels));
  p.features.T.clear();
  for (uint32_t l = 0; l < levels; ++l) p.features.T.push_back(r.get<int32_t>());
  p.features.use_colour = r.get<uint8_t>() != 0;
  p.features.use_depth = r.get<uint8_t>() != 0;
  p.features_per_modality = r.get<int32_t>();
  p.strong_threshold = r.get<float>();
  p.camera.fx = r.get<double>();
  p.camera.fy = r.get<double>();
  p.camera.cx = r.get<double>();
  p.camera.cy = r.get<double>();
  p.camera.depth_scale = r.get<double>();
  p.camera.width = r.get<int32_t>();
  p.camera.height = r.get<int32_t>();
  if (version >= 3) {
    for (int i = 0; i < 3; ++i) p.views.up[i] = r.get<float>();
    if (!p.views.up.allFinite() || std::abs(p.views.up.norm() - 1.f) > 1e-3f) r.fail("up axis is not a unit vector");
  }  // version 2 banks were all trained about +z
  if (version >= 4) p.near_symmetry_tolerance = r.get<float>();
  if (version >= 5) {  // older banks saw one hemisphere
    const auto ups = r.get<uint32_t>();
    if (ups > 5) r.fail(fmt::format("{} other resting poses", ups));
    p.views.other_ups.resize(ups);
    for (Eigen::Vector3f& up : p.views.other_ups)
      for (int i = 0; i < 3; ++i) up[i] = r.get<float>();
  }
  if (version >= 6) p.views.full_turn_within_deg = r.get<float>();  // older banks: the range everywhere
  try {
    validateTrainingParams(p);
  } catch (const InputError& e) {
    r.fail(e.what());
  }
  if (!(bank.diameter > 0.f)) r.fail("a diameter that is not positive");
  const auto count = r.get<uint32_t>();
  bank.templates.reserve(std::min<uint32_t>(count, 1u << 20));
  for (uint32_t i = 0; i < count; ++i) bank.templates.push_back(readTemplate(r, i, levels));
  if (version >= 4) {
    const auto symmetries = r.get<uint32_t>();
    if (symmetries > 64) r.fail(fmt::format("{} near-symmetries", symmetries));
    for (uint32_t i = 0; i < symmetries; ++i) {
      NearSymmetry s;
      for (int k = 0; k < 3; ++k) s.axis[k] = r.get<float>();
      for (int k = 0; k < 3; ++k) s.point[k] = r.get<float>();
      s.angle_deg = r.get<float>();
      s.deviation_m = r.get<float>();
      if (!s.axis.allFinite() || std::abs(s.axis.norm() - 1.f) > 1e-3f || !s.point.allFinite() ||
          !std::isfinite(s.angle_deg) || !std::isfinite(s.deviation_m))
        r.fail(fmt::format("near-symmetry {} is not a turn about a unit axis", i));
      bank.near_symmetries.push_back(s);
    }
  } else {
    // Older banks: the turns their mesh has, as training would find them now.
    bank.near_symmetries = findNearSymmetries(bank.mesh, p.near_symmetry_tolerance * bank.diameter);
  }
  if (!r.done()) r.fail("bytes left after the last template");
  try {
    validateTemplates(bank.linemodTemplates(), p.features);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: corrupt template bank ({})", path, e.what()));
  }
  return bank;
}

}  // namespace

void saveBank(const TemplateBank& bank, const std::string& path) {
  Writer payload;
  writePayload(payload, bank);
  Writer file;
  file.bytes.insert(file.bytes.end(), kMagic, kMagic + 8);
  file.put(kBankVersion);
  file.put(uint32_t{0});
  file.put(static_cast<uint64_t>(payload.bytes.size()));
  file.bytes.insert(file.bytes.end(), payload.bytes.begin(), payload.bytes.end());
  file.put(fnv1a64(file.bytes.data(), file.bytes.size()));
  // Write beside the target and rename, so a failed write never leaves half a bank behind.
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(fmt::format("{}: cannot write the template bank", path));
    out.write(file.bytes.data(), static_cast<std::streamsize>(file.bytes.size()));
    if (!out) {
      std::filesystem::remove(tmp);
      throw InputError(fmt::format("{}: writing the template bank failed (disk full?)", path));
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw InputError(fmt::format("{}: cannot write the template bank ({})", path, ec.message()));
  }
}

TemplateBank loadBank(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(fmt::format("{}: no such template bank", path));
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) throw InputError(fmt::format("{}: empty file, not a vkpose template bank", path));
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, 8) != 0) {
    if (bytes.size() < 8 && std::memcmp(bytes.data(), kMagic, bytes.size()) == 0)
      throw InputError(fmt::format("{}: truncated template bank ({} bytes)", path, bytes.size()));
    throw InputError(fmt::format("{}: not a vkpose template bank", path));
  }
  uint32_t version;
  std::memcpy(&version, bytes.data() + 8, 4);
  if (version > kBankVersion || version < 2)
    throw InputError(fmt::format("{}: template bank version {}, this vkpose reads versions 2 to {}: train it again",
                                 path, version, kBankVersion));
  uint64_t payload_bytes;
  std::memcpy(&payload_bytes, bytes.data() + 16, 8);
  const uint64_t expected = kHeaderBytes + payload_bytes + 8;
  if (payload_bytes > (uint64_t{1} << 40) || bytes.size() < expected)
    throw InputError(fmt::format("{}: truncated template bank ({} bytes; its header says {})", path, bytes.size(),
                                 expected));
  if (bytes.size() > expected)
    throw InputError(fmt::format("{}: corrupt template bank ({} bytes after its end)", path, bytes.size() - expected));
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + expected - 8, 8);
  if (stored != fnv1a64(bytes.data(), expected - 8))
    throw InputError(fmt::format("{}: corrupt template bank (checksum mismatch)", path));
  Reader reader(bytes.data() + kHeaderBytes, payload_bytes, path);
  return readPayload(reader, path, version);
}

uint64_t trainingKey(const Mesh& mesh, const TrainingParams& params, const std::vector<TrainingView>& views) {
  // Exactly what the bank stores of the mesh and the parameters, plus the views and the file
  // version: equal keys train equal banks.
  Writer w;
  w.put(kBankVersion);
  writeMesh(w, mesh);
  writeParams(w, params);
  w.put(static_cast<uint8_t>(params.symmetric));
  w.put(static_cast<uint64_t>(views.size()));
  for (const TrainingView& v : views) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) w.put(v.R(r, c));
    for (int i = 0; i < 3; ++i) w.put(v.t[i]);
    w.put(v.distance);
    w.put(v.inplane_deg);
  }
  return fnv1a64(w.bytes.data(), w.bytes.size());
}

}  // namespace vkpose
