// numpy <-> OpenCV/Eigen conversions and the shared devices (arrays.hpp).
#include "arrays.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "vkpose/error.hpp"

namespace vkpose::python {

namespace {
std::mutex devices_mutex;
std::map<int, std::shared_ptr<Device>> devices;  // by index; -1: the default choice

std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string describe(const py::array& a) {
  return fmt::format("shape {} {}", shapeText(a), py::str(a.dtype()).cast<std::string>());
}

/// The argument as a numpy array (lists and other array-likes are converted; a numpy array is
/// taken as it is, so its dtype and layout are checked, not silently changed).
py::array arrayOf(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::array>(value)) return py::reinterpret_borrow<py::array>(value);
  try {
    return py::array::ensure(value);
  } catch (const py::error_already_set&) {
  }
  valueError(fmt::format("{}: expected a numpy array, got {}", what, py::str(value.get_type()).cast<std::string>()));
}

void requireContiguous(const py::array& a, const std::string& what) {
  if (!(a.flags() & py::array::c_style))
    valueError(fmt::format("{}: the array is not C-contiguous (a slice, a transposed or a channel-flipped view, "
                           "{}); pass numpy.ascontiguousarray({})",
                           what, describe(a), what));
}
}  // namespace

[[noreturn]] void valueError(const std::string& message) { throw InputError(message); }

double tidy(float value) {
  if (!std::isfinite(value)) return value;
  return std::stod(fmt::format("{}", value));
}

void refuseOverwrite(const std::string& path, bool overwrite) {
  if (!overwrite && std::filesystem::exists(path)) valueError(path + " exists: pass overwrite=True to replace it");
}

std::shared_ptr<Device> deviceOf(const py::object& device) {
  if (!device.is_none() && py::isinstance<Device>(device)) return device.cast<std::shared_ptr<Device>>();
  int index = -1;
  if (!device.is_none()) {
    if (!py::isinstance<py::int_>(device) || py::isinstance<py::bool_>(device))
      valueError(fmt::format("device: expected None, a device index (int) or a vkpose.Device, got {}",
                             py::str(device.get_type()).cast<std::string>()));
    index = device.cast<int>();
    if (index < 0) valueError(fmt::format("device: {} is not a device index (0, 1, ...: see vkpose.devices())", index));
  }
  std::lock_guard<std::mutex> lock(devices_mutex);
  auto& slot = devices[index];
  if (!slot) {
    GpuOptions options;
    if (index >= 0) options.device_index = index;
    slot = std::make_shared<Device>(options);
  }
  return slot;
}

void releaseDevices() {
  std::lock_guard<std::mutex> lock(devices_mutex);
  devices.clear();
}

cv::Mat colourImage(const py::handle& value, const std::string& what) {
  const py::array a = arrayOf(value, what);
  if (a.ndim() != 3 || a.shape(2) != 3 || !py::isinstance<py::array_t<uint8_t>>(a))
    valueError(fmt::format("{}: expected an HxWx3 uint8 colour image, got {}", what, describe(a)));
  requireContiguous(a, what);
  if (a.shape(0) < 1 || a.shape(1) < 1) valueError(fmt::format("{}: the image is empty ({})", what, describe(a)));
  const cv::Mat view(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_8UC3,
                     const_cast<void*>(a.data()));
  return view.clone();
}

cv::Mat depthImage(const py::handle& value, const std::string& what, double scale_mm) {
  const py::array a = arrayOf(value, what);
  const bool u16 = py::isinstance<py::array_t<uint16_t>>(a), f32 = py::isinstance<py::array_t<float>>(a),
             f64 = py::isinstance<py::array_t<double>>(a);
  if (a.ndim() != 2 || !(u16 || f32 || f64))
    valueError(fmt::format("{}: expected an HxW depth image, uint16 millimetres or float32 metres, got {}", what,
                           describe(a)));
  requireContiguous(a, what);
  const int rows = static_cast<int>(a.shape(0)), cols = static_cast<int>(a.shape(1));
  if (rows < 1 || cols < 1) valueError(fmt::format("{}: the image is empty ({})", what, describe(a)));
  cv::Mat depth(rows, cols, CV_16UC1);
  if (u16) {
    const cv::Mat view(rows, cols, CV_16UC1, const_cast<void*>(a.data()));
    if (scale_mm == 1.0)
      view.copyTo(depth);
    else
      view.convertTo(depth, CV_16U, scale_mm);  // saturating, rounded
    return depth;
  }
  // Metres: millimetres rounded; no reading (0) where the value is not finite, not positive, or
  // beyond what 16-bit millimetres hold.
  auto convert = [&](const auto* src) {
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const double mm = static_cast<double>(src[static_cast<std::size_t>(r) * cols + c]) * 1000.0;
        depth.at<uint16_t>(r, c) =
            std::isfinite(mm) && mm > 0 && mm < 65535.5 ? static_cast<uint16_t>(std::lround(mm)) : uint16_t{0};
      }
  };
  if (f32)
    convert(static_cast<const float*>(a.data()));
  else
    convert(static_cast<const double*>(a.data()));
  return depth;
}

py::array toArray(const cv::Mat& image) {
  const cv::Mat m = image.isContinuous() ? image : image.clone();
  std::vector<py::ssize_t> shape{m.rows, m.cols};
  if (m.channels() > 1) shape.push_back(m.channels());
  switch (m.depth()) {
    case CV_8U: {
      py::array_t<uint8_t> out(shape);
      std::memcpy(out.mutable_data(), m.data, m.total() * m.elemSize());
      return out;
    }
    case CV_16U: {
      py::array_t<uint16_t> out(shape);
      std::memcpy(out.mutable_data(), m.data, m.total() * m.elemSize());
      return out;
    }
    default:
      throw std::runtime_error("toArray: unexpected image type");
  }
}

Camera cameraOf(const py::handle& camera, int width, int height, const std::string& what) {
  if (py::isinstance<Camera>(camera)) return camera.cast<Camera>();
  if (py::isinstance<py::str>(camera) || py::hasattr(camera, "__fspath__")) return loadCamera(pathOf(camera, what));
  const Eigen::Matrix3d K = matrix3dOf(camera, what);  // doubles: the intrinsics exactly as given
  if (K(2, 0) != 0.0 || K(2, 1) != 0.0 || K(2, 2) != 1.0 || K(1, 0) != 0.0)
    valueError(fmt::format("{}: not an intrinsic matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (last row [{}, {}, {}])",
                           what, K(2, 0), K(2, 1), K(2, 2)));
  if (K(0, 1) != 0.0) valueError(fmt::format("{}: a skewed camera (K[0, 1] = {}) is not supported", what, K(0, 1)));
  Camera c;
  c.fx = K(0, 0);
  c.fy = K(1, 1);
  c.cx = K(0, 2);
  c.cy = K(1, 2);
  c.width = width;
  c.height = height;
  validateCamera(c, what);
  return c;
}

py::array_t<double> toArray(const Eigen::Matrix3f& m) {
  py::array_t<double> out({3, 3});
  auto r = out.mutable_unchecked<2>();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m(i, j);
  return out;
}

py::array_t<double> toArray(const Eigen::Vector3f& v) {
  py::array_t<double> out(3);
  auto r = out.mutable_unchecked<1>();
  for (int i = 0; i < 3; ++i) r(i) = v(i);
  return out;
}

Eigen::Matrix3d matrix3dOf(const py::handle& value, const std::string& what) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
    valueError(fmt::format("{}: expected a 3x3 matrix, got {}", what,
                           a ? describe(a) : py::str(value.get_type()).cast<std::string>()));
  Eigen::Matrix3d m;
  auto r = a.unchecked<2>();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (!std::isfinite(r(i, j))) valueError(fmt::format("{}: element [{}, {}] is not finite", what, i, j));
      m(i, j) = r(i, j);
    }
  return m;
}

Eigen::Matrix3f matrix3Of(const py::handle& value, const std::string& what) {
  return matrix3dOf(value, what).cast<float>();
}

Eigen::Vector3f vector3Of(const py::handle& value, const std::string& what) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.size() != 3 || a.ndim() > 2)
    valueError(fmt::format("{}: expected 3 numbers, got {}", what,
                           a ? describe(a) : py::str(value.get_type()).cast<std::string>()));
  const double* d = a.data();
  Eigen::Vector3f v;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(d[i])) valueError(fmt::format("{}: element {} is not finite", what, i));
    v(i) = static_cast<float>(d[i]);
  }
  return v;
}

std::string pathOf(const py::handle& value, const std::string& what) {
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::hasattr(value, "__fspath__")) {
    const py::object p = value.attr("__fspath__")();
    if (py::isinstance<py::str>(p)) return p.cast<std::string>();
  }
  valueError(fmt::format("{}: expected a path (str or os.PathLike), got {}", what,
                         py::str(value.get_type()).cast<std::string>()));
}

std::function<void(std::size_t, std::size_t)> progressOf(const py::object& progress, const std::string& label) {
  py::object callback = progress;
  if (py::isinstance<py::bool_>(progress))  // True: the package's bar on stderr; False: none
    callback = progress.cast<bool>() ? py::module_::import("vkpose").attr("_ProgressBar")(label) : py::none();
  else if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    valueError(fmt::format("progress: expected True, False, None or a callable(done, total), got {}",
                           py::str(progress.get_type()).cast<std::string>()));
  // Called by the library with the GIL released, and copied there: the Python object is held
  // through a pointer whose last owner takes the GIL to let it go.
  std::shared_ptr<py::object> held(new py::object(callback), [](py::object* o) {
    py::gil_scoped_acquire gil;
    delete o;
  });
  return [held](std::size_t done, std::size_t total) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!held->is_none()) (*held)(done, total);
  };
}

}  // namespace vkpose::python
