// InlineVec<T, N>: a vector of at most N elements stored in place (no heap), with the part of
// std::vector's interface the model uses. The span unit's attributes (NumAttr <= 16) and
// lane-triangles (NumTri <= 4) are bounded by the Verilog parameters, so descriptors, setup
// results and fragments hold them inline: a frame of 100,000 fragments then makes no
// allocation per fragment or per triangle. Exceeding N throws std::length_error.
// Elements are constructed when they are added (the storage beyond size() holds no object, so
// an empty InlineVec<SpanLaneTri, 4> constructs no lane-triangle) and a copy copies size()
// elements: a descriptor's 16-attribute capacity costs nothing when it holds 4. T must be
// trivially destructible (no destructor runs when elements are dropped or overwritten).
#pragma once

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <iterator>
#include <new>
#include <stdexcept>
#include <type_traits>

namespace shd {

template <class T, size_t N>
class InlineVec {
  static_assert(std::is_trivially_destructible<T>::value, "InlineVec drops elements without destroying them");

 public:
  using value_type = T;
  using size_type = size_t;
  using difference_type = std::ptrdiff_t;
  using reference = T&;
  using const_reference = const T&;
  using pointer = T*;
  using const_pointer = const T*;
  using iterator = T*;
  using const_iterator = const T*;

  InlineVec() {}  // no element constructed (see above)
  InlineVec(const InlineVec& o) { assign(o.begin(), o.end()); }
  InlineVec& operator=(const InlineVec& o) {
    if (this != &o) assign(o.begin(), o.end());
    return *this;
  }
  explicit InlineVec(size_t n, const T& v = T()) { assign(n, v); }
  InlineVec(std::initializer_list<T> l) { assign(l.begin(), l.end()); }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  InlineVec(It first, It last) {
    assign(first, last);
  }
  InlineVec& operator=(std::initializer_list<T> l) {
    assign(l.begin(), l.end());
    return *this;
  }

  void assign(size_t n, const T& v) {
    check(n);
    for (size_t i = 0; i < n; ++i) ::new (static_cast<void*>(a_ + i)) T(v);
    n_ = n;
  }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  void assign(It first, It last) {
    check(static_cast<size_t>(std::distance(first, last)));
    size_t i = 0;
    for (; first != last; ++first, ++i) ::new (static_cast<void*>(a_ + i)) T(*first);
    n_ = i;
  }
  void resize(size_t n, const T& v = T()) {
    check(n);
    for (size_t i = n_; i < n; ++i) ::new (static_cast<void*>(a_ + i)) T(v);
    n_ = n;
  }
  // n elements, those beyond the current size left uninitialised, for the caller to write
  // (trivial types only: reading one before writing it is as reading an uninitialised int).
  void resizeForOverwrite(size_t n) {
    static_assert(std::is_trivial<T>::value, "resizeForOverwrite leaves elements unconstructed");
    check(n);
    n_ = n;
  }
  void push_back(const T& v) {
    check(n_ + 1);
    ::new (static_cast<void*>(a_ + n_)) T(v);
    ++n_;
  }
  T& emplace_back() {  // a value-initialised element built in place (no temporary to copy)
    check(n_ + 1);
    return *::new (static_cast<void*>(a_ + n_++)) T();
  }
  void clear() { n_ = 0; }

  size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  static constexpr size_t capacity() { return N; }
  T* data() { return a_; }
  const T* data() const { return a_; }
  T& operator[](size_t i) { return a_[i]; }
  const T& operator[](size_t i) const { return a_[i]; }
  T& at(size_t i) { return i < n_ ? a_[i] : throw std::out_of_range("InlineVec::at"); }
  const T& at(size_t i) const { return i < n_ ? a_[i] : throw std::out_of_range("InlineVec::at"); }
  T& front() { return a_[0]; }
  const T& front() const { return a_[0]; }
  T& back() { return a_[n_ - 1]; }
  const T& back() const { return a_[n_ - 1]; }
  iterator begin() { return a_; }
  iterator end() { return a_ + n_; }
  const_iterator begin() const { return a_; }
  const_iterator end() const { return a_ + n_; }

  // A loop, not std::equal: for integers that becomes a call of memcmp, which for the few
  // elements held here costs more than the comparison (the mode-equality tests compare every
  // fragment's attributes).
  friend bool operator==(const InlineVec& a, const InlineVec& b) {
    if (a.n_ != b.n_) return false;
    for (size_t i = 0; i < a.n_; ++i)
      if (!(a.a_[i] == b.a_[i])) return false;
    return true;
  }
  friend bool operator!=(const InlineVec& a, const InlineVec& b) { return !(a == b); }

 private:
  static void check(size_t n) {
    if (n > N) throw std::length_error("InlineVec: more elements than its capacity");
  }
  union {
    T a_[N];  // elements [0, n_) constructed in place
  };
  size_t n_ = 0;
};

}  // namespace shd
