// The orientation bins decided without atan are exact for every Sobel value.
#include <cmath>

#include <gtest/gtest.h>

#include "match/features.hpp"

namespace vkpose {
namespace {

int exactGradientBin(int gx, int gy) {
  long double deg = std::atan2(static_cast<long double>(gy), static_cast<long double>(gx)) * 180.0L / 3.14159265358979323846L;
  if (deg < 0) deg += 360.0L;
  return static_cast<int>(std::llround(deg / 22.5L)) & 7;
}

TEST(OrientationBins, GradientBinIsExactForEverySobelValue) {
  int mismatches = 0;
  for (int gx = -1020; gx <= 1020; ++gx)
    for (int gy = -1020; gy <= 1020; ++gy)
      if (gradientOrientationBin(gx, gy) != exactGradientBin(gx, gy)) ++mismatches;
  EXPECT_EQ(mismatches, 0);
}

TEST(OrientationBins, GradientSignIsIgnored) {
  EXPECT_EQ(gradientOrientationBin(10, 0), 0);
  EXPECT_EQ(gradientOrientationBin(-10, 0), 0);
  EXPECT_EQ(gradientOrientationBin(0, 10), 4);
  EXPECT_EQ(gradientOrientationBin(0, -10), 4);
  EXPECT_EQ(gradientOrientationBin(10, 10), 2);
  EXPECT_EQ(gradientOrientationBin(-10, -10), 2);
  EXPECT_EQ(gradientOrientationBin(-10, 10), 6);
  EXPECT_EQ(gradientOrientationBin(0, 0), 0);
}

TEST(OrientationBins, NormalBinsAreFortyFiveDegreeSectors) {
  // Directions k * 45 degrees land in bin k (image x right, y down), as OpenCV's DepthNormal.
  const int dirs[8][2] = {{10, 0}, {10, 10}, {0, 10}, {-10, 10}, {-10, 0}, {-10, -10}, {0, -10}, {10, -10}};
  for (int k = 0; k < 8; ++k) EXPECT_EQ(normalOrientationBin(dirs[k][0], dirs[k][1]), k) << "direction " << k;
  EXPECT_EQ(normalOrientationBin(0, 0), 0);  // a surface facing the camera: bin 0, as OpenCV
  EXPECT_EQ(normalOrientationBin(100, 40), 0);   // 21.8 degrees
  EXPECT_EQ(normalOrientationBin(100, 42), 1);   // 22.8 degrees
}

TEST(Responses, AreAQuantizedCosineOfTheNearestOrientation) {
  EXPECT_EQ(responseFor(0, 0), 0);
  EXPECT_EQ(responseFor(0, 1u << 0), 4);
  EXPECT_EQ(responseFor(0, 1u << 1), 3);
  EXPECT_EQ(responseFor(0, 1u << 7), 3);
  EXPECT_EQ(responseFor(0, 1u << 2), 2);
  EXPECT_EQ(responseFor(0, 1u << 3), 1);
  EXPECT_EQ(responseFor(0, 1u << 4), 0);
  EXPECT_EQ(responseFor(3, (1u << 4) | (1u << 0)), 3);
}

}  // namespace
}  // namespace vkpose
