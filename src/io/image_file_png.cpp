// Image files through libpng alone, PNG only (VKPOSE_LIBPNG_IMAGES; see image_file.hpp).
// Pixels come out as cv::imread gives them: BGR(A) order, 16-bit samples in host order.
#include <algorithm>
#include <cctype>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

#include <png.h>

#include "io/image_file.hpp"

namespace vkpose {

namespace {

// libpng reports errors by longjmp, which skips destructors: the functions below that call
// into libpng under setjmp hold only plain data; whatever owns memory lives in their callers.

struct PngError {
  char message[256] = "";
};

void onError(png_structp png, png_const_charp message) {
  auto* error = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(error->message, sizeof error->message, "%s", message);
  png_longjmp(png, 1);
}

void onWarning(png_structp, png_const_charp) {}

struct MemoryInput {
  const unsigned char* data;
  std::size_t size, position;
};

void readFromMemory(png_structp png, png_bytep out, png_size_t count) {
  auto* in = static_cast<MemoryInput*>(png_get_io_ptr(png));
  if (count > in->size - in->position) png_error(png, "the file ends too early");
  std::memcpy(out, in->data + in->position, count);
  in->position += count;
}

struct ReadStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~ReadStructs() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};

struct Layout {
  png_uint_32 width = 0, height = 0;
  int channels = 0, bit_depth = 0;
};

/// Reads the header and sets the transforms that give cv::imread's layout. False on a libpng error.
bool readHeader(png_structp png, png_infop info, ImageChannels channels, Layout& layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  const int colour_type = png_get_color_type(png, info);
  const bool has_transparency = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
  if (colour_type == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (colour_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (channels == ImageChannels::Grey) {
    png_set_strip_alpha(png);
    if (colour_type & PNG_COLOR_MASK_COLOR || colour_type == PNG_COLOR_TYPE_PALETTE)
      png_set_rgb_to_gray(png, 1, 0.299, 0.587);  // red and green weights, as OpenCV's decoder
  } else {
    if (has_transparency) png_set_tRNS_to_alpha(png);
    if (colour_type == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
    png_set_bgr(png);
  }
  if (png_get_bit_depth(png, info) == 16) png_set_swap(png);  // PNG stores 16-bit samples big-endian
  png_read_update_info(png, info);
  layout = {png_get_image_width(png, info), png_get_image_height(png, info), png_get_channels(png, info),
            png_get_bit_depth(png, info)};
  return true;
}

bool readRows(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, info);
  return true;
}

struct WriteStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~WriteStructs() { png_destroy_write_struct(&png, info ? &info : nullptr); }
};

bool writeRows(png_structp png, png_infop info, std::FILE* file, const Layout& layout, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, file);
  static constexpr int kColourTypes[] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                         PNG_COLOR_TYPE_RGB_ALPHA};
  png_set_IHDR(png, info, layout.width, layout.height, layout.bit_depth, kColourTypes[layout.channels],
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);  // cv::imwrite's default (IMWRITE_PNG_COMPRESSION 1)
  png_write_info(png, info);
  if (layout.channels >= 3) png_set_bgr(png);
  if (layout.bit_depth == 16) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

}  // namespace

cv::Mat readImageFile(const std::string& path, ImageChannels channels, std::string& why) {
  std::ifstream file(path, std::ios::binary);
  const std::vector<unsigned char> bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0) {
    if (!bytes.empty()) why = "not a PNG file (this build reads PNG only: VKPOSE_LIBPNG_IMAGES)";
    return {};
  }
  PngError error;
  ReadStructs s;
  s.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, onError, onWarning);
  if (s.png) s.info = png_create_info_struct(s.png);
  if (!s.info) {
    why = "out of memory";
    return {};
  }
  MemoryInput input{bytes.data(), bytes.size(), 0};
  png_set_read_fn(s.png, &input, readFromMemory);
  Layout layout;
  if (!readHeader(s.png, s.info, channels, layout)) {
    why = error.message;
    return {};
  }
  // cv::imread's limits (CV_IO_MAX_IMAGE_WIDTH, _HEIGHT and _PIXELS).
  if (layout.width == 0 || layout.height == 0 || layout.width > 1u << 20 || layout.height > 1u << 20 ||
      std::uint64_t{layout.width} * layout.height > 1ull << 30) {
    why = "image of " + std::to_string(layout.width) + "x" + std::to_string(layout.height) + " pixels";
    return {};
  }
  cv::Mat image(static_cast<int>(layout.height), static_cast<int>(layout.width),
                CV_MAKETYPE(layout.bit_depth == 16 ? CV_16U : CV_8U, layout.channels));
  std::vector<png_bytep> rows(layout.height);
  for (int y = 0; y < image.rows; ++y) rows[y] = image.ptr(y);
  if (!readRows(s.png, s.info, rows.data())) {
    why = error.message;
    return {};
  }
  return image;
}

bool writeImageFile(const std::string& path, const cv::Mat& image, std::string& why) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension != ".png" || image.empty()) return false;
  if ((image.depth() != CV_8U && image.depth() != CV_16U) || image.channels() == 2) {
    why = "PNG takes 8 or 16 bits of 1, 3 or 4 channels";
    return false;
  }
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"), std::fclose);
  if (!file) return false;
  PngError error;
  WriteStructs s;
  s.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, onError, onWarning);
  if (s.png) s.info = png_create_info_struct(s.png);
  if (!s.info) {
    why = "out of memory";
    return false;
  }
  const Layout layout{static_cast<png_uint_32>(image.cols), static_cast<png_uint_32>(image.rows), image.channels(),
                      image.depth() == CV_16U ? 16 : 8};
  std::vector<png_bytep> rows(image.rows);
  for (int y = 0; y < image.rows; ++y) rows[y] = const_cast<png_bytep>(image.ptr(y));  // libpng only reads them
  if (!writeRows(s.png, s.info, file.get(), layout, rows.data())) {
    why = error.message;
    return false;
  }
  return true;
}

}  // namespace vkpose
