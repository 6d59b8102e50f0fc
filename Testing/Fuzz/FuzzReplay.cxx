// main() for compilers without libFuzzer (the GCC build): runs every file
// named on the command line (or in a directory named there) through the
// target once, so the seed corpus and the regressions are tests everywhere.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int main(int argc, char* argv[])
{
  namespace fs = std::filesystem;
  int runs = 0;
  for (int a = 1; a < argc; ++a)
  {
    if (argv[a][0] == '-')
    {
      continue; // libFuzzer options
    }
    std::vector<fs::path> files;
    if (fs::is_directory(argv[a]))
    {
      for (const auto& e : fs::recursive_directory_iterator(argv[a]))
        if (e.is_regular_file())
          files.push_back(e.path());
    }
    else
    {
      files.emplace_back(argv[a]);
    }
    for (const auto& f : files)
    {
      std::ifstream in(f, std::ios::binary);
      std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
      ++runs;
    }
  }
  std::printf("replayed %d inputs\n", runs);
  return runs > 0 ? 0 : 1;
}
