// A per-process scratch file for fuzz targets whose readers take file names.
#ifndef octorayFuzzTempFile_h
#define octorayFuzzTempFile_h

#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

inline std::string FuzzWriteTemp(const char* ext, const void* data, size_t size)
{
  const char* dir = std::getenv("TMPDIR");
  const std::string path = std::string(dir && *dir ? dir : "/tmp") + "/octoray-fuzz-" +
    std::to_string(::getpid()) + ext;
  if (FILE* f = std::fopen(path.c_str(), "wb"))
  {
    if (size)
    {
      std::fwrite(data, 1, size, f);
    }
    std::fclose(f);
  }
  return path;
}
#endif
