// FunctionRef: a non-owning callable reference, called where std::function was (random numbers, shadow rays).
#include "eyelib/function_ref.h"

#include <catch2/catch.hpp>

#include <functional>

using eyelib::FunctionRef;

namespace {
double Twice(FunctionRef<double()> random) { return random() + random(); }
}  // namespace

TEST_CASE("a FunctionRef calls the callable it was made from, which keeps its state, and passes arguments through",
          "[function_ref]") {
  auto counter = [n = 0]() mutable { return double(++n); };  // a copy would start again from 0
  CHECK(Twice(counter) == 3.0);                              // 1 + 2
  CHECK(Twice(counter) == 7.0);                              // 3 + 4: the same lambda, not a copy

  const auto scale = [](std::size_t k, double x) { return double(k) * x; };
  const FunctionRef<double(std::size_t, double)> ref = scale;
  CHECK(ref(3, 0.5) == 1.5);
}

TEST_CASE("a FunctionRef to a std::function calls it, and an empty FunctionRef is false", "[function_ref]") {
  double next = 0.25;
  const std::function<double()> owning = [&next] { return next += 0.25; };
  const FunctionRef<double()> ref = owning;
  CHECK(bool(ref));
  CHECK(ref() == 0.5);
  CHECK(ref() == 0.75);
  CHECK_FALSE(bool(FunctionRef<double()>{}));
}
