// SpscRing: items in order through a ring of slots, one thread writing and one reading, each
// slot filled in place by the writer and read in place by the reader (no copy). Each side makes
// its progress visible to the other every Batch items, when the writer asks for it (push(true)),
// and before it waits, so neither waits for a count the other has not yet shown. Both wait by
// spinning, yielding after a while: the two users (a two-thread frame, about a millisecond, and
// the co-simulation's model ahead of the RTL, a few microseconds of slack) cannot afford a sleep
// and wake-up. The reader's stop or failure stops the writer (slot() throws ReaderStopped), the
// writer's abort the reader (next() returns null).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <thread>
#include <vector>

#include <immintrin.h>

namespace shd {

// The cache lines of [from, to) fetched for writing (PREFETCHW). A writer's next slots were last
// read by the reader's core: without it each store to them waits for its line, and a few lines
// in flight fill the store queue (the users say what it saved).
inline void prefetchForWrite(const void* from, const void* to) {
  const uintptr_t end = reinterpret_cast<uintptr_t>(to);
  for (uintptr_t a = reinterpret_cast<uintptr_t>(from) & ~uintptr_t{63}; a < end; a += 64)
    asm volatile("prefetchw %0" ::"m"(*reinterpret_cast<const char*>(a)));
}

// One round of a wait by spinning: a pause, and after 1,024 rounds a yield, so that a waiter
// sharing its core with the thread it waits for lets it run.
inline void spinPause(unsigned spin) {
  if (spin < 1024) _mm_pause();
  else std::this_thread::yield();
}

template <class T, size_t Slots, size_t Batch>
class SpscRing {
  static_assert(Slots % Batch == 0, "a batch never wraps");

 public:
  static constexpr size_t kSlots = Slots;
  SpscRing() : slots_(Slots) {}
  // Empty again (the slots and their memory kept).
  void reset() {
    head_ = done_seen_ = tail_ = written_seen_ = 0;
    written_.store(0, std::memory_order_relaxed);
    done_.store(0, std::memory_order_relaxed);
    stopped_.store(false, std::memory_order_relaxed);
    aborted_.store(false, std::memory_order_relaxed);
    error_ = nullptr;
  }
  // The writer: the next slot, filled in place, then push()ed (show_now: visible at once).
  T& slot() {
    if (head_ - done_seen_ == Slots) {
      written_.store(head_, std::memory_order_release);
      for (unsigned spin = 0; head_ - (done_seen_ = done_.load(std::memory_order_acquire)) == Slots; ++spin) {
        if (stopped_.load(std::memory_order_acquire)) throw ReaderStopped{};
        spinPause(spin);
      }
    }
    return slots_[head_ % Slots];
  }
  // The writer's slot k after the current one, to prefetch (the reader may still hold it).
  const T& ahead(size_t k) const { return slots_[(head_ + k) % Slots]; }
  // The items pushed that the reader has not yet shown done: at most Slots, at least those it
  // still holds (it shows its progress every Batch items).
  size_t backlog() const { return head_ - done_.load(std::memory_order_relaxed); }
  void push(bool show_now = false) {
    if (++head_ % Batch == 0 || show_now) written_.store(head_, std::memory_order_release);
  }
  // The writer's end without its last items: the reader's next() returns null.
  void abort() { aborted_.store(true, std::memory_order_release); }

  // The reader: the next item (null when the writer aborted), the reader's (to read and to
  // write in place) until it release()s it.
  T* next() {
    if (tail_ == written_seen_) {
      done_.store(tail_, std::memory_order_release);
      for (unsigned spin = 0; tail_ == (written_seen_ = written_.load(std::memory_order_acquire)); ++spin) {
        if (aborted_.load(std::memory_order_acquire)) return nullptr;
        spinPause(spin);
      }
    }
    return &slots_[tail_ % Slots];
  }
  void release() {
    if (++tail_ % Batch == 0) done_.store(tail_, std::memory_order_release);
  }
  // The reader reads no more: with its exception, if it failed (null: it stopped by choice).
  void stop(std::exception_ptr e = nullptr) {
    error_ = std::move(e);
    stopped_.store(true, std::memory_order_release);
  }
  // After the reader has ended (joined): its exception, if it failed.
  std::exception_ptr error() const { return error_; }
  // Thrown by slot() when the reader has stopped.
  struct ReaderStopped {};

 private:
  // Each side's own fields in cache lines of their own: a line written by one thread and read
  // by the other moves between the cores at every write (on builtin:sphere's two-thread gouraud
  // frame the writer's load of head_, beside the reader's tail_, took a tenth of its time).
  std::vector<T> slots_;
  std::exception_ptr error_;
  alignas(64) size_t head_ = 0, done_seen_ = 0;     // the writer's
  alignas(64) size_t tail_ = 0, written_seen_ = 0;  // the reader's
  alignas(64) std::atomic<size_t> written_{0};
  alignas(64) std::atomic<size_t> done_{0};
  alignas(64) std::atomic<bool> stopped_{false}, aborted_{false};
};

}  // namespace shd
