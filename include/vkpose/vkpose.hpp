#pragma once
// vkpose's public API in one include. Each header is one concept:
//   error.hpp       InputError (bad input) and DeviceError (no usable Vulkan device)
//   geometry.hpp    Mesh and loadMesh (STL, PLY, OBJ, with units), Pose (object-to-camera),
//                   Camera (intrinsics, camera.json)
//   device.hpp      GpuContext: the Vulkan device the kernels run on (a GPU, or lavapipe)
//   frame.hpp       LinemodFrame (colour + depth), FeatureParams, loadFrame, image files
//   bank.hpp        training (views, trainTemplates) and the template bank file
//   config.hpp      DetectorParams: every stage's parameters, and the config file
//   detection.hpp   Detection and DetectionResult: what the detector finds in a frame
//   detector.hpp    Detector, the detection JSON and overlay pictures
//   evaluation.hpp  BOP datasets, the paper's metrics, the baselines, runEvaluation
//   synth.hpp       synthetic BOP datasets and the demo
//   picking.hpp     bin picking: grasp files, the bin, grasps placed and checked, the pick list
// Everything under src/ is internal and may change from one commit to the next (docs/api.md).
#include <string>

#include "vkpose/bank.hpp"
#include "vkpose/config.hpp"
#include "vkpose/detection.hpp"
#include "vkpose/detector.hpp"
#include "vkpose/device.hpp"
#include "vkpose/error.hpp"
#include "vkpose/evaluation.hpp"
#include "vkpose/frame.hpp"
#include "vkpose/geometry.hpp"
#include "vkpose/picking.hpp"
#include "vkpose/synth.hpp"

namespace vkpose {

/// The library's version, "MAJOR.MINOR.PATCH" (the CMake project's).
std::string version();

}  // namespace vkpose
