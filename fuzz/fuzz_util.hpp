#pragma once
// Shared by the libFuzzer harnesses: how a broken oracle is reported.
#include <cstdio>
#include <cstdlib>
#include <string>

namespace animat::fuzz {

/// An oracle failed: print why and abort, which libFuzzer records as a crash with its input.
[[noreturn]] inline void fail(const std::string& why) {
  std::fprintf(stderr, "\n==animat fuzz oracle failed: %s\n", why.c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace animat::fuzz
