// Survives a memory-mapped file that is truncated while it is read. Private
// to the module; not wrapped.
//
// Pages of a mapping past the end of its file raise SIGBUS when touched: a
// particle file cut short by another process while vtkParticleTextReader
// parses it would otherwise kill the process. A MappedFileGuard registers a
// mapping; a process-wide SIGBUS handler (installed on first use, chaining
// to the handler it replaced) looks the faulting address up among the
// registered mappings and, when it is in one, maps zero-filled anonymous
// pages over the rest of that mapping (MAP_FIXED, one system call) and notes
// that; the faulting load then runs again and reads zeros. The parse goes
// on to its end over zeros on whatever thread it runs, no jump out of the
// middle of it, no state torn; the reader then sees Truncated() and reports
// the truncation instead of what it parsed. A fault outside every registered
// mapping goes to the previous handler (or the default action: the process
// stops, as it would without this). Up to MaximumMappings are guarded at a
// time; further ones are read unguarded.
#ifndef octorayMappedFileGuard_h
#define octorayMappedFileGuard_h

#include <cstddef>
#include <cstdint>

namespace octoray
{
class MappedFileGuard
{
public:
  static constexpr int MaximumMappings = 64;

  MappedFileGuard() = default;
  MappedFileGuard(const MappedFileGuard&) = delete;
  MappedFileGuard& operator=(const MappedFileGuard&) = delete;
  ~MappedFileGuard() { this->Release(); }

  // Guards [begin, begin + size), a private read-only mapping of a file.
  // False when every slot is taken (the mapping is then not guarded).
  bool Watch(const void* begin, size_t size);
  // Stops guarding; call before unmapping.
  void Release();
  // Whether a page of the mapping vanished (the file was truncated) while
  // it was guarded.
  bool Truncated() const;

private:
  int Slot = -1;
};
} // namespace octoray

#endif
