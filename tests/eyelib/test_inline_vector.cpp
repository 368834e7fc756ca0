// InlineVector: MNEE's solutions, in place up to N and on the heap past it, contiguous and in order either way.
#include "eyelib/inline_vector.h"

#include <catch2/catch.hpp>

#include <numeric>

TEST_CASE("an InlineVector keeps its elements in order in place and past its inline size", "[inline_vector]") {
  eyelib::InlineVector<int, 3> v;
  CHECK(v.empty());
  CHECK(v.begin() == v.end());
  for (int k = 1; k <= 7; ++k) {
    v.push_back(k * 10);
    REQUIRE(v.size() == std::size_t(k));
    CHECK(v.end() - v.begin() == k);
    for (int i = 0; i < k; ++i) CHECK(v[i] == (i + 1) * 10);  // the move to the heap at 4 keeps the first three
  }
  CHECK(v.front() == 10);
  CHECK(std::accumulate(v.begin(), v.end(), 0) == 280);
  const eyelib::InlineVector<int, 3> copy = v;  // a copy reads its own storage, not the original's
  CHECK(copy.size() == 7);
  CHECK(copy[6] == 70);
  CHECK(copy.begin() != v.begin());
}
