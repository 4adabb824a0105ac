#include "jpeg_encoder.hpp"

#include <stdexcept>

#include <gtest/gtest.h>

namespace oscar::bridge {
namespace {

struct FrameHeader {
  int width = 0;
  int height = 0;
  int components = 0;
};

// The first start-of-frame (SOF0..SOF2) header of a JPEG, walking its marker segments.
FrameHeader frame_header(const std::vector<std::uint8_t>& jpeg) {
  std::size_t i = 2;  // after SOI
  while (i + 9 < jpeg.size()) {
    if (jpeg[i] != 0xFF) return {};
    const int marker = jpeg[i + 1];
    const std::size_t length = (jpeg[i + 2] << 8) | jpeg[i + 3];
    if (marker >= 0xC0 && marker <= 0xC2) {
      return {.width = (jpeg[i + 7] << 8) | jpeg[i + 8],
              .height = (jpeg[i + 5] << 8) | jpeg[i + 6],
              .components = jpeg[i + 9]};
    }
    i += 2 + length;
  }
  return {};
}

std::vector<std::uint8_t> gradient(int width, int height) {
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width * height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) pixels[y * width + x] = static_cast<std::uint8_t>(x + 3 * y);
  }
  return pixels;
}

TEST(JpegEncoder, MakesAGreyscaleJpegOfTheImagesSize) {
  if (!jpeg_available()) GTEST_SKIP() << "this build has no libjpeg";
  const auto jpeg = encode_mono8_jpeg(gradient(640, 480), 640, 480, 80);
  ASSERT_GT(jpeg.size(), 4u);
  EXPECT_EQ(jpeg[0], 0xFF);
  EXPECT_EQ(jpeg[1], 0xD8) << "starts with SOI";
  EXPECT_EQ(jpeg[jpeg.size() - 2], 0xFF);
  EXPECT_EQ(jpeg[jpeg.size() - 1], 0xD9) << "ends with EOI";
  const auto frame = frame_header(jpeg);
  EXPECT_EQ(frame.width, 640);
  EXPECT_EQ(frame.height, 480);
  EXPECT_EQ(frame.components, 1);
  EXPECT_LT(jpeg.size(), 640u * 480u / 4) << "a smooth gradient compresses well";
  const auto odd = encode_mono8_jpeg(gradient(13, 7), 13, 7, 80);
  EXPECT_EQ(frame_header(odd).width, 13);
  EXPECT_EQ(frame_header(odd).height, 7);
}

TEST(JpegEncoder, QualityTradesSizeForFidelity) {
  if (!jpeg_available()) GTEST_SKIP() << "this build has no libjpeg";
  std::vector<std::uint8_t> noise(320 * 240);
  std::uint32_t state = 12345;
  for (auto& p : noise) p = static_cast<std::uint8_t>((state = state * 1664525 + 1013904223) >> 24);
  EXPECT_LT(encode_mono8_jpeg(noise, 320, 240, 10).size(),
            encode_mono8_jpeg(noise, 320, 240, 95).size());
}

TEST(JpegEncoder, BadInputIsAnErrorNamingTheRule) {
  const auto pixels = gradient(4, 4);
  const auto message = [&](long w, long h, int q) {
    try {
      encode_mono8_jpeg(pixels, w, h, q);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message(4, 4, 0), "JPEG quality 0: must be 1 to 100");
  EXPECT_EQ(message(4, 4, 101), "JPEG quality 101: must be 1 to 100");
  EXPECT_EQ(message(4, 5, 80), "JPEG: 16 pixels do not fill a 4 x 5 mono8 image");
  EXPECT_EQ(message(0, 4, 80), "JPEG: image 0 x 4: each side must be 1 to 65500 pixels");
}

}  // namespace
}  // namespace oscar::bridge
