#include "oscar/process_util.hpp"

#include <sys/resource.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

namespace oscar {
namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitizedMalloc = true;  // the sanitizers bring an allocator of their own
#else
constexpr bool kSanitizedMalloc = false;
#endif

long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// Page faults while 60 images of 442 KB (26 MB) are allocated and written, as a replay's first
// seconds do.
long faults_writing_images() {
  constexpr std::size_t kImage = 768 * 576;
  std::vector<char*> images;
  const long before = minor_faults();
  for (int i = 0; i < 60; ++i) {
    images.push_back(static_cast<char*>(std::malloc(kImage)));
    for (std::size_t at = 0; at < kImage; at += 64) images.back()[at] = 1;
  }
  const long faults = minor_faults() - before;
  for (auto* image : images) std::free(image);
  return faults;
}

constexpr long kPagesOfTheImages = 60 * 768 * 576 / 4096;

TEST(PrefaultHeap, WritingFreshImagesFaultsOnEveryPageWithoutIt) {
  if (kSanitizedMalloc) GTEST_SKIP() << "a sanitizer replaces malloc: mallopt has no effect";
  EXPECT_EXIT(
      {
        keep_cue_memory_in_process();
        std::exit(faults_writing_images() > kPagesOfTheImages / 2 ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
}

TEST(PrefaultHeap, AfterItWritingThoseImagesFaultsOnAlmostNoPage) {
  if (kSanitizedMalloc) GTEST_SKIP() << "a sanitizer replaces malloc: mallopt has no effect";
  EXPECT_EXIT(
      {
        prefault_heap(std::size_t{32} << 20);
        std::exit(faults_writing_images() < kPagesOfTheImages / 20 ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace oscar
