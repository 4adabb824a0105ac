#include "plain_kernels.hpp"

#include <memory>

#include "oscar/kernel_registry.hpp"

namespace oscar::test {

void fill_plain_image(PlainGvImage& image, std::uint64_t frame) {
  image.dx(kPlainImageWidth);
  image.dy(kPlainImageHeight);
  const std::size_t bytes = std::size_t{kPlainImageWidth} * kPlainImageHeight;
  image.byte_count(static_cast<std::uint32_t>(bytes));
  auto& pixels = image.image();
  for (std::size_t i = 0; i < 8; ++i) pixels[i] = static_cast<std::uint8_t>(frame >> (8 * i));
  for (std::size_t i = 8; i < bytes; ++i) pixels[i] = plain_pixel(frame, i);
}

std::uint64_t plain_image_frame(const PlainGvImage& image) {
  std::uint64_t frame = 0;
  for (std::size_t i = 0; i < 8; ++i) frame |= std::uint64_t{image.image()[i]} << (8 * i);
  return frame;
}

bool plain_image_complete(const PlainGvImage& image) {
  const std::size_t bytes = std::size_t{kPlainImageWidth} * kPlainImageHeight;
  if (image.dx() != kPlainImageWidth || image.dy() != kPlainImageHeight ||
      image.byte_count() != bytes) {
    return false;
  }
  const auto& pixels = image.image();
  const std::uint64_t frame = plain_image_frame(image);
  for (std::size_t i = 8; i < bytes; ++i) {
    if (pixels[i] != plain_pixel(frame, i)) return false;
  }
  return true;
}

PlainSource::PlainSource(KernelSetup& setup)
    : flag_(setup.output<PlainBool>("flag", {.depth = 64})),
      image_(setup.output<PlainGvImage>("image", {.depth = 4})) {}

void PlainSource::process(Cycle&) {
  ++cycles_;
  PlainBool flag;
  flag.value(cycles_ % 2 == 1);
  flag_.publish(flag);
  auto image = image_.loan();  // 442 KB, filled where it is published from
  fill_plain_image(*image, cycles_);
  last_image_ = &*image;
  image_.publish(std::move(image));
}

PlainSink::PlainSink(KernelSetup& setup)
    : flag_(setup.input<PlainBool>("flag", {.depth = 64})),
      image_(setup.input<PlainGvImage>("image", {.depth = 8})) {}

void PlainSink::process(Cycle&) {
  std::lock_guard lock(mutex_);
  for (const auto& r : flag_.take_new()) {
    flags_.push_back({.header = cue_type_info<PlainBool>().header.read(r.cue.get()),
                      .value = r.cue->value(),
                      .image_complete = false,
                      .frame = 0});
  }
  for (const auto& r : image_.take_new()) {
    images_.push_back({.header = cue_type_info<PlainGvImage>().header.read(r.cue.get()),
                       .value = false,
                       .image_complete = plain_image_complete(*r.cue),
                       .frame = plain_image_frame(*r.cue)});
  }
}

std::vector<PlainSeen> PlainSink::flags() {
  std::lock_guard lock(mutex_);
  return flags_;
}

std::vector<PlainSeen> PlainSink::images() {
  std::lock_guard lock(mutex_);
  return images_;
}

}  // namespace oscar::test

OSCAR_REGISTER_KERNEL(oscar::test::PlainSource, "test_plain_source")
OSCAR_REGISTER_KERNEL(oscar::test::PlainSink, "test_plain_sink")
