// What every octoray benchmark shares: timing, point sets, and the JSON
// records of bench-results.json. Header-only and VTK-free, so the engine's
// benchmarks build on a GPU machine that has only CUDA, CMake and a compiler.
#pragma once

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace octoray
{
namespace bench
{
// ---------------------------------------------------------------- timing

struct Timing
{
  double median = 0.0;
  double min = 0.0;
  double max = 0.0;
  int repeats = 0;
};

// Median, min and max of measured times (seconds); zeros when there are none.
inline Timing Summarise(std::vector<double> seconds)
{
  Timing t;
  const std::size_t m = seconds.size();
  if (m == 0)
  {
    return t;
  }
  std::sort(seconds.begin(), seconds.end());
  t.median = m % 2 ? seconds[m / 2] : 0.5 * (seconds[m / 2 - 1] + seconds[m / 2]);
  t.min = seconds.front();
  t.max = seconds.back();
  t.repeats = static_cast<int>(m);
  return t;
}

// Runs fn `warmups` times untimed (first-touch page faults, lazily grown
// buffers and cold caches belong to no steady state), then `repeats` times
// timed. The median is what gets reported: on a shared 2-core machine a
// single slow run from a neighbour's burst must not move the figure.
// `after`, when given, runs untimed after every call (e.g. freeing a tree of
// millions of nodes, which is not the build's cost).
inline Timing Measure(const std::function<void()>& fn, int warmups, int repeats,
  const std::function<void()>& after = nullptr)
{
  for (int w = 0; w < warmups; ++w)
  {
    fn();
    if (after)
    {
      after();
    }
  }
  std::vector<double> seconds;
  for (int r = 0; r < std::max(1, repeats); ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    fn();
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (after)
    {
      after();
    }
  }
  return Summarise(std::move(seconds));
}

// ---------------------------------------------------------------- point sets

// SplitMix64: a few lines, fast, and the same sequence on every platform and
// standard library (std::normal_distribution is not), so a point set is
// reproducible from its seed wherever a benchmark runs.
class Random
{
public:
  explicit Random(std::uint64_t seed)
    : State(seed)
  {
  }
  std::uint64_t Next()
  {
    std::uint64_t z = (State += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1), 53 bits.
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1p-53; }
  // Standard normal (Box-Muller; the second value is dropped for simplicity).
  double Normal()
  {
    const double u = 1.0 - Uniform(); // (0, 1]: log stays finite
    const double v = Uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(6.283185307179586 * v);
  }

private:
  std::uint64_t State;
};

constexpr std::uint64_t kDefaultSeed = 20150101; // fixed: every run sees the same points

// n points uniform in the unit cube, xyz interleaved.
inline std::vector<float> UniformCube(std::size_t n, std::uint64_t seed = kDefaultSeed)
{
  Random random(seed);
  std::vector<float> xyz(3 * n);
  for (float& c : xyz)
  {
    c = static_cast<float>(random.Uniform());
  }
  return xyz;
}

// n points in `clusters` Gaussian blobs with centres uniform in the unit
// cube and standard deviation `sigma`: dense cores and empty space, the
// shape of particle and scan data, where an octree is deep and sparse.
inline std::vector<float> GaussianClusters(
  std::size_t n, int clusters = 32, double sigma = 0.02, std::uint64_t seed = kDefaultSeed)
{
  Random random(seed);
  std::vector<double> centre(3 * clusters);
  for (double& c : centre)
  {
    c = random.Uniform();
  }
  std::vector<float> xyz(3 * n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::size_t k = random.Next() % static_cast<std::uint64_t>(clusters);
    for (int a = 0; a < 3; ++a)
    {
      xyz[3 * i + a] = static_cast<float>(centre[3 * k + a] + sigma * random.Normal());
    }
  }
  return xyz;
}

// Bytes of the thesis's dense octree of depth L: a pointer for every
// possible node, (8^(L+1) - 1) / 7 of them. In double: past depth 20 the
// count no longer fits in 64 bits, which is the point of the comparison.
inline double DenseSkeletonBytes(int depth, double bytesPerPointer = 8.0)
{
  return bytesPerPointer * (std::pow(8.0, depth + 1) - 1.0) / 7.0;
}

// "1.5 GB", "12.3 MB": sizes in the tables.
inline std::string HumanBytes(double bytes)
{
  const char* units[] = { "B", "KB", "MB", "GB", "TB", "PB", "EB", "ZB" };
  int u = 0;
  while (bytes >= 1000.0 && u < 7)
  {
    bytes /= 1000.0;
    ++u;
  }
  char text[32];
  std::snprintf(text, sizeof text, bytes < 10.0 && u ? "%.2f %s" : "%.1f %s", bytes, units[u]);
  return text;
}

// ---------------------------------------------------------------- JSON records

// One line of bench-results.json. `peer` is empty (written as null) when a
// record compares with nothing.
struct Record
{
  std::string name;
  std::string backend;
  std::size_t n = 0;
  int depth = 0;
  double seconds = 0.0;
  std::string peer;
  double peerSeconds = 0.0;
  // Further figures of the same measurement (node counts, bytes, phases,
  // rays), written as extra members so the report needs no second file.
  std::vector<std::pair<std::string, double>> extra;

  Record& With(const std::string& key, double value)
  {
    extra.emplace_back(key, value);
    return *this;
  }
};

namespace detail
{
inline std::string Quote(const std::string& s)
{
  std::string out = "\"";
  for (const char c : s)
  {
    switch (c)
    {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20)
        {
          char esc[8];
          std::snprintf(esc, sizeof esc, "\\u%04x", c);
          out += esc;
        }
        else
        {
          out += c;
        }
    }
  }
  return out + "\"";
}

inline std::string Number(double v)
{
  if (!std::isfinite(v))
  {
    return "null"; // JSON has no inf or nan
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

inline std::string ToJson(const Record& r)
{
  std::ostringstream o;
  o << "{\"name\": " << Quote(r.name) << ", \"backend\": " << Quote(r.backend) << ", \"n\": " << r.n
    << ", \"depth\": " << r.depth << ", \"seconds\": " << Number(r.seconds)
    << ", \"peer\": " << (r.peer.empty() ? "null" : Quote(r.peer))
    << ", \"peer_seconds\": " << (r.peer.empty() ? "null" : Number(r.peerSeconds));
  for (const auto& e : r.extra)
  {
    o << ", " << Quote(e.first) << ": " << Number(e.second);
  }
  o << "}";
  return o.str();
}

// A minimal reader for what other benchmarks may have written: a JSON array
// of objects. Objects are kept as their original text (whatever fields and
// nesting they have); only the four identifying fields are looked at.
class Scanner
{
public:
  Scanner(const std::string& text, const std::string& path)
    : Text(text)
    , Path(path)
  {
  }

  void Space()
  {
    while (Pos < Text.size() && std::isspace(static_cast<unsigned char>(Text[Pos])))
    {
      ++Pos;
    }
  }
  bool AtEnd()
  {
    Space();
    return Pos >= Text.size();
  }
  char Peek()
  {
    Space();
    return Pos < Text.size() ? Text[Pos] : '\0';
  }
  void Expect(char c)
  {
    if (Peek() != c)
    {
      Fail(std::string("expected '") + c + "'");
    }
    ++Pos;
  }
  std::string String()
  {
    Expect('"');
    std::string s;
    while (Pos < Text.size() && Text[Pos] != '"')
    {
      if (Text[Pos] == '\\' && Pos + 1 < Text.size())
      {
        ++Pos; // escapes are kept as the escaped character; good enough for keys
      }
      s += Text[Pos++];
    }
    Expect('"');
    return s;
  }
  // Skips one value of any kind and returns its text.
  std::string Value()
  {
    Space();
    const std::size_t begin = Pos;
    const char c = Peek();
    if (c == '"')
    {
      String();
    }
    else if (c == '{' || c == '[')
    {
      const char close = c == '{' ? '}' : ']';
      ++Pos;
      if (Peek() == close)
      {
        ++Pos;
      }
      else
      {
        for (;;)
        {
          if (c == '{')
          {
            String();
            Expect(':');
          }
          Value();
          if (Peek() == ',')
          {
            ++Pos;
            continue;
          }
          Expect(close);
          break;
        }
      }
    }
    else
    {
      while (Pos < Text.size() && !std::strchr(",]} \t\r\n", Text[Pos]))
      {
        ++Pos;
      }
      if (Pos == begin)
      {
        Fail("expected a value");
      }
    }
    return Text.substr(begin, Pos - begin);
  }
  [[noreturn]] void Fail(const std::string& what) const
  {
    throw std::runtime_error(Path + ": not a JSON array of records (" + what + " at byte " + std::to_string(Pos) +
      "); left unchanged");
  }

  const std::string& Text;
  const std::string& Path;
  std::size_t Pos = 0;
};

struct StoredRecord
{
  std::string text;
  std::string key; // name, backend, n, depth as they appear
};

inline std::string KeyOf(const std::string& name, const std::string& backend, const std::string& n,
  const std::string& depth)
{
  return name + '\x1f' + backend + '\x1f' + n + '\x1f' + depth;
}

inline std::vector<StoredRecord> ReadRecords(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    return {}; // no file yet
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  Scanner s(text, path);
  std::vector<StoredRecord> records;
  if (s.AtEnd())
  {
    return records; // empty file
  }
  s.Expect('[');
  if (s.Peek() == ']')
  {
    return records;
  }
  for (;;)
  {
    if (s.Peek() != '{')
    {
      s.Fail("expected an object");
    }
    const std::size_t begin = s.Pos;
    // Walk the object's members to pick out the identifying ones.
    std::string fields[4];
    const char* names[4] = { "name", "backend", "n", "depth" };
    ++s.Pos;
    if (s.Peek() != '}')
    {
      for (;;)
      {
        const std::string member = s.String();
        s.Expect(':');
        std::string value = s.Value();
        if (value.size() >= 2 && value.front() == '"')
        {
          value = value.substr(1, value.size() - 2);
        }
        for (int f = 0; f < 4; ++f)
        {
          if (member == names[f])
          {
            fields[f] = value;
          }
        }
        if (s.Peek() == ',')
        {
          ++s.Pos;
          continue;
        }
        break;
      }
    }
    s.Expect('}');
    records.push_back(
      StoredRecord{ text.substr(begin, s.Pos - begin), KeyOf(fields[0], fields[1], fields[2], fields[3]) });
    if (s.Peek() == ',')
    {
      ++s.Pos;
      continue;
    }
    s.Expect(']');
    break;
  }
  if (!s.AtEnd())
  {
    s.Fail("text after the array");
  }
  return records;
}
}

// Merges `records` into the JSON array at `path`: a stored record with the
// same name, backend, n and depth is replaced in place, every other stored
// record (other benchmarks' included) is kept as it was, new ones are
// appended. Written to a temporary file and renamed, so an interrupted run
// never leaves a truncated file. Throws if the file exists but is not an
// array of objects, rather than overwrite what it cannot read.
inline void MergeRecords(const std::string& path, const std::vector<Record>& records)
{
  std::vector<detail::StoredRecord> stored = detail::ReadRecords(path);
  for (const Record& r : records)
  {
    const std::string key = detail::KeyOf(r.name, r.backend, std::to_string(r.n), std::to_string(r.depth));
    detail::StoredRecord fresh{ detail::ToJson(r), key };
    auto same = std::find_if(
      stored.begin(), stored.end(), [&](const detail::StoredRecord& s) { return s.key == key; });
    if (same != stored.end())
    {
      *same = fresh;
    }
    else
    {
      stored.push_back(fresh);
    }
  }
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << "[\n";
    for (std::size_t i = 0; i < stored.size(); ++i)
    {
      out << "  " << stored[i].text << (i + 1 < stored.size() ? ",\n" : "\n");
    }
    out << "]\n";
    if (!out)
    {
      throw std::runtime_error(temporary + ": could not be written");
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0)
  {
    throw std::runtime_error(path + ": could not be replaced by " + temporary);
  }
}
// Merges `records` into the JSON file `path` (nothing when it is empty) and
// says so.
inline void SaveRecords(const std::string& path, const std::vector<Record>& records)
{
  if (!path.empty())
  {
    MergeRecords(path, records);
    std::printf("\n%zu records merged into %s\n", records.size(), path.c_str());
  }
}
}
}
