// GoogleTest main. In Debug builds floating-point traps are on, so a NaN stops where it starts
// (as libigl's test main does).
#include <gtest/gtest.h>
#ifndef NDEBUG
#include <cfenv>
#endif

int main(int argc, char** argv) {
#if !defined(NDEBUG) && defined(__GLIBC__)
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
#endif
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
