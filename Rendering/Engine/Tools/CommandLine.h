// The command lines of the octoray tool and of the benchmarks: `--name
// value` options and `--name` flags, after the positional arguments. Each
// option writes its variable as it is parsed; a value that does not parse,
// an unknown option or a missing value stops the parse with a message that
// names the option, what it expects and what it got. `--help` or `-h`
// asks for the usage, which goes to stdout with exit status 0.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace octoray
{
// A comma-separated list, empty items dropped.
inline std::vector<std::string> SplitList(const std::string& list)
{
  std::vector<std::string> items;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ','))
  {
    if (!item.empty())
    {
      items.push_back(item);
    }
  }
  return items;
}

class CommandLine
{
public:
  // parse(value): false where the value is not one the option takes.
  using Parser = std::function<bool(const std::string&)>;

  // `expects` completes "NAME expects ...", for the message of a bad value.
  CommandLine& Option(const char* name, std::string expects, Parser parse)
  {
    Options.push_back(Entry{ name, std::move(expects), std::move(parse), false });
    return *this;
  }
  // An option without a value: sets `into`.
  CommandLine& Flag(const char* name, bool& into)
  {
    Parser set = [&into](const std::string&) {
      into = true;
      return true;
    };
    Options.push_back(Entry{ name, "", std::move(set), true });
    return *this;
  }
  CommandLine& Text(const char* name, std::string& into)
  {
    return Option(name, "a value", [&into](const std::string& v) {
      into = v;
      return true;
    });
  }
  // One of `allowed`, e.g. the backend.
  CommandLine& Choice(const char* name, std::string& into, std::vector<std::string> values)
  {
    std::string expects = "one of";
    for (const std::string& v : values)
    {
      expects += (&v == &values.front() ? " " : ", ") + v;
    }
    return Option(name, expects, [&into, values](const std::string& v) {
      if (std::find(values.begin(), values.end(), v) == values.end())
      {
        return false;
      }
      into = v;
      return true;
    });
  }
  // A whole number from `least` to `most`.
  CommandLine& Integer(const char* name, int& into, int least = std::numeric_limits<int>::min(),
    int most = std::numeric_limits<int>::max())
  {
    return Option(name, "a whole number" + Range(least, most), [&into, least, most](const std::string& v) {
      double d = 0;
      if (!ParseNumber(v, d) || d != std::floor(d) || d < least || d > most)
      {
        return false;
      }
      into = static_cast<int>(d);
      return true;
    });
  }
  // A number; with `positive`, one above 0.
  CommandLine& Real(const char* name, double& into, bool positive = false)
  {
    return Option(name, positive ? "a number above 0" : "a number", [&into, positive](const std::string& v) {
      double d = 0;
      if (!ParseNumber(v, d) || (positive && !(d > 0)))
      {
        return false;
      }
      into = d;
      return true;
    });
  }
  // A point count: "1000000" or "1e6".
  CommandLine& Count(const char* name, std::size_t& into)
  {
    return Option(name, "a count such as 1000000 or 1e6", [&into](const std::string& v) {
      return ParseCount(v, into);
    });
  }
  // A comma-separated list of point counts, each at least `least`.
  CommandLine& Counts(const char* name, std::vector<std::size_t>& into, std::size_t least = 0)
  {
    const std::string expects =
      "a list of counts such as 1e6,1e7" + (least ? ", each at least " + std::to_string(least) : std::string());
    return Option(name, expects, [&into, least](const std::string& v) {
      std::vector<std::size_t> counts;
      for (const std::string& item : SplitList(v))
      {
        std::size_t n = 0;
        if (!ParseCount(item, n) || n < least)
        {
          return false;
        }
        counts.push_back(n);
      }
      into = counts;
      return !counts.empty();
    });
  }
  // A picture size, "WxH", both above 0.
  CommandLine& Size(const char* name, int& width, int& height)
  {
    return Option(name, "a size WxH such as 1920x1080, at most 16384 a side", [&width, &height](const std::string& v) {
      return ParseSize(v, width, height);
    });
  }

  // Parses argv[first..argc); prints what is wrong, after the program's
  // name, and returns false at the first argument that does not parse.
  bool Parse(int argc, char** argv, int first = 1) const
  {
    const std::string error = Error(argc, argv, first);
    if (!error.empty())
    {
      std::fprintf(stderr, "%s: %s\n", ProgramName(argv[0]).c_str(), error.c_str());
    }
    return error.empty();
  }

  // Parses a program's whole command line, argv[1..argc): nothing where the
  // program goes on; else the exit status it stops with, 0 after `usage` on
  // stdout where --help or -h asks for it, 2 after the message for what is
  // wrong and `usage` on stderr.
  std::optional<int> ParseOrStop(int argc, char** argv, const char* usage) const
  {
    if (AsksForHelp(argc, argv))
    {
      return PrintUsage(stdout, usage);
    }
    if (!Parse(argc, argv))
    {
      return PrintUsage(stderr, usage);
    }
    return std::nullopt;
  }

  // What is wrong with argv[first..argc), or "" where every argument parses.
  std::string Error(int argc, char** argv, int first = 1) const
  {
    for (int a = first; a < argc; ++a)
    {
      const std::string name = argv[a];
      const auto option =
        std::find_if(Options.begin(), Options.end(), [&](const Entry& o) { return o.name == name; });
      if (option == Options.end())
      {
        return "unknown option '" + name + "'";
      }
      if (option->flag)
      {
        option->parse("");
        continue;
      }
      if (a + 1 >= argc)
      {
        return name + " expects " + option->expects + ", and no value follows it";
      }
      const std::string value = argv[++a];
      if (!option->parse(value))
      {
        return name + " expects " + option->expects + ", not '" + value + "'";
      }
    }
    return "";
  }

  // Whether argv[first..argc) asks for the usage: `--help` or `-h` anywhere.
  static bool AsksForHelp(int argc, char** argv, int first = 1)
  {
    return std::any_of(argv + std::min(first, argc), argv + argc, [](const char* a) {
      return std::string(a) == "--help" || std::string(a) == "-h";
    });
  }

  // Prints a program's usage on `to` and returns its exit status: 0 where
  // it was asked for (on stdout), 2 after a wrong command line (on stderr).
  static int PrintUsage(std::FILE* to, const char* usage)
  {
    std::fputs(usage, to);
    return to == stdout ? 0 : 2;
  }

  // A whole count, written as digits or in floating-point notation (1e6);
  // false for anything else.
  static bool ParseCount(const std::string& text, std::size_t& into)
  {
    double d = 0;
    if (!ParseNumber(text, d) || d < 0 || d != std::floor(d) || d > 9.0e15)
    {
      return false;
    }
    into = static_cast<std::size_t>(d);
    return true;
  }

  // A picture size "WxH", both above 0 and at most kMaxSide (as the Python
  // tool's, OpenGL's usual limit; 40000x40000 ended in a bare
  // std::bad_alloc), that is the whole of `text`.
  static constexpr int kMaxSide = 16384;
  static bool ParseSize(const std::string& text, int& width, int& height)
  {
    int w = 0, h = 0;
    char rest = 0;
    if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &rest) != 2 || w <= 0 || h <= 0 || w > kMaxSide ||
      h > kMaxSide)
    {
      return false;
    }
    width = w;
    height = h;
    return true;
  }

  // A finite number that is the whole of `text`.
  static bool ParseNumber(const std::string& text, double& into)
  {
    if (text.empty())
    {
      return false;
    }
    char* end = nullptr;
    errno = 0;
    const double d = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(d))
    {
      return false;
    }
    into = d;
    return true;
  }

private:
  struct Entry
  {
    std::string name;
    std::string expects;
    Parser parse;
    bool flag;
  };

  static std::string Range(int least, int most)
  {
    const bool low = least != std::numeric_limits<int>::min(), high = most != std::numeric_limits<int>::max();
    if (low && high)
    {
      return " from " + std::to_string(least) + " to " + std::to_string(most);
    }
    return low ? " of at least " + std::to_string(least) : high ? " of at most " + std::to_string(most) : "";
  }

  static std::string ProgramName(const char* path)
  {
    const std::string p = path ? path : "octoray";
    return p.substr(p.find_last_of('/') + 1);
  }

  std::vector<Entry> Options;
};
}
