#pragma once
// Kernels of the plain cue types (oscar/plain_cue_types.hpp) for oscar_plain_cue_test, and as a
// plugin (liboscar_kernel_test_plain.so) for its oscar-run children.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "oscar/kernel.hpp"
#include "oscar/plain_cue_types.hpp"

namespace oscar::test {

/// The width and height of the images PlainSource publishes: the largest a PlainGvImage holds.
inline constexpr short kPlainImageWidth = 768, kPlainImageHeight = 576;

/// The pixel at `index` of image number `frame`: every image differs, a pixel out of place shows.
inline std::uint8_t plain_pixel(std::uint64_t frame, std::size_t index) {
  return static_cast<std::uint8_t>(frame * 131 + index * 7 + index / 768);
}

/// Fills a full PlainGvImage as image number `frame`: its first 8 pixels hold `frame` (little
/// endian), the others plain_pixel(frame, index).
void fill_plain_image(PlainGvImage& image, std::uint64_t frame);
/// The frame number fill_plain_image() wrote into the first 8 pixels.
std::uint64_t plain_image_frame(const PlainGvImage& image);
/// Whether every pixel of `image` is as fill_plain_image() wrote it (the frame read from its
/// first 8 pixels), with the full size.
bool plain_image_complete(const PlainGvImage& image);

/// Publishes a PlainBool on "flag" (true on odd cycles, published by value) and a full
/// PlainGvImage on "image" (fill_plain_image with the cycle number, from 1, filled in a loan) on
/// every cycle; the frame completes the headers.
class PlainSource final : public Kernel {
 public:
  explicit PlainSource(KernelSetup& setup);
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override { process(cycle); }
  /// Where the last image was filled: it is loaned from the output (Output::loan()), so on the
  /// zero-copy path a chunk, which the output publishes without a copy.
  const void* last_image() const { return last_image_.load(); }

 private:
  Output<PlainBool>& flag_;
  Output<PlainGvImage>& image_;
  std::uint64_t cycles_ = 0;
  std::atomic<const void*> last_image_{nullptr};
};

/// What PlainSink saw of one cue: its header as read through the framework, and its content.
struct PlainSeen {
  CueHeader header{};
  bool value = false;           ///< a PlainBool's value
  bool image_complete = false;  ///< a PlainGvImage as PlainSource writes it, every pixel
  std::uint64_t frame = 0;      ///< a PlainGvImage's frame number (plain_image_frame)
};

/// Keeps what it receives on "flag" (PlainBool) and "image" (PlainGvImage).
class PlainSink final : public Kernel {
 public:
  explicit PlainSink(KernelSetup& setup);
  void process(Cycle& cycle) override;
  void stub(Cycle& cycle) override { process(cycle); }
  std::vector<PlainSeen> flags();
  std::vector<PlainSeen> images();

 private:
  Input<PlainBool>& flag_;
  Input<PlainGvImage>& image_;
  std::mutex mutex_;
  std::vector<PlainSeen> flags_, images_;
};

}  // namespace oscar::test
