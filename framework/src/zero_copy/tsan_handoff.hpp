#pragma once
// ThreadSanitizer and iceoryx (internal to src/zero_copy): a chunk passes from publisher to
// subscriber and back to the publisher's pool through iceoryx's lock-free queues, whose atomics
// live in Debian's uninstrumented libiceoryx, so ThreadSanitizer sees no order between the
// producer's writes and the consumer's reads (a false data race, seen on the in-process wiring
// test). These tell it what iceoryx guarantees; without ThreadSanitizer they are nothing.

#if defined(__SANITIZE_THREAD__)
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
#endif

namespace oscar::zero_copy::internal {

/// Before a chunk is handed on (published, or given back to its pool).
inline void handing_over(const void* chunk) {
#if defined(__SANITIZE_THREAD__)
  __tsan_release(const_cast<void*>(chunk));
#else
  (void)chunk;
#endif
}

/// After a chunk was received (taken, or loaned from the pool).
inline void taken_over(const void* chunk) {
#if defined(__SANITIZE_THREAD__)
  __tsan_acquire(const_cast<void*>(chunk));
#else
  (void)chunk;
#endif
}

}  // namespace oscar::zero_copy::internal
