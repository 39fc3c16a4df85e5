#pragma once
// What the binding files share: the device objects Python holds, and numpy <-> OpenCV/Eigen
// conversions that check what they are given (dtype, shape, contiguity) and say what was wrong
// as a ValueError, so that bad arrays never reach the library as garbage.
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <opencv2/core.hpp>

#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
struct BopResult;
}  // namespace vkpose

namespace vkpose::python {

namespace py = pybind11;

/// A Vulkan device as Python holds it: the context and a lock that serializes the work on it
/// (a context's queue takes one submitter at a time; Python threads take turns).
struct Device {
  explicit Device(const GpuOptions& options) : context(options) {}
  GpuContext context;
  std::mutex mutex;
};

/// The device a `device=` argument names: None (the default choice: VKPOSE_DEVICE, else a GPU
/// first, lavapipe otherwise), an int (a Vulkan device index) or a Device. Devices are opened
/// once per index and shared.
std::shared_ptr<Device> deviceOf(const py::object& device);

/// Forgets the shared devices (at interpreter exit, before static destruction).
void releaseDevices();

/// A detector and the device it runs on; results keep it alive so that drawing them can use
/// its banks.
struct DetectorState {
  std::shared_ptr<Device> device;
  std::unique_ptr<Detector> detector;
};

/// An HxWx3 uint8 C-contiguous array as a cv::Mat (a copy); `what` names the argument.
cv::Mat colourImage(const py::handle& array, const std::string& what);
/// A depth array (HxW uint16 millimetres, or float32/float64 metres) as CV_16U millimetres;
/// `scale_mm` multiplies integer depth (millimetres per unit).
cv::Mat depthImage(const py::handle& array, const std::string& what, double scale_mm);
/// A cv::Mat (8UC3, 8UC1 or 16UC1) as a new numpy array.
py::array toArray(const cv::Mat& image);

/// A Camera from a Camera object, a path to a camera file, or a 3x3 intrinsic matrix (then the
/// image size is width x height).
Camera cameraOf(const py::handle& camera, int width, int height, const std::string& what);

/// A 3x3 float64 array of an Eigen matrix, and a length-3 vector.
py::array_t<double> toArray(const Eigen::Matrix3f& m);
py::array_t<double> toArray(const Eigen::Vector3f& v);
/// Reads a 3x3 / length-3 array-like; ValueError naming `what` otherwise.
Eigen::Matrix3d matrix3dOf(const py::handle& value, const std::string& what);
Eigen::Matrix3f matrix3Of(const py::handle& value, const std::string& what);
Eigen::Vector3f vector3Of(const py::handle& value, const std::string& what);

/// A `config=` argument as stage parameters: None (the defaults), a Config, a dict in the
/// config file's layout ({"section": {"key": value}}), or the path of a config file; checked.
DetectorParams paramsOf(const py::handle& config);

/// A path argument: str or os.PathLike.
std::string pathOf(const py::handle& value, const std::string& what);

/// Wraps a `progress=` argument for the library: a callable(done, total), True (a bar on
/// stderr labelled `label`), or None/False. Called with the GIL taken; it also checks for
/// Ctrl-C, which then stops the work with KeyboardInterrupt.
std::function<void(std::size_t, std::size_t)> progressOf(const py::object& progress, const std::string& label);

/// A float32 as the shortest double that prints like it (0.4f -> 0.4, not 0.4000000059604645).
double tidy(float value);

/// InputError when `path` exists and `overwrite` is false (nothing is replaced unasked).
void refuseOverwrite(const std::string& path, bool overwrite);

[[noreturn]] void valueError(const std::string& message);

void bindCore(py::module_& m);
void bindDetect(py::module_& m);
void bindData(py::module_& m);
void bindEval(py::module_& m);

/// A BOP results row as read_bop_results gives it: scene_id, im_id, obj_id, score, R, t, time.
py::dict resultRow(const BopResult& r);

}  // namespace vkpose::python
