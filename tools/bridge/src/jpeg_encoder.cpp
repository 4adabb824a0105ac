#include "jpeg_encoder.hpp"

#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#ifdef OSCAR_BRIDGE_HAVE_JPEG
#include <jpeglib.h>
#endif

namespace oscar::bridge {

namespace {
constexpr long kMaxJpegSide = 65500;  // JPEG_MAX_DIMENSION

void check_arguments(std::size_t pixels, long width, long height, int quality) {
  if (width < 1 || height < 1 || width > kMaxJpegSide || height > kMaxJpegSide) {
    throw std::invalid_argument(fmt::format("JPEG: image {} x {}: each side must be 1 to {} pixels",
                                            width, height, kMaxJpegSide));
  }
  if (pixels != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw std::invalid_argument(
        fmt::format("JPEG: {} pixels do not fill a {} x {} mono8 image", pixels, width, height));
  }
  if (quality < kMinJpegQuality || quality > kMaxJpegQuality) {
    throw std::invalid_argument(fmt::format("JPEG quality {}: must be {} to {}", quality,
                                            kMinJpegQuality, kMaxJpegQuality));
  }
}
}  // namespace

#ifdef OSCAR_BRIDGE_HAVE_JPEG

namespace {
// libjpeg reports errors through error_exit, which must not return: it jumps back to encode.
struct ErrorJump {
  jpeg_error_mgr manager{};
  std::jmp_buf back{};
  char message[JMSG_LENGTH_MAX]{};
};

extern "C" void jump_on_error(j_common_ptr info) {
  auto* error = reinterpret_cast<ErrorJump*>(info->err);
  (*info->err->format_message)(info, error->message);
  std::longjmp(error->back, 1);
}

// Everything libjpeg allocated, freed on every path (no C++ object with a destructor lives
// between setjmp and longjmp).
struct Compressor {
  jpeg_compress_struct info{};
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  ~Compressor() {
    jpeg_destroy_compress(&info);
    std::free(buffer);
  }
};
}  // namespace

bool jpeg_available() { return true; }

std::vector<std::uint8_t> encode_mono8_jpeg(std::span<const std::uint8_t> pixels, long width,
                                            long height, int quality) {
  check_arguments(pixels.size(), width, height, quality);
  Compressor c;
  ErrorJump error;
  c.info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = jump_on_error;
  if (setjmp(error.back) != 0) {
    throw std::runtime_error(std::string("JPEG: libjpeg: ") + error.message);
  }
  jpeg_create_compress(&c.info);
  jpeg_mem_dest(&c.info, &c.buffer, &c.size);
  c.info.image_width = static_cast<JDIMENSION>(width);
  c.info.image_height = static_cast<JDIMENSION>(height);
  c.info.input_components = 1;
  c.info.in_color_space = JCS_GRAYSCALE;
  jpeg_set_defaults(&c.info);
  jpeg_set_quality(&c.info, quality, TRUE);
  jpeg_start_compress(&c.info, TRUE);
  while (c.info.next_scanline < c.info.image_height) {
    // libjpeg's API takes rows as non-const; it only reads them.
    JSAMPROW row = const_cast<JSAMPLE*>(pixels.data() + c.info.next_scanline * width);
    jpeg_write_scanlines(&c.info, &row, 1);
  }
  jpeg_finish_compress(&c.info);
  return {c.buffer, c.buffer + c.size};
}

#else

bool jpeg_available() { return false; }

std::vector<std::uint8_t> encode_mono8_jpeg(std::span<const std::uint8_t> pixels, long width,
                                            long height, int quality) {
  check_arguments(pixels.size(), width, height, quality);
  throw std::runtime_error("JPEG: this bridge was built without libjpeg (install libjpeg-dev)");
}

#endif

}  // namespace oscar::bridge
