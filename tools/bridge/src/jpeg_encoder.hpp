#pragma once
// JPEG for the foxglove.CompressedImage side channels (docs/foxglove.md): a mono8 image as a
// baseline greyscale JPEG, with libjpeg(-turbo) (Debian's libjpeg-dev). A build without it has
// no JPEG: jpeg_available() says so and the bridge offers no CompressedImage channel.

#include <cstdint>
#include <span>
#include <vector>

namespace oscar::bridge {

/// Whether this build of the bridge can make JPEG (libjpeg was found when it was configured).
bool jpeg_available();

/// The quality range libjpeg takes (1: smallest, 100: best).
inline constexpr int kMinJpegQuality = 1;
inline constexpr int kMaxJpegQuality = 100;

/// A greyscale JPEG of `width` x `height` mono8 pixels, row by row, at `quality`.
/// @throws std::invalid_argument if the pixels do not fill width x height, a dimension is
///         outside 1..65500 (JPEG's limit) or the quality outside 1..100;
///         std::runtime_error if libjpeg fails or this build has none (jpeg_available()).
std::vector<std::uint8_t> encode_mono8_jpeg(std::span<const std::uint8_t> pixels, long width,
                                            long height, int quality);

}  // namespace oscar::bridge
