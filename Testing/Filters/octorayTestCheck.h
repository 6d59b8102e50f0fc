// A minimal check macro for the C++ tests: prints the failed condition with
// its line and makes the test fail, without stopping at the first failure.
#ifndef octorayTestCheck_h
#define octorayTestCheck_h

#include <iostream>

static int octorayTestFailures = 0;
#define CHECK(cond)                                                                                \
  do                                                                                               \
  {                                                                                                \
    if (!(cond))                                                                                   \
    {                                                                                              \
      std::cerr << __FILE__ << ":" << __LINE__ << ": check failed: " #cond << std::endl;           \
      ++octorayTestFailures;                                                                       \
    }                                                                                              \
  } while (0)
#define CHECK_CONTAINS(text, part)                                                                 \
  do                                                                                               \
  {                                                                                                \
    const std::string t_ = (text);                                                                 \
    if (t_.find(part) == std::string::npos)                                                        \
    {                                                                                              \
      std::cerr << __FILE__ << ":" << __LINE__ << ": '" << t_ << "' lacks '" << (part) << "'"     \
                << std::endl;                                                                      \
      ++octorayTestFailures;                                                                       \
    }                                                                                              \
  } while (0)

#endif
