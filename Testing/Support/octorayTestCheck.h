// The checks of the project's C++ tests that are not GoogleTest (the VTK
// modules' Testing/Cxx, Testing/Reliability): a failed check prints its
// file, line and what failed, and the test goes on, so that one run shows
// every failure; the test then returns octoray_test::Result(), which fails
// it when any check failed. Header-only and VTK-free; the CMake target
// octoray::TestCheck puts it on a test's include path.
#ifndef octorayTestCheck_h
#define octorayTestCheck_h

#include <cstdlib>
#include <iostream>
#include <string>

namespace octoray_test
{
inline int& Failures()
{
  static int failures = 0;
  return failures;
}

// EXIT_SUCCESS, or EXIT_FAILURE after saying how many checks failed.
inline int Result()
{
  if (Failures() == 0)
  {
    return EXIT_SUCCESS;
  }
  std::cerr << Failures() << " check(s) failed" << std::endl;
  return EXIT_FAILURE;
}
} // namespace octoray_test

#define CHECK(cond)                                                                                \
  do                                                                                               \
  {                                                                                                \
    if (!(cond))                                                                                   \
    {                                                                                              \
      std::cerr << __FILE__ << ":" << __LINE__ << ": check failed: " #cond << std::endl;           \
      ++octoray_test::Failures();                                                                  \
    }                                                                                              \
  } while (0)

// text contains part.
#define CHECK_CONTAINS(text, part)                                                                 \
  do                                                                                               \
  {                                                                                                \
    const std::string t_ = (text);                                                                 \
    if (t_.find(part) == std::string::npos)                                                        \
    {                                                                                              \
      std::cerr << __FILE__ << ":" << __LINE__ << ": '" << t_ << "' lacks '" << (part) << "'"     \
                << std::endl;                                                                      \
      ++octoray_test::Failures();                                                                  \
    }                                                                                              \
  } while (0)

// text is expected, to the character (error messages).
#define CHECK_EQ_STR(text, expected)                                                               \
  do                                                                                               \
  {                                                                                                \
    const std::string t_ = (text), e_ = (expected);                                                \
    if (t_ != e_)                                                                                  \
    {                                                                                              \
      std::cerr << __FILE__ << ":" << __LINE__ << ":\n  got      '" << t_ << "'\n  expected '"    \
                << e_ << "'" << std::endl;                                                         \
      ++octoray_test::Failures();                                                                  \
    }                                                                                              \
  } while (0)

#endif
