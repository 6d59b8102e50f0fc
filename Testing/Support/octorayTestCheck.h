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

// A failed check: "file:line: what", counted.
inline void Report(const char* file, int line, const std::string& what)
{
  std::cerr << file << ":" << line << ": " << what << std::endl;
  ++Failures();
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
      octoray_test::Report(__FILE__, __LINE__, "check failed: " #cond);                            \
    }                                                                                              \
  } while (0)

// text contains part.
#define CHECK_CONTAINS(text, part)                                                                 \
  do                                                                                               \
  {                                                                                                \
    const std::string t_ = (text), p_ = (part);                                                    \
    if (t_.find(p_) == std::string::npos)                                                          \
    {                                                                                              \
      octoray_test::Report(__FILE__, __LINE__, "'" + t_ + "' lacks '" + p_ + "'");                 \
    }                                                                                              \
  } while (0)

// text is expected, to the character (error messages).
#define CHECK_EQ_STR(text, expected)                                                               \
  do                                                                                               \
  {                                                                                                \
    const std::string t_ = (text), e_ = (expected);                                                \
    if (t_ != e_)                                                                                  \
    {                                                                                              \
      octoray_test::Report(                                                                        \
        __FILE__, __LINE__, "\n  got      '" + t_ + "'\n  expected '" + e_ + "'");                \
    }                                                                                              \
  } while (0)

#endif
