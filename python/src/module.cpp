// The extension module vkpose._vkpose: errors, then the bindings by family (core: devices,
// cameras, banks, training; detect: config, detector, detections, drawing; data: frames,
// synthetic datasets, BOP files; eval: evaluation, on one process or
// spread over Dask's workers). vkpose/__init__.py re-exports them.
#include "arrays.hpp"
#include "vkpose/error.hpp"
#include "vkpose/vkpose.hpp"

PYBIND11_MODULE(_vkpose, m) {
  namespace py = pybind11;
  using namespace vkpose::python;
  m.doc() = "vkpose's C++ core (use the vkpose package, not this module)";
  // Bad input is a ValueError and no usable device a RuntimeError, with the CLI's messages.
  py::register_exception<vkpose::InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<vkpose::DeviceError>(m, "DeviceError", PyExc_RuntimeError);
  m.attr("__version__") = vkpose::version();
  bindCore(m);
  bindDetect(m);
  bindData(m);
  bindEval(m);
  // Vulkan contexts go before the interpreter does, not in static destruction.
  py::module_::import("atexit").attr("register")(py::cpp_function([] { releaseDevices(); }));
}
