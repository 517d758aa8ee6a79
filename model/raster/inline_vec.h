// InlineVec<T, N>: a vector of at most N elements stored in place (no heap), with the part of
// std::vector's interface the model uses. The span unit's attributes (NumAttr <= 16) and
// lane-triangles (NumTri <= 4) are bounded by the Verilog parameters, so descriptors, setup
// results and fragments hold them inline: a frame of 100,000 fragments then makes no
// allocation per fragment or per triangle. Exceeding N throws std::length_error.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <initializer_list>
#include <iterator>
#include <stdexcept>

namespace shd {

template <class T, size_t N>
class InlineVec {
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

  InlineVec() = default;
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
    std::fill_n(a_.begin(), n, v);
    n_ = n;
  }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  void assign(It first, It last) {
    const auto n = std::distance(first, last);
    check(static_cast<size_t>(n));
    std::copy(first, last, a_.begin());
    n_ = static_cast<size_t>(n);
  }
  void resize(size_t n, const T& v = T()) {
    check(n);
    if (n > n_) std::fill(a_.begin() + static_cast<std::ptrdiff_t>(n_), a_.begin() + static_cast<std::ptrdiff_t>(n), v);
    n_ = n;
  }
  void push_back(const T& v) {
    check(n_ + 1);
    a_[n_++] = v;
  }
  void clear() { n_ = 0; }

  size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  static constexpr size_t capacity() { return N; }
  T* data() { return a_.data(); }
  const T* data() const { return a_.data(); }
  T& operator[](size_t i) { return a_[i]; }
  const T& operator[](size_t i) const { return a_[i]; }
  T& at(size_t i) { return i < n_ ? a_[i] : throw std::out_of_range("InlineVec::at"); }
  const T& at(size_t i) const { return i < n_ ? a_[i] : throw std::out_of_range("InlineVec::at"); }
  T& front() { return a_[0]; }
  const T& front() const { return a_[0]; }
  T& back() { return a_[n_ - 1]; }
  const T& back() const { return a_[n_ - 1]; }
  iterator begin() { return a_.data(); }
  iterator end() { return a_.data() + n_; }
  const_iterator begin() const { return a_.data(); }
  const_iterator end() const { return a_.data() + n_; }

  friend bool operator==(const InlineVec& a, const InlineVec& b) {
    return a.n_ == b.n_ && std::equal(a.begin(), a.end(), b.begin());
  }
  friend bool operator!=(const InlineVec& a, const InlineVec& b) { return !(a == b); }

 private:
  static void check(size_t n) {
    if (n > N) throw std::length_error("InlineVec: more elements than its capacity");
  }
  std::array<T, N> a_{};
  size_t n_ = 0;
};

}  // namespace shd
