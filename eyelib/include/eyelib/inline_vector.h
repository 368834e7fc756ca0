#pragma once
// A vector whose first N elements live in place: MNEE finds one to three paths per estimate, and a heap allocation
// for each would cost as much as a Newton step. Past N the elements move to the heap. Contiguous either way.
#include <array>
#include <cstddef>
#include <vector>

namespace eyelib {

template <class T, std::size_t N> class InlineVector {
 public:
  void push_back(const T& value) {
    if (heap_.empty() && size_ < N) {
      inline_[size_++] = value;
      return;
    }
    if (heap_.empty()) heap_.assign(inline_.begin(), inline_.begin() + size_);
    heap_.push_back(value);
    ++size_;
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T* begin() const { return heap_.empty() ? inline_.data() : heap_.data(); }
  const T* end() const { return begin() + size_; }
  const T& operator[](std::size_t i) const { return begin()[i]; }
  const T& front() const { return *begin(); }

 private:
  std::array<T, N> inline_{};
  std::vector<T> heap_;
  std::size_t size_ = 0;
};

}  // namespace eyelib
