// The bytes of a text file: memory-mapped when plain, inflated into memory
// when gzip-compressed (recognised by its magic bytes, not its name).
// Private to the module; not wrapped.
//
// Memory-mapped rather than read(): the parse makes two passes over the
// bytes and a 10 GB file need not fit in memory. The mapping is guarded
// (octorayMappedFileGuard.h): if another process truncates the file while
// it is read, the vanished pages read as zeros instead of raising SIGBUS,
// and Truncated() tells the reader to report it.
#ifndef octorayTextSource_h
#define octorayTextSource_h

#include "octorayMappedFileGuard.h"
#include "octorayTextScan.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "vtk_zlib.h" // VTK's zlib: the module needs no third-party library of its own

namespace octoray
{
// "device:inode:size:mtime" of a file, empty when it cannot be stat'ed: the
// readers' GetMTime() compare it with the last one seen, so that Update()
// reads a file again once it changed on disk.
inline std::string FileSignature(const char* name)
{
  struct stat st;
  if (!name || ::stat(name, &st) != 0)
  {
    return std::string();
  }
  return std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino) + ":" +
    std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) + "." +
    std::to_string(st.st_mtim.tv_nsec);
}

class TextSource
{
public:
  TextSource() = default;
  TextSource(const TextSource&) = delete;
  TextSource& operator=(const TextSource&) = delete;
  ~TextSource() { this->Close(); }

  const char* Data() const { return this->Inflated.empty() ? this->Map : this->Inflated.data(); }
  size_t Size() const { return this->Inflated.empty() ? this->MapSize : this->Inflated.size(); }
  bool IsCompressed() const { return this->Compressed; }

  bool Open(const std::string& name, std::string& error)
  {
    this->Close();
    int fd = ::open(name.c_str(), O_RDONLY);
    if (fd < 0)
    {
      error = name + ": cannot open the file: " + std::strerror(errno);
      return false;
    }
    struct stat st;
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    {
      error = name + (S_ISDIR(st.st_mode) ? ": is a directory, not a file"
                                          : ": not a regular file");
      ::close(fd);
      return false;
    }
    this->MapSize = static_cast<size_t>(st.st_size);
    if (this->MapSize > 0)
    {
      void* m = ::mmap(nullptr, this->MapSize, PROT_READ, MAP_PRIVATE, fd, 0);
      if (m == MAP_FAILED)
      {
        error = name + ": cannot map the file: " + std::strerror(errno);
        ::close(fd);
        this->MapSize = 0;
        return false;
      }
      this->Map = static_cast<const char*>(m);
      // The parse reads front to back; tell the kernel so it reads ahead.
      ::madvise(m, this->MapSize, MADV_SEQUENTIAL);
      this->Guard.Watch(m, this->MapSize);
    }
    this->Fd = fd;
    this->Opened = st;
    if (StartsGzip(this->Map, this->MapSize))
    {
      this->Compressed = true;
      bool ok = this->Inflate(name, error);
      if (this->Guard.Truncated())
      {
        error = this->TruncationMessage(name);
        this->Inflated.clear();
        ok = false;
      }
      this->Guard.Release();
      ::munmap(const_cast<char*>(this->Map), this->MapSize);
      this->Map = nullptr;
      this->MapSize = 0;
      if (ok && this->Inflated.empty())
      {
        // An empty member: report the text as empty (Data() must not be null).
        this->Inflated.clear();
      }
      return ok;
    }
    return true;
  }

  // True when the mapped file lost pages while it was read: some of what
  // was parsed is zeros, not the file.
  bool Truncated() const { return this->Guard.Truncated(); }

  // "<name>: the file was truncated while it was being read ..."
  std::string TruncationMessage(const std::string& name) const
  {
    struct stat now;
    std::string size;
    if (this->Fd >= 0 && ::fstat(this->Fd, &now) == 0)
    {
      // Truncated and written again (a shell's `>`) by the time it is seen.
      size = now.st_size < this->Opened.st_size
        ? " to " + std::to_string(now.st_size) + " bytes"
        : " (and written again, now " + std::to_string(now.st_size) + " bytes)";
    }
    return name + ": the file was truncated" + size + " while it was being read (it had " +
      std::to_string(this->Opened.st_size) + " bytes); nothing was read (read it again)";
  }

  // True when the open file's size or modification time differ from what
  // they were when it was opened: it was written to while being read.
  bool ChangedSinceOpen() const
  {
    struct stat now;
    if (this->Fd < 0 || ::fstat(this->Fd, &now) != 0)
    {
      return false;
    }
    return now.st_size != this->Opened.st_size ||
      now.st_mtim.tv_sec != this->Opened.st_mtim.tv_sec ||
      now.st_mtim.tv_nsec != this->Opened.st_mtim.tv_nsec;
  }

  void Close()
  {
    if (this->Fd >= 0)
    {
      ::close(this->Fd);
    }
    this->Fd = -1;
    this->Guard.Release();
    if (this->Map)
    {
      ::munmap(const_cast<char*>(this->Map), this->MapSize);
    }
    this->Map = nullptr;
    this->MapSize = 0;
    this->Inflated.clear();
    this->Inflated.shrink_to_fit();
    this->Compressed = false;
  }

private:
  // Inflates every gzip member; a stream that ends before its end marker is
  // reported as truncated rather than read as a shorter file.
  bool Inflate(const std::string& name, std::string& error)
  {
    z_stream zs;
    std::memset(&zs, 0, sizeof(zs));
    if (inflateInit2(&zs, 15 + 16) != Z_OK)
    {
      error = name + ": cannot initialise zlib";
      return false;
    }
    const unsigned char* in = reinterpret_cast<const unsigned char*>(this->Map);
    size_t inLeft = this->MapSize;
    this->Inflated.reserve(this->MapSize * 4);
    const size_t block = 1 << 20;
    int ret = Z_OK;
    while (true)
    {
      const uInt feed = static_cast<uInt>(std::min<size_t>(inLeft, 1u << 30));
      zs.next_in = const_cast<unsigned char*>(in);
      zs.avail_in = feed;
      size_t before = this->Inflated.size();
      this->Inflated.resize(before + block);
      zs.next_out = reinterpret_cast<unsigned char*>(this->Inflated.data() + before);
      zs.avail_out = static_cast<uInt>(block);
      ret = inflate(&zs, Z_NO_FLUSH);
      this->Inflated.resize(before + (block - zs.avail_out));
      const size_t used = feed - zs.avail_in;
      in += used;
      inLeft -= used;
      if (ret == Z_STREAM_END)
      {
        // Concatenated members (gzip -c a b > c) form one text.
        if (StartsGzip(in, inLeft))
        {
          inflateReset(&zs);
          continue;
        }
        break;
      }
      if (ret == Z_NEED_DICT || ret == Z_DATA_ERROR || ret == Z_MEM_ERROR)
      {
        error = name + ": corrupt gzip data at compressed byte " +
          std::to_string(this->MapSize - inLeft) + ": " + (zs.msg ? zs.msg : "inflate failed");
        inflateEnd(&zs);
        this->Inflated.clear();
        return false;
      }
      if (inLeft == 0 && zs.avail_out != 0)
      {
        error = name + ": truncated gzip data: the compressed stream ends at byte " +
          std::to_string(this->MapSize) + " before its end marker (" +
          std::to_string(this->Inflated.size()) + " bytes of text were recovered)";
        inflateEnd(&zs);
        this->Inflated.clear();
        return false;
      }
    }
    inflateEnd(&zs);
    return true;
  }

  const char* Map = nullptr;
  size_t MapSize = 0;
  std::vector<char> Inflated;
  bool Compressed = false;
  int Fd = -1;
  struct stat Opened = {};
  MappedFileGuard Guard;
};
} // namespace octoray

#endif
