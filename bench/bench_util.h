#pragma once
// What every benchmark program shares: the median of timed passes, and the command-line loop (each
// program keeps its own options and usage text).
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

namespace bench {

/// The median of v (the mean of the two middle values for an even count); v must not be empty.
inline double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Walks argv[1..]: `handle(arg, value)` returns whether it knows `arg`, calling `value()` for an
/// option's argument. --help/-h calls usage(argv0, 0); an unknown option, a missing argument or one
/// that does not parse (a std::exception from std::stoi and the like) calls usage(argv0, 2).
/// `usage` must not return.
template <class Handle>
void ParseArgs(int argc, char** argv, void (*usage)(const char* argv0, int exitCode), Handle handle) {
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) usage(argv[0], 2);
        return argv[++i];
      };
      if (arg == "--help" || arg == "-h") usage(argv[0], 0);
      if (!handle(arg, value)) usage(argv[0], 2);
    }
  } catch (const std::exception&) {
    usage(argv[0], 2);
  }
}

}  // namespace bench
