// Devices, cameras, template banks and training.
#include <filesystem>

#include <fmt/core.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/error.hpp"

namespace vkpose::python {

namespace {

/// A stepped range from "A:B:STEP", a number, or (A, B, STEP), through the library's parser
/// (and its messages).
SteppedRange rangeOf(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::str>(value)) return parseSteppedRange(value.cast<std::string>(), what);
  if (py::isinstance<py::float_>(value) || (py::isinstance<py::int_>(value) && !py::isinstance<py::bool_>(value)))
    return parseSteppedRange(fmt::format("{}", value.cast<double>()), what);
  if (py::isinstance<py::sequence>(value)) {
    const auto seq = value.cast<py::sequence>();
    if (seq.size() == 3)
      return parseSteppedRange(
          fmt::format("{}:{}:{}", seq[0].cast<double>(), seq[1].cast<double>(), seq[2].cast<double>()), what);
  }
  valueError(fmt::format("{}: expected \"FROM:TO:STEP\", a number, or (FROM, TO, STEP), got {}", what,
                         py::repr(value).cast<std::string>()));
}

py::tuple rangeTuple(const SteppedRange& r) { return py::make_tuple(tidy(r.from), tidy(r.to), tidy(r.step)); }

py::array_t<float> verticesOf(const std::vector<Eigen::Vector3f>& points) {
  py::array_t<float> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto r = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int j = 0; j < 3; ++j) r(static_cast<py::ssize_t>(i), j) = points[i](j);
  return out;
}

std::string cameraRepr(const Camera& c) {
  return fmt::format("vkpose.Camera(fx={}, fy={}, cx={}, cy={}, width={}, height={}, depth_scale={})", c.fx, c.fy, c.cx,
                     c.cy, c.width, c.height, c.depth_scale);
}

std::string upAxis(const TemplateBank& bank) { return upAxisName(bank.params.views.up); }

}  // namespace

void bindCore(py::module_& m) {
  py::class_<GpuDeviceInfo>(m, "DeviceInfo", "A Vulkan device and the limits vkpose cares about.")
      .def_readonly("index", &GpuDeviceInfo::index, "Position in the Vulkan enumeration (device=index)")
      .def_readonly("name", &GpuDeviceInfo::name)
      .def_readonly("type", &GpuDeviceInfo::type, "'discrete', 'integrated', 'virtual', 'cpu' or 'other'")
      .def_readonly("api_version", &GpuDeviceInfo::api_version)
      .def_readonly("driver", &GpuDeviceInfo::driver)
      .def_readonly("usable", &GpuDeviceInfo::usable, "Has the features vkpose needs")
      .def_readonly("missing", &GpuDeviceInfo::missing, "When not usable: what is missing")
      .def_readonly("device_local_memory", &GpuDeviceInfo::device_local_memory, "Bytes")
      .def_readonly("subgroup_size", &GpuDeviceInfo::subgroup_size)
      .def("__repr__", [](const GpuDeviceInfo& d) {
        return fmt::format("<vkpose.DeviceInfo {}: '{}' ({}{})>", d.index, d.name, d.type,
                           d.usable ? "" : ", not usable: " + d.missing);
      });

  m.def("devices", &listGpuDevices,
        "The Vulkan devices of this machine, in Vulkan's order (a GPU, or lavapipe on the CPU).\n\n"
        "Raises DeviceError when Vulkan itself is missing.");

  py::class_<Device, std::shared_ptr<Device>>(
      m, "Device",
      "A Vulkan device opened for vkpose's kernels. Device() is the default choice (VKPOSE_DEVICE, else a GPU "
      "first, lavapipe otherwise); Device(i) the device of index i in devices(). Opened once per index and "
      "shared; work on one device runs one call at a time.")
      .def(py::init([](const py::object& index) { return deviceOf(index); }), py::arg("index") = py::none())
      .def("__eq__", [](const Device& a, const Device& b) { return &a == &b; })
      .def("__hash__", [](const Device& d) { return std::hash<const void*>()(&d); })
      .def_property_readonly("info", [](const Device& d) { return d.context.device(); })
      .def_property_readonly("name", [](const Device& d) { return d.context.device().name; })
      .def_property_readonly("index", [](const Device& d) { return d.context.device().index; })
      .def("__repr__", [](const Device& d) {
        return fmt::format("<vkpose.Device {}: '{}'>", d.context.device().index, d.context.device().name);
      });
  m.def("_validation_errors", &GpuContext::processValidationErrors,
        "Vulkan validation-layer errors seen in this process (with VKPOSE_VALIDATION=1)");

  py::class_<Camera>(m, "Camera", "Pinhole intrinsics in pixels, the image size, and the depth scale (mm per unit).")
      .def(py::init([](double fx, double fy, double cx, double cy, int width, int height, double depth_scale) {
             Camera c{fx, fy, cx, cy, width, height, depth_scale};
             validateCamera(c);
             return c;
           }),
           py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"), py::arg("width") = 640,
           py::arg("height") = 480, py::arg("depth_scale") = 1.0)
      .def_static(
          "load", [](const py::object& path, const std::string& entry) { return loadCamera(pathOf(path, "path"), entry); },
          py::arg("path"), py::arg("entry") = "",
          "Reads a BOP camera.json (cam_K or fx/fy/cx/cy, width, height, depth_scale) or one entry of a "
          "scene_camera.json (entry: its key, e.g. '0'; empty: the first).")
      .def_static(
          "from_K", [](const py::object& K, int width, int height, double depth_scale) {
            Camera c = cameraOf(K, width, height, "K");
            c.depth_scale = depth_scale;
            validateCamera(c, "K");
            return c;
          },
          py::arg("K"), py::arg("width"), py::arg("height"), py::arg("depth_scale") = 1.0,
          "A camera from a 3x3 intrinsic matrix and the image size.")
      .def_readwrite("fx", &Camera::fx)
      .def_readwrite("fy", &Camera::fy)
      .def_readwrite("cx", &Camera::cx)
      .def_readwrite("cy", &Camera::cy)
      .def_readwrite("width", &Camera::width)
      .def_readwrite("height", &Camera::height)
      .def_readwrite("depth_scale", &Camera::depth_scale, "Millimetres per depth-image unit")
      .def_property_readonly(
          "K",
          [](const Camera& c) {
            py::array_t<double> out({3, 3});
            auto r = out.mutable_unchecked<2>();
            const double K[3][3] = {{c.fx, 0, c.cx}, {0, c.fy, c.cy}, {0, 0, 1}};
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) r(i, j) = K[i][j];
            return out;
          },
          "The 3x3 intrinsic matrix")
      .def("__repr__", &cameraRepr);

  py::class_<TemplateBank, std::shared_ptr<TemplateBank>>(
      m, "Bank",
      "One object's template bank: LINEMOD templates rendered from its mesh, the poses they were rendered at, and "
      "the mesh itself. Made by vkpose.train() or Bank.load(); the same file as `vkpose train` writes.")
      .def_static(
          "load",
          [](const py::object& path) {
            const std::string p = pathOf(path, "path");
            py::gil_scoped_release nogil;
            return std::make_shared<TemplateBank>(loadBank(p));
          },
          py::arg("path"), "Reads a bank file (.vkpb); ValueError naming the file when it is missing or damaged.")
      .def(
          "save",
          [](const TemplateBank& bank, const py::object& path, bool overwrite) {
            const std::string p = pathOf(path, "path");
            refuseOverwrite(p, overwrite);
            py::gil_scoped_release nogil;
            saveBank(bank, p);
          },
          py::arg("path"), py::arg("overwrite") = false, "Writes the bank file (.vkpb).")
      .def_readonly("object", &TemplateBank::object, "The object's name (the mesh file's stem)")
      .def_property_readonly("diameter", [](const TemplateBank& b) { return tidy(b.diameter); }, "Metres")
      .def_readonly("symmetric", &TemplateBank::symmetric)
      .def_property_readonly(
          "templates", [](const TemplateBank& b) { return b.templates.size(); }, "Number of templates")
      .def_property_readonly("up_axis", &upAxis,
                             "The object's up axis the views were sampled about ('+z', '-z', ...), mesh frame")
      .def_property_readonly(
          "other_resting_ups",
          [](const TemplateBank& b) {
            py::list out;
            for (const Eigen::Vector3f& u : b.params.views.other_ups) out.append(upAxisName(u));
            return out;
          },
          "Up axes of the other resting poses (lying, upside down) whose views the bank also holds")
      .def_property_readonly(
          "near_symmetries",
          [](const TemplateBank& b) {
            py::list out;
            for (const auto& sym : b.near_symmetries) {
              py::dict d;
              d["angle_deg"] = tidy(sym.angle_deg);
              d["axis"] = toArray(sym.axis);
              d["point"] = toArray(sym.point);
              d["deviation_m"] = tidy(sym.deviation_m);
              out.append(d);
            }
            return out;
          },
          "Turns that map the mesh onto itself within the training tolerance: angle_deg about axis through point "
          "(object frame, metres), deviation_m")
      .def_property_readonly("hemisphere", [](const TemplateBank& b) { return b.params.views.full_sphere ? "full" : "upper"; },
                             "'upper': views above the up axis; 'full': the whole sphere")
      .def_property_readonly("camera", [](const TemplateBank& b) { return b.params.camera; },
                             "The camera the templates were rendered for")
      .def_property_readonly("viewpoints", [](const TemplateBank& b) { return b.params.views.viewpoints; })
      .def_property_readonly("radii", [](const TemplateBank& b) { return rangeTuple(b.params.views.radii); },
                             "(from, to, step), metres")
      .def_property_readonly("inplane", [](const TemplateBank& b) { return rangeTuple(b.params.views.inplane_deg); },
                             "(from, to, step), degrees")
      .def_property_readonly(
          "full_turn_within", [](const TemplateBank& b) { return b.params.views.full_turn_within_deg; },
          "Viewpoints this near a pole (degrees) took in-plane rotations over the whole turn; 0: none")
      .def_property_readonly("centre", [](const TemplateBank& b) { return toArray(b.centre); },
                             "The point the training cameras looked at, object frame, metres")
      .def_property_readonly("mesh_vertices", [](const TemplateBank& b) { return verticesOf(b.mesh.vertices); },
                             "The mesh's vertices, Nx3, metres, object frame")
      .def_property_readonly(
          "mesh_faces",
          [](const TemplateBank& b) {
            py::array_t<int32_t> out({static_cast<py::ssize_t>(b.mesh.faces.size()), py::ssize_t{3}});
            auto r = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < b.mesh.faces.size(); ++i)
              for (int j = 0; j < 3; ++j) r(static_cast<py::ssize_t>(i), j) = b.mesh.faces[i](j);
            return out;
          },
          "The mesh's triangles, Mx3 vertex indices")
      .def("__len__", [](const TemplateBank& b) { return b.templates.size(); })
      .def("__repr__", [](const TemplateBank& b) {
        return fmt::format("<vkpose.Bank '{}': {} templates, diameter {:.4f} m, up axis {}{}>", b.object,
                           b.templates.size(), b.diameter, upAxis(b), b.symmetric ? ", symmetric" : "");
      });

  m.def(
      "train",
      [](const py::object& mesh_path, const std::string& units, int views, const py::object& radii,
         const py::object& inplane, const std::string& hemisphere, float max_view_angle, int features,
         const py::object& camera, bool symmetric, const std::string& up, const std::string& resting,
         bool allow_small, const py::object& full_turn_within, const py::object& device,
         const py::object& cache_dir, const py::object& progress) {
        TrainingParams params;
        params.views.viewpoints = views;
        params.views.radii = rangeOf(radii, "radii");
        params.views.inplane_deg = rangeOf(inplane, "inplane");
        if (hemisphere != "upper" && hemisphere != "full")
          valueError(fmt::format("hemisphere: '{}' is neither 'upper' nor 'full'", hemisphere));
        params.views.full_sphere = hemisphere == "full";
        params.features_per_modality = features;
        params.symmetric = symmetric;
        if (!camera.is_none()) params.camera = cameraOf(camera, 640, 480, "camera");
        if (up != "auto") params.views.up = parseUpAxis(up);
        if (resting != "auto" && resting != "all" && resting != "up")
          valueError(fmt::format("resting: '{}' is none of 'auto', 'all', 'up'", resting));
        if (!(max_view_angle >= 1.f && max_view_angle <= 180.f))
          valueError(fmt::format("max_view_angle: {} is not within 1..180 degrees", max_view_angle));
        std::optional<float> full_turn;
        if (!full_turn_within.is_none()) {
          try {
            full_turn = full_turn_within.cast<float>();
          } catch (const py::cast_error&) {
            valueError("full_turn_within: a number of degrees, or None");
          }
          if (!(*full_turn >= 0.f && *full_turn <= 90.f))
            valueError(fmt::format("full_turn_within: {} is not within 0..90 degrees", *full_turn));
        }
        validateTrainingParams(params);
        const std::string path = pathOf(mesh_path, "mesh");
        const std::string cache = cache_dir.is_none() ? std::string() : pathOf(cache_dir, "cache_dir");
        const MeshUnits mesh_units = parseMeshUnits(units);
        const std::shared_ptr<Device> dev = deviceOf(device);
        const Mesh mesh = [&] {
          py::gil_scoped_release nogil;
          return loadMesh(path, mesh_units);
        }();
        if (const PartSizeEvidence size = partSizeEvidence(mesh, params); size.too_small() && !allow_small)
          valueError(size.refusal() + " (allow_small=True in Python)");
        for (const std::string& w : trainingWarnings(mesh, params))
          if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
        const auto report = progressOf(progress, "training");
        py::gil_scoped_release nogil;
        const std::vector<TrainingView> training_views =
            planTraining(mesh, params, up == "auto", resting, max_view_angle, full_turn).views;
        std::lock_guard<std::mutex> lock(dev->mutex);
        if (!cache.empty())
          return std::make_shared<TemplateBank>(
              loadOrTrainBank(dev->context, mesh, params, training_views, cache, report).bank);
        return std::make_shared<TemplateBank>(
            trainTemplatesFromViews(dev->context, mesh, params, training_views, report));
      },
      py::arg("mesh"), py::kw_only(), py::arg("units") = "auto", py::arg("views") = 216,
      py::arg("radii") = "0.6:1.0:0.1", py::arg("inplane") = "-60:60:10", py::arg("hemisphere") = "upper",
      py::arg("max_view_angle") = 180.f, py::arg("features") = 63, py::arg("camera") = py::none(),
      py::arg("symmetric") = false, py::arg("up") = "auto", py::arg("resting") = "auto",
      py::arg("allow_small") = false, py::arg("full_turn_within") = py::none(), py::arg("device") = py::none(),
      py::arg("cache_dir") = py::none(),
      py::arg("progress") = py::none(),
      R"(Renders a mesh from every training view on the GPU and returns its template bank,
as `vkpose train` does (the same defaults).

mesh: STL, PLY (colours kept) or OBJ. units: 'mm', 'm' or 'auto' (from the object's size).
views: viewpoints on the (hemi)sphere. radii: camera distances "FROM:TO:STEP" or (from, to, step),
metres. inplane: in-plane rotations, degrees. hemisphere: 'upper' or 'full'. max_view_angle:
keep viewpoints within this angle of the up axis, degrees. features: per modality and level.
camera: the sensor (a Camera, a camera.json path, or a 3x3 K): templates are scale-specific.
symmetric: score the object with ADI. up: the object's up axis, 'auto' (the end it stands on,
+z first) or '+x', '-x', '+y', '-y', '+z', '-z'; views are sampled above it. resting: 'up' (views about
the up axis only), 'all' (also a hemisphere about each other pose it rests in, lying or upside
down, that no near-symmetry covers: up to 6x the templates) or 'auto' (all for a part smaller
than 10 cm across or trained nearer than 0.5 m, up otherwise). allow_small: train a part under
2 cells of LINEMOD's coarsest level across (or 1 wide) at the nearest radius, which raises ValueError
otherwise (too small to tell from its neighbourhood). full_turn_within: viewpoints within this many
degrees of a pole take in-plane rotations over the whole turn (None: 40 where resting trains the
lying poses, a part in a bin, else 0). device: None, an index or a Device. cache_dir: a folder
where banks are kept between runs (None: no cache). progress: True for a bar on stderr, or a
callable(done, total).)");
}

}  // namespace vkpose::python
