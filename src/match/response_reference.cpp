// Response maps and linear memories, CPU reference (LINEMOD sections 2.4, 2.5).
// shaders/response_linearize.comp computes the same bytes.
#include <algorithm>

#include "match/features.hpp"

namespace vkpose {

int responseFor(int bin, uint8_t spread_labels) {
  int best = 0;
  for (int j = 0; j < 8; ++j) {
    if (!(spread_labels & (1u << j))) continue;
    const int d = std::abs(bin - j);
    best = std::max(best, 4 - std::min(d, 8 - d));
  }
  return best;
}

std::array<cv::Mat, 8> computeResponseMaps(const cv::Mat& spread) {
  CV_Assert(spread.type() == CV_8UC1);
  std::array<cv::Mat, 8> maps;
  uint8_t lut[8][256];
  for (int b = 0; b < 8; ++b)
    for (int v = 0; v < 256; ++v) lut[b][v] = static_cast<uint8_t>(responseFor(b, static_cast<uint8_t>(v)));
  for (int b = 0; b < 8; ++b) {
    maps[b].create(spread.size(), CV_8UC1);
    for (int y = 0; y < spread.rows; ++y)
      for (int x = 0; x < spread.cols; ++x) maps[b].at<uint8_t>(y, x) = lut[b][spread.at<uint8_t>(y, x)];
  }
  return maps;
}

LinearMemoryLayout makeLinearMemoryLayout(int width, int height, int T, int max_template_cells, int extra_cells) {
  LinearMemoryLayout l;
  l.T = T;
  l.width = width;
  l.height = height;
  l.cells_x = (width + T - 1) / T;
  l.cells_y = (height + T - 1) / T;
  // Left/top: a template whose centre is inside the image may start half its size outside;
  // refinement windows reach `extra_cells` further. Right/bottom: the full template, the
  // window and one 16-cell block of overrun.
  l.pad = max_template_cells / 2 + extra_cells + 1;
  // A multiple of 32 cells: with a nibble per cell on the GPU, every row starts at one
  // 16-byte alignment.
  l.stride = (l.pad + l.cells_x + max_template_cells + extra_cells + 16 + 4 + 31) / 32 * 32;
  l.rows = l.pad + l.cells_y + max_template_cells + extra_cells + 1;
  return l;
}

void linearizeResponseMaps(const std::array<cv::Mat, 8>& response_maps, int modality,
                           const LinearMemoryLayout& layout, std::vector<uint8_t>& memory) {
  CV_Assert(memory.size() == layout.total_bytes());
  const int T = layout.T;
  for (int b = 0; b < 8; ++b) {
    const cv::Mat& map = response_maps[b];
    CV_Assert(map.cols == layout.width && map.rows == layout.height);
    for (int y = 0; y < map.rows; ++y)
      for (int x = 0; x < map.cols; ++x)
        memory[layout.offset(modality, b, y % T, x % T, y / T, x / T)] = map.at<uint8_t>(y, x);
  }
}

}  // namespace vkpose
