#pragma once
// Shared helpers of the test suites: the real frames in ../shared/data, skipping with a
// clear message when it is absent, and LINEMOD templates cut from a frame.
#include <cstdlib>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "match/features.hpp"
#include "vkpose/device.hpp"
#include "vkpose/bank.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose::test {

std::string sharedData();  ///< ../shared/data (VKPOSE_SHARED_DATA_DIR), or $VKPOSE_TEST_SHARED_DATA where set
bool haveSharedData();
/// A folder of this test process under the temporary directory, named `prefix` and the
/// process id (ctest runs tests in parallel processes); removed with what it holds when the
/// process exits, so test runs leave nothing behind.
std::string scratchDir(const std::string& prefix);

/// The real frames the parity tests use: LM-O scene 2 frame 3 and IC-BIN scene 2 frame 0.
LinemodFrame lmoFrame();
LinemodFrame icbinFrame();

// Stand-ins for tests that need "some frame" or "some mesh", not these in particular (GPU ==
// CPU parity, OpenCV parity, a mesh to render or train): the real data where it is there, so
// that CI's results stay what they were, and otherwise something vkpose makes itself, so that
// a newcomer without ../shared still runs them.

/// LM-O's frame, or else a synthetic 640 x 480 bin scene of the demo's three objects.
LinemodFrame lmoFrameOrStandIn();
/// IC-BIN's frame, or else another synthetic scene (another seed, a table).
LinemodFrame icbinFrameOrStandIn();
/// `name` ("LM-O") where the real frames are used, otherwise `name` marked as a stand-in.
std::string frameName(const std::string& name);
/// The mesh at `path` under sharedData() ("meshes/coffee_cup.stl"), loaded with `units`, or
/// else a procedural object of the same kind and size (synth/procedural_meshes.hpp): the
/// lidded cup for the coffee cup, the gable-top carton for the cartons and LM-O's can.
Mesh meshOrStandIn(const std::string& path, MeshUnits units = MeshUnits::Auto);

/// Templates cut with OpenCV's extraction from regions of `frame` (objects' boxes and
/// random boxes); `count` at most.
std::vector<LinemodTemplate> templatesFrom(const LinemodFrame& frame, const FeatureParams& params, int count,
                                           unsigned seed = 1);

/// The message of the InputError `f` throws; fails the test when it throws nothing.
std::string inputErrorOf(const std::function<void()>& f);
/// `f` throws an InputError whose message holds every one of `parts`.
void expectInputError(const std::function<void()>& f, std::initializer_list<std::string> parts);

/// A bank trained from `mesh` with `params`, cached in VKPOSE_TEST_CACHE_DIR between runs
/// under its training key (bank_cache.hpp; training takes about a minute per object on 2
/// cores): another mesh, other parameters or another bank version train again.
TemplateBank cachedBank(const Mesh& mesh, const TrainingParams& params);

/// One Vulkan context shared by all tests of a process (lavapipe in CI).
GpuContext& context();

}  // namespace vkpose::test

// Without ../shared/data a test that needs it skips, except where VKPOSE_REQUIRE_DATA is set
// (scripts/test.sh sets it under CI=true): there a missing data folder must fail, not pass green.
#define VKPOSE_REQUIRE_SHARED_DATA()                                                          \
  do {                                                                                        \
    if (!::vkpose::test::haveSharedData()) {                                                  \
      if (std::getenv("VKPOSE_REQUIRE_DATA"))                                                 \
        FAIL() << "../shared/data is absent, and VKPOSE_REQUIRE_DATA says it must be there";  \
      GTEST_SKIP() << "../shared/data is absent: this test needs the real RGB-D frames";      \
    }                                                                                         \
  } while (0)
