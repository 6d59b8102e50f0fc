// What coding unit values into 16-bit codes costs a staging thread beside a
// plain copy of the floats: 40 MB of floats (the reflectivity of 10 M
// points) dealt in pieces to 1 and to 16 threads, each writing into a
// buffer of its own: memcpy of the floats in 4 MB pieces; the engine's
// EncodeUnitScalars (Scalar16.cpp) in pieces of 4 MB of floats and, as the
// staging cuts them (StagingPieces.h), of 2 MB of floats, whose codes are
// half as long. Medians of 7.
//
//   g++ -O3 -std=c++17 -pthread -I Rendering/Engine -o /tmp/uch scripts/gpu/unit-codes-host.cpp \
//     Rendering/Engine/octoray/Scalar16.cpp && /tmp/uch
#include <octoray/Scalar16.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

namespace
{
constexpr std::size_t kValues = 10000000, kPiece = 1 << 20; // values a piece: 4 MB of floats

template <typename Fill>
double Milliseconds(int threads, std::size_t piece, const std::vector<float>& values,
  std::vector<std::vector<char>>& buffers, Fill fill)
{
  std::vector<double> times;
  for (int round = 0; round < 7; ++round)
  {
    std::atomic<std::size_t> next{ 0 };
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::thread> team;
    for (int t = 0; t < threads; ++t)
      team.emplace_back([&, t] {
        for (std::size_t p = next++; p * piece < kValues; p = next++)
          fill(values.data() + p * piece, std::min(piece, kValues - p * piece), buffers[t].data());
      });
    for (auto& member : team)
      member.join();
    times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}
}

int main()
{
  std::vector<float> values(kValues);
  for (std::size_t i = 0; i < kValues; ++i)
    values[i] = i % 32 == 0 ? 0.5f : 0.0f;
  std::vector<std::vector<char>> buffers(16, std::vector<char>(kPiece * sizeof(float)));
  const auto copy = [](const float* v, std::size_t n, char* to) { std::memcpy(to, v, n * sizeof(float)); };
  const auto encode = [](const float* v, std::size_t n, char* to) {
    octoray::EncodeUnitScalars(v, n, reinterpret_cast<std::uint16_t*>(to));
  };
  for (int threads : { 1, 16 })
  {
    std::printf("%2d thread(s): memcpy %.3f ms, EncodeUnitScalars %.3f ms, in half pieces %.3f ms\n", threads,
      Milliseconds(threads, kPiece, values, buffers, copy), Milliseconds(threads, kPiece, values, buffers, encode),
      Milliseconds(threads, kPiece / 2, values, buffers, encode));
  }
}
