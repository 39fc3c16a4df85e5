// The stage parameters (Config), the detector, its detections and overlays.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/error.hpp"
#include "vkpose/picking.hpp"

namespace vkpose::python {

namespace {

/// What a frame's detections refer to: the detector (its banks: meshes, names) and the camera.
struct FrameContext {
  std::shared_ptr<DetectorState> state;
  Camera camera;
};

struct PyDetection {
  Detection d;
  std::shared_ptr<const FrameContext> frame;
};

struct PyResult {
  DetectionResult r;
  std::shared_ptr<const FrameContext> frame;
};

// ---- Config ---------------------------------------------------------------------------

std::vector<std::string> sectionsOf(const std::vector<ConfigField>& fields) {
  std::vector<std::string> out;
  for (const ConfigField& f : fields)
    if (std::find(out.begin(), out.end(), f.section) == out.end()) out.push_back(f.section);
  return out;
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

ConfigField& fieldOf(std::vector<ConfigField>& fields, const std::string& section, const std::string& key) {
  for (ConfigField& f : fields)
    if (f.section == section && f.key == key) return f;
  std::vector<std::string> keys;
  for (const ConfigField& f : fields)
    if (f.section == section) keys.push_back(f.key);
  if (keys.empty())
    throw py::key_error(fmt::format("no config section '{}' (sections: {})", section, joined(sectionsOf(fields))));
  throw py::key_error(fmt::format("no config key '{}.{}' (keys of {}: {})", section, key, section, joined(keys)));
}

/// "section.key" split in two; KeyError otherwise.
std::pair<std::string, std::string> dottedKey(const std::string& name) {
  const auto dot = name.find('.');
  if (dot == std::string::npos) throw py::key_error(fmt::format("'{}': expected 'section.key', e.g. 'verify.threshold'", name));
  return {name.substr(0, dot), name.substr(dot + 1)};
}

/// One section of a Config, for attribute access: config.verify.threshold = 0.5.
struct ConfigSection {
  py::object config;  // the Config it belongs to (kept alive)
  std::string section;
  DetectorParams& params() const { return config.cast<DetectorParams&>(); }
};

py::object valueOf(const ConfigField& f) {
  return std::visit(
      [](auto* p) -> py::object {
        if constexpr (std::is_same_v<decltype(p), float*>)
          return py::float_(tidy(*p));
        else
          return py::cast(*p);
      },
      f.value);
}

/// Sets a field from a Python value of its type (an int is a number; a bool is not), then
/// checks the whole set as the detector will: the params stay as they were when it fails.
void setField(DetectorParams& params, const std::string& section, const std::string& key, const py::handle& value) {
  DetectorParams next = params;
  std::vector<ConfigField> fields = configFields(next);
  ConfigField& f = fieldOf(fields, section, key);
  const std::string name = section + "." + key;
  const bool is_bool = py::isinstance<py::bool_>(value);
  const bool is_int = py::isinstance<py::int_>(value) && !is_bool;
  const bool is_number = is_int || py::isinstance<py::float_>(value);
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, bool>) {
          if (!is_bool) valueError(fmt::format("{}: expected True or False, got {}", name, py::repr(value).cast<std::string>()));
          *p = value.cast<bool>();
        } else if constexpr (std::is_floating_point_v<T>) {
          if (!is_number) valueError(fmt::format("{}: expected a number, got {}", name, py::repr(value).cast<std::string>()));
          *p = static_cast<T>(value.cast<double>());
        } else {
          if (!is_int) valueError(fmt::format("{}: expected a whole number, got {}", name, py::repr(value).cast<std::string>()));
          const long long v = value.cast<long long>();
          if ((std::is_unsigned_v<T> && v < 0) || v > static_cast<long long>(std::numeric_limits<int>::max()))
            valueError(fmt::format("{}: {} is out of range", name, v));
          *p = static_cast<T>(v);
        }
      },
      f.value);
  validateDetectorParams(next);
  params = next;
}

// ---- detections -----------------------------------------------------------------------

py::array_t<double> poseMatrix(const Pose& p) {
  py::array_t<double> out({4, 4});
  auto r = out.mutable_unchecked<2>();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r(i, j) = i < 3 ? (j < 3 ? p.R(i, j) : p.t(i)) : (j == 3 ? 1.0 : 0.0);
  return out;
}

/// Poses compared with a detection's: [{"angle_deg", "axis", "depth_fit", ("depth_residual_mm"),
/// "colour", "score"}].
py::list alternativesList(const std::vector<SymmetryAlternative>& alternatives, bool residual) {
  py::list out;
  for (const auto& a : alternatives) {
    py::dict alt;
    alt["angle_deg"] = tidy(a.angle_deg);
    alt["axis"] = py::make_tuple(tidy(a.axis.x()), tidy(a.axis.y()), tidy(a.axis.z()));
    alt["depth_fit"] = tidy(a.depth_fit);
    if (residual) alt["depth_residual_mm"] = tidy(1e3f * a.depth_residual_m);
    alt["colour"] = tidy(a.colour);
    alt["score"] = tidy(a.score);
    out.append(alt);
  }
  return out;
}

/// The near-symmetric poses compared: {"alternatives", "chosen": index, "margin": by how much
/// it won, "compared"}.
py::dict symmetryDict(const Detection& d) {
  py::dict out;
  out["alternatives"] = alternativesList(d.symmetry_alternatives, false);
  out["chosen"] = d.symmetry_chosen;
  out["margin"] = tidy(d.symmetry_margin);
  out["compared"] = d.symmetry_compared;
  return out;
}

/// The look-alike half-turns refit and compared: {"alternatives", "chosen", "margin"}.
py::object lookAlikeDict(const Detection& d) {
  if (d.look_alike_alternatives.empty()) return py::none();
  py::dict out;
  out["alternatives"] = alternativesList(d.look_alike_alternatives, true);
  out["chosen"] = d.look_alike_chosen;
  out["margin"] = tidy(d.look_alike_margin);
  return out;
}

/// A share or ratio that is NaN where it was not measured: None there.
py::object measuredOrNone(float value) {
  if (!std::isfinite(value)) return py::none();
  return py::float_(tidy(value));
}

py::dict detectionDict(const Detection& d) {
  py::dict out;
  out["object"] = d.object;
  out["bank"] = d.bank;
  out["score"] = tidy(d.score);
  out["R"] = toArray(d.pose.R);
  out["t"] = toArray(d.pose.t);
  out["bbox"] = py::make_tuple(tidy(d.bbox.x), tidy(d.bbox.y), tidy(d.bbox.width), tidy(d.bbox.height));
  out["centre"] = py::make_tuple(tidy(d.x), tidy(d.y));
  out["gamma"] = tidy(d.gamma);
  out["alpha"] = tidy(d.alpha);
  out["beta"] = tidy(d.beta);
  out["templates"] = d.templates;
  out["template"] = d.template_index;
  out["similarity"] = tidy(d.similarity);
  out["verified"] = d.verified;
  out["collision_rate"] = tidy(d.collision_rate);
  out["see_through"] = tidy(d.see_through);
  out["depth_fit"] = tidy(d.depth_fit);
  out["colour_only"] = d.colour_only;
  out["explained_edges"] = tidy(d.explained_edges);
  if (std::isfinite(d.plain_outline_edges)) out["plain_outline_edges"] = tidy(d.plain_outline_edges);
  if (std::isfinite(d.region_contrast)) out["region_contrast"] = tidy(d.region_contrast);
  out["silhouette_support"] = tidy(d.silhouette_support);
  out["contour_edges"] = tidy(d.contour_edges);
  if (std::isfinite(d.outline_on_edges)) out["outline_on_edges"] = tidy(d.outline_on_edges);
  if (std::isfinite(d.silhouette_scale)) out["silhouette_scale"] = tidy(d.silhouette_scale);
  out["colour_agreement"] = tidy(d.colour_agreement);
  out["colour_measured"] = d.colour_measured;
  out["icp_fitness"] = d.icp_fitness;
  out["icp_iterations"] = d.icp_iterations;
  out["rotation_votes"] = d.rotation_votes;
  if (!d.symmetry_alternatives.empty()) {
    out["symmetry"] = symmetryDict(d);
    out["ambiguous_symmetry"] = d.ambiguous_symmetry;
  }
  if (!d.look_alike_alternatives.empty()) out["look_alike_turns"] = lookAlikeDict(d);
  if (!d.rejection.empty()) out["reason"] = d.rejection;
  return out;
}

std::vector<PyDetection> wrap(const std::vector<Detection>& dets, const std::shared_ptr<const FrameContext>& frame) {
  std::vector<PyDetection> out;
  out.reserve(dets.size());
  for (const Detection& d : dets) out.push_back({d, frame});
  return out;
}

/// The colour channel order of an image argument: "bgr" (OpenCV's) or "rgb".
bool isRgb(const std::string& color) {
  if (color != "bgr" && color != "rgb") valueError(fmt::format("color: '{}' is neither 'bgr' nor 'rgb'", color));
  return color == "rgb";
}

cv::Mat bgrOf(const py::handle& image, const std::string& color, const std::string& what) {
  const bool rgb = isRgb(color);
  cv::Mat m = colourImage(image, what);
  if (rgb) cv::cvtColor(m, m, cv::COLOR_RGB2BGR);
  return m;
}

/// A share in [0, 1] given from Python, or ValueError naming the argument.
float shareOf(float value, const char* name) {
  if (!(value >= 0.f && value <= 1.f)) valueError(fmt::format("{} must be in [0, 1], not {}", name, value));
  return value;
}

}  // namespace

DetectorParams paramsOf(const py::handle& config) {
  if (config.is_none()) return {};
  if (py::isinstance<DetectorParams>(config)) {
    DetectorParams p = config.cast<DetectorParams>();
    validateDetectorParams(p);
    return p;
  }
  if (py::isinstance<py::dict>(config)) {
    const std::string text = py::module_::import("json").attr("dumps")(config).cast<std::string>();
    return parseConfig(text, "config");
  }
  if (py::isinstance<py::str>(config) || py::hasattr(config, "__fspath__")) return loadConfig(pathOf(config, "config"));
  valueError(fmt::format("config: expected None, a vkpose.Config, a dict or a config file path, got {}",
                         py::str(config.get_type()).cast<std::string>()));
}

void bindDetect(py::module_& m) {
  // ---- Config: the stage parameters, the same keys as `vkpose config` and --config files.
  py::class_<ConfigSection>(m, "ConfigSection", "One stage's parameters of a Config, as attributes")
      .def("__getattr__",
           [](const ConfigSection& s, const std::string& key) {
             std::vector<ConfigField> fields = configFields(s.params());
             try {
               return valueOf(fieldOf(fields, s.section, key));
             } catch (const py::key_error& e) {
               throw py::attribute_error(e.what());
             }
           })
      .def("__setattr__",
           [](const ConfigSection& s, const std::string& key, const py::object& value) {
             try {
               setField(s.params(), s.section, key, value);  // looks the key up before setting anything
             } catch (const py::key_error& e) {
               throw py::attribute_error(e.what());
             }
           })
      .def("__dir__",
           [](const ConfigSection& s) {
             std::vector<std::string> keys;
             for (const ConfigField& f : configFields(s.params()))
               if (f.section == s.section) keys.push_back(f.key);
             return keys;
           })
      .def("__repr__", [](const ConfigSection& s) {
        std::string items;
        for (const ConfigField& f : configFields(s.params()))
          if (f.section == s.section)
            items += (items.empty() ? "" : ", ") + f.key + "=" + py::repr(valueOf(f)).cast<std::string>();
        return fmt::format("<vkpose.Config section '{}': {}>", s.section, items);
      });

  py::class_<DetectorParams>(
      m, "Config",
      R"(The detector's stage parameters: the same sections and keys as `vkpose config --explain`
and --config files. Read and set them as attributes (config.verify.threshold = 0.5) or by name
(config["verify.threshold"]); a value of the wrong type or out of range is a ValueError and
leaves the config as it was.)")
      .def(py::init([](const py::object& values) { return paramsOf(values); }), py::arg("values") = py::none(),
           "values: None (the defaults), a dict {\"section\": {\"key\": value}}, a config file path, or a Config")
      .def_static("load", [](const py::object& path) { return loadConfig(pathOf(path, "path")); }, py::arg("path"),
                  "Reads a config file (JSON, as `vkpose config --print-defaults` writes)")
      .def(
          "save",
          [](const DetectorParams& p, const py::object& path, bool overwrite) {
            const std::string file = pathOf(path, "path");
            refuseOverwrite(file, overwrite);
            writeTextFile(file, configJson(p), true);
          },
          py::arg("path"), py::arg("overwrite") = false, "Writes the config file")
      .def("__getattr__",
           [](const py::object& self, const std::string& section) {
             DetectorParams& p = self.cast<DetectorParams&>();
             const auto sections = sectionsOf(configFields(p));
             if (std::find(sections.begin(), sections.end(), section) == sections.end())
               throw py::attribute_error(
                   fmt::format("no config section '{}' (sections: {})", section, joined(sections)));
             return ConfigSection{self, section};
           })
      .def("__getitem__",
           [](DetectorParams& p, const std::string& name) {
             const auto [section, key] = dottedKey(name);
             std::vector<ConfigField> fields = configFields(p);
             return valueOf(fieldOf(fields, section, key));
           })
      .def("__setitem__",
           [](DetectorParams& p, const std::string& name, const py::object& value) {
             const auto [section, key] = dottedKey(name);
             setField(p, section, key, value);
           })
      .def("__dir__", [](DetectorParams& p) { return sectionsOf(configFields(p)); })
      .def("keys",
           [](DetectorParams& p) {
             std::vector<std::string> keys;
             for (const ConfigField& f : configFields(p)) keys.push_back(f.section + "." + f.key);
             return keys;
           },
           "Every parameter as 'section.key', in pipeline order")
      .def("to_dict",
           [](const DetectorParams& p) {
             return py::module_::import("json").attr("loads")(configJson(p));
           },
           "{section: {key: value}}, as the config file holds them")
      .def("to_json", &configJson, "The config file's JSON")
      .def("copy", [](const DetectorParams& p) { return p; })
      .def("explain", [](const DetectorParams& p) { return configTable(p); },
           "A table of every parameter: section.key, value, meaning and unit")
      .def("__eq__", [](const DetectorParams& a, const DetectorParams& b) { return configJson(a) == configJson(b); })
      .def("__repr__", [](const DetectorParams& p) {
        std::string changed;
        DetectorParams copy = p, base;  // configFields points into them; base holds the defaults
        const auto fields = configFields(copy), base_fields = configFields(base);
        for (std::size_t i = 0; i < fields.size(); ++i) {
          const py::object v = valueOf(fields[i]);
          if (!v.equal(valueOf(base_fields[i])))
            changed += (changed.empty() ? "" : ", ") + fields[i].section + "." + fields[i].key + "=" +
                       py::repr(v).cast<std::string>();
        }
        return fmt::format("<vkpose.Config {}>", changed.empty() ? "(defaults)" : changed);
      });

  // ---- detections.
  py::class_<PyDetection>(m, "Detection",
                          "One detected object instance: its pose (R, t: object-to-camera, metres), what to rank "
                          "by (score) and the scores of the stages it passed (see the README).")
      .def_property_readonly("object", [](const PyDetection& p) { return p.d.object; }, "The bank's object name")
      .def_property_readonly("bank", [](const PyDetection& p) { return p.d.bank; }, "Index of its bank in the detector")
      .def_property_readonly("score", [](const PyDetection& p) { return tidy(p.d.score); },
                             "What to rank by: phi * (1 - see_through) * silhouette_support (gamma without poses)")
      .def_property_readonly("R", [](const PyDetection& p) { return toArray(p.d.pose.R); },
                             "3x3 rotation, object to camera")
      .def_property_readonly("t", [](const PyDetection& p) { return toArray(p.d.pose.t); }, "Translation, metres")
      .def_property_readonly("pose", [](const PyDetection& p) { return poseMatrix(p.d.pose); },
                             "4x4 object-to-camera transform, metres")
      .def_property_readonly(
          "bbox", [](const PyDetection& p) { return py::make_tuple(tidy(p.d.bbox.x), tidy(p.d.bbox.y), tidy(p.d.bbox.width), tidy(p.d.bbox.height)); },
          "(x, y, w, h), pixels: the best template's object box")
      .def_property_readonly("centre", [](const PyDetection& p) { return py::make_tuple(tidy(p.d.x), tidy(p.d.y)); },
                             "(x, y) pixels of the object's centre")
      .def_property_readonly("gamma", [](const PyDetection& p) { return tidy(p.d.gamma); }, "Cluster score alpha * beta")
      .def_property_readonly("alpha", [](const PyDetection& p) { return tidy(p.d.alpha); })
      .def_property_readonly("beta", [](const PyDetection& p) { return tidy(p.d.beta); })
      .def_property_readonly("templates", [](const PyDetection& p) { return p.d.templates; }, "Members of the cluster")
      .def_property_readonly("template", [](const PyDetection& p) { return p.d.template_index; },
                             "The best template's index in its bank")
      .def_property_readonly("similarity", [](const PyDetection& p) { return tidy(p.d.similarity); },
                             "The best template's LINEMOD similarity, percent")
      .def_property_readonly("verified", [](const PyDetection& p) { return p.d.verified; })
      .def_property_readonly("collision_rate", [](const PyDetection& p) { return tidy(p.d.collision_rate); },
                             "phi; -1 when the pose stages did not run")
      .def_property_readonly("see_through", [](const PyDetection& p) { return tidy(p.d.see_through); })
      .def_property_readonly("depth_fit", [](const PyDetection& p) { return tidy(p.d.depth_fit); })
      .def_property_readonly("colour_only", [](const PyDetection& p) { return p.d.colour_only; },
                             "Posed without depth: fitted to the image's edges, no depth test ran")
      .def_property_readonly("explained_edges", [](const PyDetection& p) { return tidy(p.d.explained_edges); },
                             "Colour only: share of the frame's edges under the pose's mask that the model's edges explain")
      .def_property_readonly("plain_outline_edges",
                             [](const PyDetection& p) { return measuredOrNone(p.d.plain_outline_edges); },
                             "Colour only, a mesh without colours over one colour: share of its outline alone on "
                             "image edges, the test it passed instead of contour_edges; None where not measured")
      .def_property_readonly("region_contrast", [](const PyDetection& p) { return measuredOrNone(p.d.region_contrast); },
                             "Colour only: how well the frame's colours tell the pose's mask from a band around it "
                             "(0..1); None where not measured")
      .def_property_readonly("silhouette_support", [](const PyDetection& p) { return tidy(p.d.silhouette_support); })
      .def_property_readonly("contour_edges", [](const PyDetection& p) { return tidy(p.d.contour_edges); })
      .def_property_readonly("outline_on_edges", [](const PyDetection& p) { return measuredOrNone(p.d.outline_on_edges); })
      .def_property_readonly("silhouette_scale",
                             [](const PyDetection& p) { return measuredOrNone(p.d.silhouette_scale); },
                             "The scene's silhouette around the outline, times the model's (a larger look-alike: "
                             "over 1); None where not measured")
      .def_property_readonly("colour_agreement", [](const PyDetection& p) { return tidy(p.d.colour_agreement); },
                             "Correlation of the rendered mesh's chromaticity with the frame's; 1 when not measured")
      .def_property_readonly("colour_measured", [](const PyDetection& p) { return p.d.colour_measured; },
                             "colour_agreement was measured (the mesh has colours and the rendering shows them)")
      .def_property_readonly("icp_fitness", [](const PyDetection& p) { return p.d.icp_fitness; },
                             "Mean squared ICP pair distance, m^2")
      .def_property_readonly("icp_iterations", [](const PyDetection& p) { return p.d.icp_iterations; })
      .def_property_readonly("rotation_votes", [](const PyDetection& p) { return p.d.rotation_votes; })
      .def_property_readonly(
          "symmetry", [](const PyDetection& p) { return p.d.symmetry_alternatives.empty() ? py::object(py::none()) : py::object(symmetryDict(p.d)); },
          "The near-symmetric poses compared with the scene and the one kept (None when the object has none)")
      .def_property_readonly("ambiguous_symmetry", [](const PyDetection& p) { return p.d.ambiguous_symmetry; },
                             "Colour and depth could not tell the near-symmetric poses apart")
      .def_property_readonly("look_alike_turns", [](const PyDetection& p) { return lookAlikeDict(p.d); },
                             "The look-alike half-turns refit and compared with the pose (None when none were)")
      .def_property_readonly("reason", [](const PyDetection& p) { return p.d.rejection; },
                             "Why it was rejected (rejected hypotheses only; empty otherwise)")
      .def("to_dict", [](const PyDetection& p) { return detectionDict(p.d); }, "Every field as a dict")
      .def("__repr__", [](const PyDetection& p) {
        return fmt::format("<vkpose.Detection '{}' score {:.3f} t [{:.3f}, {:.3f}, {:.3f}] m{}>", p.d.object, p.d.score,
                           p.d.pose.t.x(), p.d.pose.t.y(), p.d.pose.t.z(),
                           p.d.rejection.empty() ? "" : ", rejected: " + p.d.rejection);
      });

  py::class_<PyResult>(m, "Result",
                       "What detect() found in a frame: detections (best score first), the hypotheses the pose "
                       "stages rejected, counts and per-stage timings. Iterating gives the detections.")
      .def_property_readonly("detections", [](const PyResult& r) { return wrap(r.r.detections, r.frame); })
      .def_property_readonly("rejected", [](const PyResult& r) { return wrap(r.r.rejected, r.frame); })
      .def_property_readonly(
          "timings_ms",
          [](const PyResult& r) {
            py::dict out;
            for (const auto& [stage, ms] : r.r.timings_ms) out[py::str(stage)] = ms;
            return out;
          },
          "Milliseconds per stage, in pipeline order")
      .def_property_readonly("matches", [](const PyResult& r) { return r.r.matches; })
      .def_property_readonly("hypotheses", [](const PyResult& r) { return r.r.hypotheses; })
      .def_property_readonly("scored_hypotheses", [](const PyResult& r) { return r.r.scored_hypotheses; })
      .def_property_readonly("match_pairs", [](const PyResult& r) { return r.r.match_pairs; },
                             "(template, position) pairs of the coarse pass (0 without depth-guided pruning)")
      .def_property_readonly("match_pairs_pruned", [](const PyResult& r) { return r.r.match_pairs_pruned; },
                             "pairs whose scene depth does not suit the template's training distance")
      .def_property_readonly("match_pairs_skipped", [](const PyResult& r) { return r.r.match_pairs_skipped; },
                             "pruned pairs the GPU skipped without reading memory")
      .def_property_readonly("refined_candidates", [](const PyResult& r) { return r.r.refined_candidates; },
                             "pose candidates that stages 7-8 refined and verified")
      .def_property_readonly("refine_cpu_ms", [](const PyResult& r) { return r.r.refine_cpu_ms; },
                             "their CPU milliseconds together (MLS, ICP, verification; each on one core)")
      .def_property_readonly("warnings", [](const PyResult& r) { return r.r.warnings; })
      .def_property_readonly("camera", [](const PyResult& r) { return r.frame->camera; })
      .def(
          "to_json",
          [](const PyResult& r, const std::string& rgb, const std::string& depth) {
            return detectionJson(r.r, {rgb, depth, r.frame->state->device->context.device().name});
          },
          py::arg("rgb") = "", py::arg("depth") = "",
          "The detection JSON that `vkpose detect --out` writes (rgb, depth: the file names to put in it)")
      .def("__len__", [](const PyResult& r) { return r.r.detections.size(); })
      .def("__getitem__",
           [](const PyResult& r, py::ssize_t i) {
             const auto n = static_cast<py::ssize_t>(r.r.detections.size());
             if (i < 0) i += n;
             if (i < 0 || i >= n) throw py::index_error("detection index out of range");
             return PyDetection{r.r.detections[static_cast<std::size_t>(i)], r.frame};
           })
      .def("__iter__", [](const PyResult& r) { return py::iter(py::cast(wrap(r.r.detections, r.frame))); })
      .def("__repr__", [](const PyResult& r) {
        double total = 0;
        for (const auto& [stage, ms] : r.r.timings_ms) total += ms;
        return fmt::format("<vkpose.Result: {} detection{}, {} rejected, {:.0f} ms>", r.r.detections.size(),
                           r.r.detections.size() == 1 ? "" : "s", r.r.rejected.size(), total);
      });

  // ---- the detector.
  py::class_<DetectorState, std::shared_ptr<DetectorState>>(
      m, "Detector",
      "Finds the objects of one or more banks in RGB-D frames (stages 1-8). Set up once, then detect() frame after "
      "frame; the GIL is released while it works, so other threads run meanwhile. Calls on one device take turns.")
      .def(py::init([](const py::object& banks, const py::object& config, const py::object& device) {
             const DetectorParams params = paramsOf(config);
             std::vector<TemplateBank> list;
             auto add = [&](const py::handle& b) {
               if (py::isinstance<TemplateBank>(b))
                 list.push_back(b.cast<const TemplateBank&>());
               else if (py::isinstance<py::str>(b) || py::hasattr(b, "__fspath__"))
                 list.push_back(loadBank(pathOf(b, "banks")));
               else
                 valueError(fmt::format("banks: expected vkpose.Bank objects or bank file paths, got {}",
                                        py::str(b.get_type()).cast<std::string>()));
             };
             if (py::isinstance<TemplateBank>(banks) || py::isinstance<py::str>(banks) || py::hasattr(banks, "__fspath__"))
               add(banks);
             else if (py::isinstance<py::sequence>(banks))
               for (const py::handle b : banks) add(b);
             else
               valueError(fmt::format("banks: expected a list of vkpose.Bank objects or bank file paths, got {}",
                                      py::str(banks.get_type()).cast<std::string>()));
             auto state = std::make_shared<DetectorState>();
             state->device = deviceOf(device);
             py::gil_scoped_release nogil;
             std::lock_guard<std::mutex> lock(state->device->mutex);
             state->detector = std::make_unique<Detector>(state->device->context, std::move(list), params);
             return state;
           }),
           py::arg("banks"), py::arg("config") = py::none(), py::arg("device") = py::none(),
           R"(banks: a list of vkpose.Bank objects or bank file paths (one per object; they must share
the feature parameters). config: None (the defaults), a vkpose.Config, a dict {"section": {"key":
value}} or a config file path, as `vkpose detect --config`. device: None, an index or a Device.)")
      .def(
          "detect",
          [](const std::shared_ptr<DetectorState>& state, const py::object& rgb, const py::object& depth,
             const py::object& K, const py::object& depth_scale, const std::string& color) {
            LinemodFrame frame;
            frame.bgr = bgrOf(rgb, color, "rgb");
            const bool camera_object = !py::isinstance<py::array>(K) && !py::isinstance<py::list>(K) &&
                                       !py::isinstance<py::tuple>(K);
            Camera camera = cameraOf(K, frame.bgr.cols, frame.bgr.rows, "K");
            double scale = camera_object ? camera.depth_scale : 1.0;
            if (!depth_scale.is_none()) {
              scale = depth_scale.cast<double>();
              if (!(scale > 0) || !std::isfinite(scale))
                valueError(fmt::format("depth_scale: {} is not a positive number of millimetres per unit", scale));
            }
            if (!depth.is_none()) frame.depth_mm = depthImage(depth, "depth", scale);  // None: colour only
            if (!depth.is_none() && frame.depth_mm.size() != frame.bgr.size())
              valueError(fmt::format("depth is {}x{} but rgb is {}x{} (width x height): they must be the same size, "
                                     "the depth registered to the colour image",
                                     frame.depth_mm.cols, frame.depth_mm.rows, frame.bgr.cols, frame.bgr.rows));
            FeatureParams features = state->detector->banks().front().params.features;
            features.use_depth = features.use_depth && !frame.depth_mm.empty();
            validateFrame(frame, features);
            camera.width = frame.bgr.cols;
            camera.height = frame.bgr.rows;
            PyResult out;
            out.frame = std::make_shared<FrameContext>(FrameContext{state, camera});
            py::gil_scoped_release nogil;
            std::lock_guard<std::mutex> lock(state->device->mutex);
            out.r = state->detector->detect(frame, camera);
            return out;
          },
          py::arg("rgb"), py::arg("depth"), py::arg("K"), py::kw_only(), py::arg("depth_scale") = py::none(),
          py::arg("color") = "bgr",
          R"(Detects every bank's object in one RGB-D frame; returns a Result.

rgb: HxWx3 uint8, BGR as OpenCV reads it (color="rgb" for RGB). depth: HxW, uint16 in millimetres
(times depth_scale) or float32/float64 in metres (0, NaN: no reading), registered to the colour
image; None: colour-only detection (the banks' colour templates, poses fitted to the image's edges). K: a 3x3 intrinsic matrix, a vkpose.Camera or a camera.json path. depth_scale: millimetres
per uint16 unit (default: the Camera's depth_scale, or 1 with a matrix).)")
      .def_property_readonly("banks", [](const DetectorState& s) {
        py::list out;
        for (const TemplateBank& b : s.detector->banks()) out.append(std::make_shared<TemplateBank>(b));
        return out;
      }, "Copies of the detector's banks")
      .def_property_readonly("config", [](const DetectorState& s) { return s.detector->params(); },
                             "The stage parameters in use (a copy)")
      .def_property_readonly("device", [](const DetectorState& s) { return s.device; })
      .def("__repr__", [](const DetectorState& s) {
        std::string objects;
        for (const TemplateBank& b : s.detector->banks()) objects += (objects.empty() ? "" : ", ") + b.object;
        return fmt::format("<vkpose.Detector [{}] on '{}'>", objects, s.device->context.device().name);
      });

  m.def(
      "draw",
      [](const py::object& rgb, const py::object& detections, bool show_rejected, bool legend,
         const py::object& depth, const std::string& color) {
        DetectionResult result;
        std::shared_ptr<const FrameContext> frame;
        if (py::isinstance<PyResult>(detections)) {
          const PyResult& r = detections.cast<const PyResult&>();
          result = r.r;
          frame = r.frame;
        } else if (py::isinstance<py::sequence>(detections)) {
          for (const py::handle h : detections) {
            if (!py::isinstance<PyDetection>(h))
              valueError("detections: expected a vkpose.Result or a list of vkpose.Detection");
            const PyDetection& d = h.cast<const PyDetection&>();
            if (frame && d.frame != frame) valueError("detections: they come from different frames");
            frame = d.frame;
            (d.d.rejection.empty() ? result.detections : result.rejected).push_back(d.d);
          }
        } else {
          valueError("detections: expected a vkpose.Result or a list of vkpose.Detection");
        }
        const bool to_rgb = isRgb(color);
        const cv::Mat bgr = bgrOf(rgb, color, "rgb");
        if (!frame) return toArray(bgr);  // nothing to draw
        if (bgr.cols != frame->camera.width || bgr.rows != frame->camera.height)
          valueError(fmt::format("rgb is {}x{} but the detections are of a {}x{} frame", bgr.cols, bgr.rows,
                                 frame->camera.width, frame->camera.height));
        OverlayOptions options;
        options.show_rejected = show_rejected;
        options.legend = legend;
        if (!depth.is_none()) {
          options.depth_mm = depthImage(depth, "depth", frame->camera.depth_scale);
          if (options.depth_mm.size() != bgr.size())
            valueError(fmt::format("depth is {}x{} but rgb is {}x{}", options.depth_mm.cols, options.depth_mm.rows,
                                   bgr.cols, bgr.rows));
        }
        cv::Mat out;
        {
          py::gil_scoped_release nogil;
          out = drawDetections(bgr, result, frame->state->detector->banks(), frame->camera, options);
          if (to_rgb) cv::cvtColor(out, out, cv::COLOR_BGR2RGB);
        }
        return toArray(out);
      },
      py::arg("rgb"), py::arg("detections"), py::kw_only(), py::arg("show_rejected") = false,
      py::arg("legend") = true, py::arg("depth") = py::none(), py::arg("color") = "bgr",
      R"(The colour image with the detections drawn, as `vkpose detect --overlay` draws them: each
pose's projected model outline and axes in its object's colour, a label and a legend. Returns a
new HxWx3 uint8 array in the same channel order as rgb (color="bgr" or "rgb").

detections: a Result, or a list of its Detection objects. show_rejected: also the rejected
hypotheses, in red. depth: the frame's depth, to put beside the colour in false colour.)");

  m.def(
      "plan_picks",
      [](const PyResult& result, const py::object& grasps, const py::object& depth, const py::object& bin,
         const std::string& order, float max_tilt, const py::object& approach_axis, float min_outline_on_edges,
         float min_colour_agreement, float colour_outline_allowance) {
        if (!result.frame) valueError("result: a Result of Detector.detect()");
        const auto& banks = result.frame->state->detector->banks();
        PickParams params;
        params.order = parsePickOrder(order);
        params.max_tilt_deg = max_tilt;
        params.min_outline_on_edges = shareOf(min_outline_on_edges, "min_outline_on_edges");
        params.min_colour_agreement = shareOf(min_colour_agreement, "min_colour_agreement");
        params.colour_outline_allowance = shareOf(colour_outline_allowance, "colour_outline_allowance");
        if (!approach_axis.is_none()) params.approach_axis = vector3Of(approach_axis, "approach_axis");
        std::vector<std::string> files;
        if (py::isinstance<py::str>(grasps) || py::hasattr(grasps, "__fspath__")) {
          files.push_back(pathOf(grasps, "grasps"));
        } else {
          for (const py::handle h : grasps) files.push_back(pathOf(h, "grasps"));
        }
        const std::vector<std::vector<Grasp>> by_bank = graspsForBanks(files, banks, params.symmetry_steps);
        std::optional<BinBox> box;
        if (!bin.is_none()) box = loadBin(pathOf(bin, "bin"));
        const Camera& camera = result.frame->camera;
        const cv::Mat depth_mm = depthImage(depth, "depth", camera.depth_scale);
        if (depth_mm.cols != camera.width || depth_mm.rows != camera.height)
          valueError(fmt::format("depth is {}x{} but the detections are of a {}x{} frame", depth_mm.cols, depth_mm.rows,
                                 camera.width, camera.height));
        std::string json;
        {
          py::gil_scoped_release nogil;
          cv::Mat depth_m;
          depth_mm.convertTo(depth_m, CV_32F, 0.001);
          json = pickPlanJson(planPicks(result.r.detections, banks, by_bank, depth_m, camera, box, params));
        }
        return py::module_::import("json").attr("loads")(json);
      },
      py::arg("result"), py::arg("grasps"), py::arg("depth"), py::kw_only(), py::arg("bin") = py::none(),
      py::arg("order") = "combined", py::arg("max_tilt") = PickParams{}.max_tilt_deg,
      py::arg("approach_axis") = py::none(), py::arg("min_outline_on_edges") = PickParams{}.min_outline_on_edges,
      py::arg("min_colour_agreement") = PickParams{}.min_colour_agreement,
      py::arg("colour_outline_allowance") = PickParams{}.colour_outline_allowance,
      R"(Bin picking on a Result, as `vkpose detect --grasps` does (docs/picking.md): each grasp file's
grasps placed at the detections of its object, refused where the gripper would hit the bin, the
scene or another detection, and the detections ordered into a pick list. Returns {"grasps": [per
detection {"valid": [...], "refused": [{"name", "reason"}]}], "picks": [{"detection", "grasp",
"rank", "score", "visible", "height", "reach", "free"}]}, camera frame, metres.

grasps: a grasp file or a list of them. depth: the frame's depth (as detect() took it). bin: a
bin file. order: combined, height, score or visible. max_tilt: degrees from approach_axis
(default: down into the bin, or the camera's viewing direction (0, 0, 1) without one).
min_outline_on_edges: a detection is picked only when this share of its outline lies on the
image's edges (Detection.outline_on_edges; 0: off). min_colour_agreement: and only when its colour
agrees with its model's this much (Detection.colour_agreement, where the mesh has colours; 0: off).
colour_outline_allowance: min_outline_on_edges asks up to this much less of a detection whose colour
was measured (Detection.colour_measured) and passed min_colour_agreement: all of it at an agreement
of 1, none at 0.6, linear between.)");
}

}  // namespace vkpose::python
