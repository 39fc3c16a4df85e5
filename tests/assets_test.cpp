// assets/: what the project ships for users to start from. The example camera files must read
// as valid 640x480 cameras; the config and the meshes are compared with the code by
// tests/assets_test.sh (ctest: Assets.MatchTheCode).
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "vkpose/config.hpp"
#include "vkpose/geometry.hpp"

namespace vkpose {
namespace {

const std::filesystem::path kAssets = std::filesystem::path(VKPOSE_SOURCE_DIR) / "assets";

TEST(Assets, CameraFilesAreValidCameras) {
  for (const char* name : {"camera_primesense.json", "camera_realsense_d435.json"}) {
    SCOPED_TRACE(name);
    const Camera c = loadCamera((kAssets / name).string());
    EXPECT_NO_THROW(validateCamera(c));
    EXPECT_EQ(c.width, 640);
    EXPECT_EQ(c.height, 480);
    EXPECT_GT(c.fx, 500.0);  // 640-pixel-wide sensors of 50-65 degrees
    EXPECT_LT(c.fx, 700.0);
    EXPECT_NEAR(c.cx, 320.0, 5.0);
    EXPECT_NEAR(c.cy, 240.0, 5.0);
    EXPECT_EQ(c.depth_scale, 1.0);
  }
}

TEST(Assets, DefaultConfigReadsBackAsTheDefaults) {
  const DetectorParams read = loadConfig((kAssets / "config_defaults.json").string());
  EXPECT_EQ(configJson(read), configJson(DetectorParams{}));
}

TEST(Assets, DemoMeshesLoadWithFacesAndTheirSize) {
  int meshes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kAssets / "meshes")) {
    SCOPED_TRACE(entry.path().string());
    const Mesh mesh = loadMesh(entry.path().string(), MeshUnits::Millimetres);
    EXPECT_GT(mesh.faces.size(), 0u);
    EXPECT_FALSE(mesh.colours.empty());  // the demo paints its parts
    EXPECT_GT(mesh.diameter, 0.03f);  // the demo's parts are 5-20 cm
    EXPECT_LT(mesh.diameter, 0.3f);
    ++meshes;
  }
  EXPECT_EQ(meshes, 3);
}

}  // namespace
}  // namespace vkpose
