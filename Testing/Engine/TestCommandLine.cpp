// The command line of the octoray tool and the benchmarks (Tools/
// CommandLine.h): what each option takes, the message for each wrong
// argument, and the usage asked for.
#include "CommandLine.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace
{
using octoray::CommandLine;

// argv for the arguments after a program name.
struct Args
{
  explicit Args(std::vector<std::string> args)
    : Text(std::move(args))
  {
    Text.insert(Text.begin(), "octoray_bench");
    for (std::string& a : Text)
    {
      Pointers.push_back(&a[0]);
    }
  }
  int argc() const { return static_cast<int>(Pointers.size()); }
  char** argv() { return Pointers.data(); }

  std::vector<std::string> Text;
  std::vector<char*> Pointers;
};

struct Options
{
  std::size_t points = 0;
  int depth = 10;
  bool small = false;
  std::string backend = "cpu";
  int width = 0, height = 0;
  CommandLine line;

  Options()
  {
    line.Count("--points", points)
      .Integer("--depth", depth, 0, 21)
      .Flag("--small", small)
      .Choice("--backend", backend, { "cpu", "cuda" })
      .Size("--size", width, height);
  }
  std::string Error(std::vector<std::string> args)
  {
    Args a(std::move(args));
    return line.Error(a.argc(), a.argv());
  }
};

TEST(CommandLine, OptionsWriteTheirValues)
{
  Options o;
  EXPECT_EQ(o.Error({ "--points", "1e6", "--depth", "16", "--small", "--backend", "cuda", "--size", "640x360" }), "");
  EXPECT_EQ(o.points, 1000000u);
  EXPECT_EQ(o.depth, 16);
  EXPECT_TRUE(o.small);
  EXPECT_EQ(o.backend, "cuda");
  EXPECT_EQ(o.width, 640);
  EXPECT_EQ(o.height, 360);
}

TEST(CommandLine, EachWrongArgumentIsNamed)
{
  Options o;
  EXPECT_EQ(o.Error({ "--bogus" }), "unknown option '--bogus'");
  EXPECT_EQ(o.Error({ "--points" }), "--points expects a count such as 1000000 or 1e6, and no value follows it");
  EXPECT_EQ(o.Error({ "--points", "1e6x" }), "--points expects a count such as 1000000 or 1e6, not '1e6x'");
  EXPECT_EQ(o.Error({ "--depth", "22" }), "--depth expects a whole number from 0 to 21, not '22'");
  EXPECT_EQ(o.Error({ "--depth", "2.5" }), "--depth expects a whole number from 0 to 21, not '2.5'");
  EXPECT_EQ(o.Error({ "--backend", "gpu" }), "--backend expects one of cpu, cuda, not 'gpu'");
  EXPECT_EQ(o.Error({ "--size", "640x360x2" }),
    "--size expects a size WxH such as 1920x1080, at most 16384 a side, not '640x360x2'");
  EXPECT_EQ(o.depth, 10) << "a refused value leaves the option as it was";
  EXPECT_EQ(o.backend, "cpu");
}

TEST(CommandLine, HelpAnywhereGoesToStdoutWithStatusZero)
{
  Args asks({ "--points", "1e6", "-h" }), asksLong({ "--help" }), plain({ "--points", "1e6" });
  EXPECT_TRUE(CommandLine::AsksForHelp(asks.argc(), asks.argv()));
  EXPECT_TRUE(CommandLine::AsksForHelp(asksLong.argc(), asksLong.argv()));
  EXPECT_FALSE(CommandLine::AsksForHelp(plain.argc(), plain.argv()));
  EXPECT_FALSE(CommandLine::AsksForHelp(asks.argc(), asks.argv(), 4)) << "only from `first` on";
  testing::internal::CaptureStdout();
  EXPECT_EQ(CommandLine::PrintUsage(stdout, "usage: octoray_bench\n"), 0);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "usage: octoray_bench\n");
  testing::internal::CaptureStderr();
  EXPECT_EQ(CommandLine::PrintUsage(stderr, "usage: octoray_bench\n"), 2);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "usage: octoray_bench\n");
}

TEST(CommandLine, ParseOrStopGoesOnOrGivesTheExitStatus)
{
  Options o;
  Args good({ "--depth", "12" }), help({ "--depth", "12", "--help" }), wrong({ "--depth", "x" });
  EXPECT_FALSE(o.line.ParseOrStop(good.argc(), good.argv(), "usage\n").has_value());
  EXPECT_EQ(o.depth, 12);
  testing::internal::CaptureStdout();
  EXPECT_EQ(o.line.ParseOrStop(help.argc(), help.argv(), "usage\n"), 0);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "usage\n");
  testing::internal::CaptureStderr();
  EXPECT_EQ(o.line.ParseOrStop(wrong.argc(), wrong.argv(), "usage\n"), 2);
  EXPECT_EQ(testing::internal::GetCapturedStderr(),
    "octoray_bench: --depth expects a whole number from 0 to 21, not 'x'\nusage\n");
}
}
