// Frames from files, synthetic datasets and BOP results files.
#include <algorithm>
#include <filesystem>
#include <sstream>

#include <fmt/core.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/synth.hpp"

namespace vkpose::python {

namespace {

std::vector<std::string> pathsOf(const py::handle& value, const std::string& what) {
  std::vector<std::string> out;
  if (py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__")) {
    out.push_back(pathOf(value, what));
  } else if (py::isinstance<py::sequence>(value)) {
    for (const py::handle h : value) out.push_back(pathOf(h, what));
  } else {
    valueError(fmt::format("{}: expected a path or a list of paths", what));
  }
  return out;
}

/// "N", "MIN:MAX", N or (MIN, MAX).
std::pair<int, int> countRange(const py::handle& value, const std::string& what) {
  auto whole = [&](const py::handle& h) {
    if (!py::isinstance<py::int_>(h) || py::isinstance<py::bool_>(h))
      valueError(fmt::format("{}: expected whole numbers, got {}", what, py::repr(value).cast<std::string>()));
    return h.cast<int>();
  };
  if (py::isinstance<py::str>(value)) {
    const std::string text = value.cast<std::string>();
    const auto colon = text.find(':');
    try {
      std::size_t used = 0;
      if (colon == std::string::npos) {
        const int n = std::stoi(text, &used);
        if (used == text.size()) return {n, n};
      } else {
        const int a = std::stoi(text.substr(0, colon), &used);
        std::size_t used_b = 0;
        const int b = std::stoi(text.substr(colon + 1), &used_b);
        if (used == colon && used_b == text.size() - colon - 1) return {a, b};
      }
    } catch (const std::exception&) {
    }
    valueError(fmt::format("{}: '{}' is not N or MIN:MAX", what, text));
  }
  if (py::isinstance<py::sequence>(value) && py::len(value) == 2) {
    const auto seq = value.cast<py::sequence>();
    return {whole(seq[0]), whole(seq[1])};
  }
  const int n = whole(value);
  return {n, n};
}

/// Numbers of a (from, to) or (x, y[, h]) argument, `count` of them or `count_alt`.
std::vector<float> metresOf(const py::handle& value, const std::string& what, std::size_t count, std::size_t count_alt) {
  std::vector<float> out;
  if (py::isinstance<py::str>(value)) {
    std::string text = value.cast<std::string>();
    std::replace(text.begin(), text.end(), ':', ' ');
    std::istringstream in(text);
    for (float v; in >> v;) out.push_back(v);
  } else if (py::isinstance<py::sequence>(value)) {
    for (const py::handle h : value) {
      if (!py::isinstance<py::float_>(h) && !py::isinstance<py::int_>(h))
        valueError(fmt::format("{}: expected numbers in metres, got {}", what, py::repr(value).cast<std::string>()));
      out.push_back(h.cast<float>());
    }
  }
  if (out.size() != count && out.size() != count_alt)
    valueError(fmt::format("{}: expected {} numbers in metres, got {}", what, count, py::repr(value).cast<std::string>()));
  return out;
}

void applyCloseRange(SynthParams& params, const py::object& camera_distance, const py::object& bin_size) {
  if (!camera_distance.is_none()) {
    const auto d = metresOf(camera_distance, "camera_distance", 2, 2);
    params.camera_range = cameraAtDistances(d[0], d[1]);
    if (!(d[1] > 0.f)) valueError("camera_distance: the largest distance must be positive");
  }
  if (!bin_size.is_none()) {
    const auto b = metresOf(bin_size, "bin_size", 2, 3);
    params.placement.bin_inner_m = {b[0], b[1]};
    if (b.size() == 3) params.placement.bin_wall_height_m = b[2];
    params.fit_bin_to_parts = false;
  }
}

/// What synth() and synth_frame() share: the meshes, the layout and what goes in it, the seed,
/// and the close-range camera and bin.
SynthParams synthParamsOf(const py::object& meshes, const std::string& layout, uint32_t seed,
                          const py::object& instances, int clutter, const std::string& units,
                          const py::object& camera_distance, const py::object& bin_size) {
  SynthParams params;
  applyCloseRange(params, camera_distance, bin_size);
  params.meshes = pathsOf(meshes, "meshes");
  if (layout != "table" && layout != "bin") valueError(fmt::format("layout: '{}' is neither 'table' nor 'bin'", layout));
  params.placement.layout = layout == "bin" ? Layout::Bin : Layout::Table;
  params.seed = seed;
  std::tie(params.min_instances, params.max_instances) = countRange(instances, "instances");
  params.clutter = clutter;
  params.units = parseMeshUnits(units);
  return params;
}

}  // namespace

py::dict resultRow(const BopResult& r) {
  py::dict row;
  row["scene_id"] = r.scene_id;
  row["im_id"] = r.im_id;
  row["obj_id"] = r.estimate.obj_id;
  row["score"] = r.estimate.score;
  row["R"] = toArray(r.estimate.R);
  row["t"] = toArray(r.estimate.t);
  row["time"] = r.time_s;
  return row;
}

namespace {

BopResult resultOf(const py::handle& row, std::size_t index) {
  const std::string what = fmt::format("rows[{}]", index);
  if (!py::isinstance<py::dict>(row)) valueError(what + ": expected a dict with scene_id, im_id, obj_id, score, R, t");
  const auto d = row.cast<py::dict>();
  for (const char* key : {"scene_id", "im_id", "obj_id", "score", "R", "t"})
    if (!d.contains(key)) valueError(fmt::format("{}: no '{}'", what, key));
  BopResult r;
  r.scene_id = d["scene_id"].cast<int>();
  r.im_id = d["im_id"].cast<int>();
  r.estimate.obj_id = d["obj_id"].cast<int>();
  r.estimate.score = d["score"].cast<float>();
  r.estimate.R = matrix3Of(d["R"], what + "['R']");
  r.estimate.t = vector3Of(d["t"], what + "['t']");
  if (d.contains("time") && !d["time"].is_none()) r.time_s = d["time"].cast<double>();
  return r;
}

}  // namespace

void bindData(py::module_& m) {
  m.def(
      "load_frame",
      [](const py::object& rgb, const py::object& depth, double depth_scale) {
        const std::string rgb_path = pathOf(rgb, "rgb"), depth_path = pathOf(depth, "depth");
        LinemodFrame frame;
        {
          py::gil_scoped_release nogil;
          frame = loadFrame(rgb_path, depth_path, depth_scale);
        }
        return py::make_tuple(toArray(frame.bgr), toArray(frame.depth_mm));
      },
      py::arg("rgb"), py::arg("depth"), py::arg("depth_scale") = 1.0,
      "Reads a colour image and a 16-bit depth PNG as vkpose detect does: (bgr HxWx3 uint8, depth HxW uint16 "
      "millimetres). depth_scale: millimetres per depth unit (BOP's).");

  m.def(
      "load_scene_cameras",
      [](const py::object& path) { return loadSceneCamera(pathOf(path, "path")); }, py::arg("path"),
      "A BOP scene_camera.json: {image id: Camera} (the image size is left at 640x480: detect() takes the frame's).");

  m.def(
      "write_bop_results",
      [](const py::object& path, const py::object& rows, bool overwrite) {
        const std::string file = pathOf(path, "path");
        refuseOverwrite(file, overwrite);
        std::vector<BopResult> results;
        std::size_t i = 0;
        for (const py::handle row : rows) results.push_back(resultOf(row, i++));
        saveBopResults(file, results);
      },
      py::arg("path"), py::arg("rows"), py::arg("overwrite") = false,
      "Writes bop_toolkit's results CSV. rows: dicts with scene_id, im_id, obj_id, score, R (3x3), t (metres; the "
      "file holds millimetres) and optionally time (seconds).");

  m.def(
      "read_bop_results",
      [](const py::object& path) {
        py::list out;
        for (const BopResult& r : loadBopResults(pathOf(path, "path"))) out.append(resultRow(r));
        return out;
      },
      py::arg("path"), "Reads bop_toolkit's results CSV as the dicts write_bop_results takes (t in metres).");

  m.def(
      "synth",
      [](const py::object& meshes, const py::object& out, int images, const std::string& poses,
         const std::string& layout, uint32_t seed, const py::object& instances, int clutter,
         const std::vector<int>& symmetric, const std::string& units, const py::object& camera,
         const py::object& camera_distance, const py::object& bin_size, bool overwrite, const py::object& device,
         const py::object& progress) {
        SynthParams params = synthParamsOf(meshes, layout, seed, instances, clutter, units, camera_distance, bin_size);
        params.images = images;
        params.poses = poses;
        params.symmetric = symmetric;
        if (!camera.is_none()) params.camera = cameraOf(camera, 640, 480, "camera");
        validateSynthParams(params);
        const std::string out_dir = pathOf(out, "out");
        if (!overwrite && std::filesystem::is_directory(out_dir) && !std::filesystem::is_empty(out_dir))
          valueError(out_dir + " exists and is not empty: pass overwrite=True to write into it");
        const std::shared_ptr<Device> dev = deviceOf(device);
        const auto report = progressOf(progress, "rendering");
        SynthSummary s;
        {
          py::gil_scoped_release nogil;
          std::lock_guard<std::mutex> lock(dev->mutex);
          s = generateSyntheticDataset(dev->context, params, out_dir, overwrite, [&](int done, int total) {
            report(static_cast<std::size_t>(done), static_cast<std::size_t>(total));
          });
        }
        py::dict summary;
        summary["dataset"] = out_dir;
        summary["images"] = s.images;
        summary["instances"] = s.instances;
        summary["left_out"] = s.left_out;
        summary["ms_per_image"] = s.ms_per_image;
        return summary;
      },
      py::arg("meshes"), py::arg("out"), py::kw_only(), py::arg("images"), py::arg("poses") = "random",
      py::arg("layout") = "table", py::arg("seed") = 0, py::arg("instances") = "1:3", py::arg("clutter") = 4,
      py::arg("symmetric") = std::vector<int>{}, py::arg("units") = "auto", py::arg("camera") = py::none(),
      py::arg("camera_distance") = py::none(), py::arg("bin_size") = py::none(), py::arg("overwrite") = false, py::arg("device") = py::none(), py::arg("progress") = py::none(),
      R"(Renders a synthetic multi-instance RGB-D dataset in BOP format into `out`, as `vkpose synth`
does: the same arguments and seed give the same files. Returns a summary dict (dataset, images,
instances, left_out, ms_per_image); vkpose.evaluate() scores a method on it.

meshes: one path or a list (obj_id 1, 2, ...). poses: 'random' or a folder of Tejani et al.
pose files. layout: 'table' or 'bin'. instances: of each mesh per image, N or "MIN:MAX".
clutter: boxes and cylinders not in the ground truth. symmetric: obj_ids scored with ADI.
camera_distance: (from, to) metres from the camera to the point it looks at (default: its
height, 0.6 to 1.2 m). bin_size: (x, y) or (x, y, wall height) metres (default: fitted to the
parts and the view).)");

  m.def(
      "synth_frame",
      [](const py::object& meshes, int index, uint32_t seed, const std::string& layout, const py::object& instances,
         int clutter, const std::string& units, const py::object& camera_distance, const py::object& bin_size,
         const py::object& device) {
        SynthParams params = synthParamsOf(meshes, layout, seed, instances, clutter, units, camera_distance, bin_size);
        params.images = index + 1;
        if (index < 0) valueError(fmt::format("index: {} is negative", index));
        validateSynthParams(params);
        const std::shared_ptr<Device> dev = deviceOf(device);
        SynthImage image;
        {
          py::gil_scoped_release nogil;
          std::vector<Mesh> models;
          for (const std::string& p : params.meshes) models.push_back(loadMesh(p, params.units));
          std::lock_guard<std::mutex> lock(dev->mutex);
          image = synthesizeImage(dev->context, params, models, index);
        }
        py::list gt;
        for (std::size_t i = 0; i < image.poses.size(); ++i) {
          py::dict g;
          g["obj_id"] = image.obj_ids[i];
          g["R"] = toArray(image.poses[i].R);
          g["t"] = toArray(image.poses[i].t);
          gt.append(g);
        }
        py::dict out;
        out["rgb"] = toArray(image.frame.bgr);
        out["depth"] = toArray(image.frame.depth_mm);
        out["camera"] = image.camera;
        out["gt"] = gt;
        return out;
      },
      py::arg("meshes"), py::kw_only(), py::arg("index") = 0, py::arg("seed") = 0, py::arg("layout") = "table",
      py::arg("instances") = "1:3", py::arg("clutter") = 4, py::arg("units") = "auto",
      py::arg("camera_distance") = py::none(), py::arg("bin_size") = py::none(), py::arg("device") = py::none(),
      "One random synthetic frame in memory, image `index` of what synth() would write with these arguments: a dict "
      "with rgb (BGR uint8), depth (uint16 mm), camera (a Camera) and gt (obj_id, R, t per instance).");
}

}  // namespace vkpose::python
