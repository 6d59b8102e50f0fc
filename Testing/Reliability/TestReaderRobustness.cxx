// Input that must never crash the readers (issue 8): random bytes, a 10 GB
// sparse file (progress, abort through AbortExecute), a file that changes
// while it is read, a directory where a file was expected, permission
// denied, a slice stack with one corrupt image; each a clear error naming
// what failed, and the previous output intact after a failed re-read. Also:
// a reader re-executes when its file changes on disk, and the picture the
// engine makes of the same file is the same each time.
//   TestReaderRobustness <scratch folder> <Data folder> <seed PNG>
#include "EnginePicture.h"
#include "octorayTestCheck.h"

#include "vtkCallbackCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkParticleTextReader.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSliceStackReader.h"

#include <octoray/Engine.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace
{
std::string Dir;

std::string Write(const std::string& name, const std::string& bytes)
{
  const std::string path = Dir + "/" + name;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  return path;
}

// Replaces a file by a new one (a new inode, as editors and exporters do).
void Replace(const std::string& path, const std::string& bytes)
{
  const std::string tmp = path + ".new";
  std::ofstream(tmp, std::ios::binary | std::ios::trunc) << bytes;
  fs::rename(tmp, path);
}

std::string ReadAll(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void Quiet(vtkObject* o)
{
  vtkNew<vtkCallbackCommand> cb;
  cb->SetCallback([](vtkObject*, unsigned long, void*, void*) {});
  o->AddObserver(vtkCommand::ErrorEvent, cb);
  o->AddObserver(vtkCommand::WarningEvent, cb);
}

struct Progress
{
  std::vector<double> Values;
  double AbortAt = 2; // abort at the first progress above this
  std::string AppendTo; // append a line to this file during the read
  std::string Truncate; // truncate this file to TruncateTo bytes at the
  off_t TruncateTo = 0; // first progress above TruncateAbove
  double TruncateAbove = 2;
};

void Observe(vtkAlgorithm* a, Progress& p)
{
  vtkNew<vtkCallbackCommand> cb;
  cb->SetClientData(&p);
  cb->SetCallback([](vtkObject* o, unsigned long, void* client, void* call) {
    auto* pr = static_cast<Progress*>(client);
    const double v = *static_cast<double*>(call);
    pr->Values.push_back(v);
    if (v > pr->AbortAt)
    {
      static_cast<vtkAlgorithm*>(o)->SetAbortExecute(1);
    }
    if (!pr->AppendTo.empty() && v > 0) // after the file was opened
    {
      std::ofstream(pr->AppendTo, std::ios::app) << "7 8 9\n";
      pr->AppendTo.clear();
    }
    if (!pr->Truncate.empty() && v > pr->TruncateAbove)
    {
      if (::truncate(pr->Truncate.c_str(), pr->TruncateTo) != 0)
      {
        std::perror("truncate");
      }
      pr->Truncate.clear();
    }
  });
  a->AddObserver(vtkCommand::ProgressEvent, cb);
}

// The Data folder, a PNG slice (the seed corpus's), and a good particle
// file, which the checks below share.
std::string DataDir, Png, Good;

// Random bytes: never a crash; an empty result names the file.
void RandomBytesNeverCrash()
{
  std::mt19937 rng(8);
  for (int i = 0; i < 40; ++i)
  {
    std::string bytes(1 + rng() % 20000, '\0');
    for (char& c : bytes)
      c = static_cast<char>(i % 2 ? rng() : " 0123456789.-e\n,#"[rng() % 17]);
    const std::string path = Write("random" + std::to_string(i) + ".txt", bytes);
    vtkNew<vtkParticleTextReader> r;
    Quiet(r);
    r->SetFileName(path.c_str());
    r->SetLenient(i % 4 == 1);
    r->Update();
    if (r->GetOutput()->GetNumberOfPoints() == 0)
    {
      CHECK_CONTAINS(r->GetErrorMessage(), path);
    }
    const std::string img = Write("random" + std::to_string(i) + (i % 3 ? ".png" : ".dcm"), bytes);
    vtkNew<vtkSliceStackReader> s;
    Quiet(s);
    s->AddFileName(img.c_str());
    s->Update();
    CHECK(s->GetOutput()->GetNumberOfPoints() == 0);
    CHECK_CONTAINS(s->GetErrorMessage(), img);
  }
  // A binary file: the error says so, with a bounded message.
  vtkNew<vtkParticleTextReader> r;
  Quiet(r);
  const std::string bin = Write("binary.txt", std::string("\x7f" "ELF\0\0\0\1\2\3", 10));
  r->SetFileName(bin.c_str());
  r->Update();
  CHECK_CONTAINS(r->GetErrorMessage(), bin + ":1:5: a NUL byte");
}

// A 10 GB sparse file: progress is reported, an observer aborts, and the
// previous output stays. Only the first bytes are real; the reader is
// stopped long before it has touched much of the rest.
void SparseFileReportsProgressAndAborts()
{
  vtkNew<vtkParticleTextReader> r;
  Quiet(r);
  r->SetFileName(Good.c_str());
  r->Update();
  CHECK(r->GetOutput()->GetNumberOfPoints() == 3);
  const std::string huge = Write("huge.txt", "1 2 3\n4 5 6\n");
  std::error_code ec;
  fs::resize_file(huge, 10ull << 30, ec);
  struct stat st;
  if (ec || ::stat(huge.c_str(), &st) != 0 || st.st_blocks * 512ull > (100ull << 20))
  {
    std::cout << "SKIPPED the 10 GB sparse file: this file system does not make sparse files ("
              << ec.message() << ")" << std::endl;
  }
  else
  {
    Progress p;
    p.AbortAt = 0.0;
    Observe(r, p);
    r->SetFileName(huge.c_str());
    const auto t0 = std::chrono::steady_clock::now();
    r->Update();
    const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    CHECK(!p.Values.empty());
    CHECK_CONTAINS(r->GetErrorMessage(), huge + ": reading was aborted");
    CHECK(r->GetOutput()->GetNumberOfPoints() == 3); // the previous output
    CHECK(seconds < 30);
    std::cout << "10 GB sparse file: aborted after " << seconds << " s, " << p.Values.size()
              << " progress events" << std::endl;
  }
  fs::remove(huge);
}

// Long lines before any particle: a clear error, not a walk through
// the file.
void LongLinesBeforeAnyParticle()
{
  vtkNew<vtkParticleTextReader> r;
  Quiet(r);
  const std::string longLine = Write("long.txt", std::string(3 << 20, 'x') + "\n1 2 3\n");
  r->SetFileName(longLine.c_str());
  r->Update();
  CHECK_CONTAINS(r->GetErrorMessage(), longLine + ":1:1: line 1 is longer than");
}

// A file that changes while it is read: an error, the previous output
// kept; the next Update() re-reads the changed file by itself.
void FileChangingWhileRead()
{
  const std::string path = Write("changing.txt", "1 2 3\n4 5 6\n");
  vtkNew<vtkParticleTextReader> r;
  Quiet(r);
  r->SetFileName(Good.c_str());
  r->Update();
  Progress p;
  p.AppendTo = path;
  Observe(r, p);
  r->SetFileName(path.c_str());
  r->Update();
  CHECK_CONTAINS(r->GetErrorMessage(), path + ": the file changed while it was being read");
  CHECK(r->GetOutput()->GetNumberOfPoints() == 3);
  r->Update(); // the file's time changed: read again, now settled
  CHECK(std::string(r->GetErrorMessage()).empty());
  CHECK(r->GetOutput()->GetNumberOfPoints() == 3);
  double pt[3];
  r->GetOutput()->GetPoint(2, pt);
  CHECK(pt[0] == 7 && pt[1] == 8 && pt[2] == 9);
}

// A file truncated by another writer while it is memory-mapped and
// parsed: its pages past the new end vanish (a bare mmap would raise
// SIGBUS); a clear error, the previous output kept. The truncation is
// done by a progress observer, so it falls at a known point: with one
// thread in the middle of the parse (some chunks done, the next one
// gone), with two threads before the worker threads have started (they
// are the ones that meet the vanished pages).
void FileTruncatedWhileMapped()
{
  // 12 MiB of 16-byte lines: 8 chunks of 1.5 MiB with one thread.
  std::string text;
  for (int i = 0; text.size() < (12u << 20); ++i)
  {
    char line[32];
    std::snprintf(line, sizeof(line), "%05d 1.50 2.50\n", i % 100000);
    text += line;
  }
  const std::string path = Dir + "/truncated.txt";
  for (int threads : { 1, 2 })
  {
    Write("truncated.txt", text);
    vtkNew<vtkParticleTextReader> r;
    Quiet(r);
    r->SetFileName(Good.c_str());
    r->Update();
    Progress p;
    p.Truncate = path;
    p.TruncateTo = 4096; // 256 whole lines
    p.TruncateAbove = threads == 1 ? 0.3 : 0.0;
    Observe(r, p);
    r->SetNumberOfThreads(threads);
    r->SetFileName(path.c_str());
    r->Update();
    CHECK(p.Truncate.empty()); // the observer did truncate
    CHECK(std::string(r->GetErrorMessage()) ==
      path + ": the file was truncated to 4096 bytes while it was being read (it had " +
        std::to_string(text.size()) + " bytes); nothing was read (read it again)");
    CHECK(r->GetOutput()->GetNumberOfPoints() == 3); // the previous output
    double pt[3];
    r->GetOutput()->GetPoint(2, pt);
    CHECK(pt[0] == 7 && pt[1] == 8 && pt[2] == 10);
    r->Update(); // the file changed: read again, what is left of it
    CHECK(std::string(r->GetErrorMessage()).empty());
    CHECK(r->GetOutput()->GetNumberOfPoints() == 256);
  }
}

// A directory where a file was expected.
void DirectoryWhereAFileWasExpected()
{
  const std::string folder = Dir + "/a_folder.txt";
  fs::create_directories(folder);
  vtkNew<vtkParticleTextReader> r;
  Quiet(r);
  r->SetFileName(folder.c_str());
  r->Update();
  CHECK(std::string(r->GetErrorMessage()) == folder + ": is a directory, not a file");
  vtkNew<vtkSliceStackReader> s;
  Quiet(s);
  s->AddFileName(folder.c_str());
  s->Update();
  CHECK(std::string(s->GetErrorMessage()) ==
    "slice '" + folder + "' is a directory, not an image file");
  vtkNew<vtkSliceStackReader> d;
  Quiet(d);
  d->SetDirectoryName(Good.c_str());
  d->Update();
  CHECK_CONTAINS(d->GetErrorMessage(), "'" + Good + "' is not a directory");
}

// Permission denied. root reads files whatever their mode, so there the
// case cannot be made and is skipped, saying so.
void PermissionDenied()
{
  const std::string path = Write("locked.txt", "1 2 3\n");
  const std::string img = Write("locked.png", Png);
  ::chmod(path.c_str(), 0);
  ::chmod(img.c_str(), 0);
  if (::access(path.c_str(), R_OK) == 0)
  {
    std::cout << "SKIPPED permission denied: running as root (uid " << ::geteuid()
              << "), where mode 000 does not stop reading" << std::endl;
  }
  else
  {
    vtkNew<vtkParticleTextReader> r;
    Quiet(r);
    r->SetFileName(path.c_str());
    r->Update();
    CHECK(std::string(r->GetErrorMessage()) ==
      path + ": cannot open the file: Permission denied");
    vtkNew<vtkSliceStackReader> s;
    Quiet(s);
    s->AddFileName(img.c_str());
    s->Update();
    CHECK_CONTAINS(s->GetErrorMessage(), img);
  }
  ::chmod(path.c_str(), 0644);
  ::chmod(img.c_str(), 0644);
}

// A slice stack with one corrupt image: the error names that slice and the
// previous stack stays whole.
void SliceStackWithOneCorruptImage()
{
  const std::string stack = Dir + "/stack";
  fs::create_directories(stack);
  std::vector<std::string> names;
  for (int k = 0; k < 3; ++k)
    names.push_back(stack + "/s" + std::to_string(k) + ".png");
  for (const auto& n : names)
    Replace(n, Png);
  vtkNew<vtkSliceStackReader> s;
  Quiet(s);
  s->SetDirectoryName(stack.c_str());
  s->Update();
  const vtkIdType points = s->GetOutput()->GetNumberOfPoints();
  int dims[3];
  s->GetImageOutput()->GetDimensions(dims);
  CHECK(points > 0);
  CHECK(dims[2] == 3);
  // Keep the PNG header (size, type) but cut the pixel data short: the
  // header pass passes, the pixel pass fails.
  Replace(names[1], Png.substr(0, Png.size() - 30));
  s->Update(); // the file changed on disk: read again without Modified()
  CHECK_CONTAINS(s->GetErrorMessage(), names[1]);
  CHECK(s->GetOutput()->GetNumberOfPoints() == points);
  int after[3];
  s->GetImageOutput()->GetDimensions(after);
  CHECK(after[0] == dims[0] && after[1] == dims[1] && after[2] == 3);
  CHECK(s->GetNumberOfSlices() == 3);
  // Header garbage in one slice.
  Replace(names[2], "\x89PNG\r\n\x1a\n garbage");
  s->Update();
  CHECK_CONTAINS(s->GetErrorMessage(), "cannot read slice '" + names[2] + "'");
  CHECK(s->GetOutput()->GetNumberOfPoints() == points);
  // Mended: read again.
  Replace(names[1], Png);
  Replace(names[2], Png);
  s->Update();
  CHECK(std::string(s->GetErrorMessage()).empty());
  CHECK(s->GetOutput()->GetNumberOfPoints() == points);
}

// A reader re-executed when its file changes on disk; the same picture
// each time the same content is read.
void ReExecutesWhenTheFileChanges()
{
  const std::string bundled = DataDir + "/Particles/lidar_simple.particles";
  const std::string original = ReadAll(bundled);
  const std::string path = Write("scene.particles", original);
  vtkNew<vtkParticleTextReader> r;
  r->SetFileName(path.c_str());
  r->Update();
  const vtkIdType n = r->GetOutput()->GetNumberOfPoints();
  CHECK(n > 100);
  const auto first = EnginePicture(r->GetOutput(), 64, 48);
  const vtkMTimeType t = r->GetOutput()->GetMTime();
  r->Update(); // nothing changed: no new execution
  CHECK(r->GetOutput()->GetMTime() == t);
  // Another content (the first 10 particles) replaces the file.
  std::string head;
  size_t at = 0;
  for (int l = 0; l < 11; ++l)
    at = original.find('\n', at) + 1;
  Replace(path, original.substr(0, at));
  r->Update();
  CHECK(r->GetOutput()->GetNumberOfPoints() == 10);
  // The same bytes again, written in place: the same picture.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::ofstream(path, std::ios::binary | std::ios::trunc) << original;
  r->Update();
  CHECK(r->GetOutput()->GetNumberOfPoints() == n);
  CHECK(EnginePicture(r->GetOutput(), 64, 48) == first);
  bool lit = false;
  for (float v : first)
    lit = lit || v > 0;
  CHECK(lit);
}

} // namespace

int main(int argc, char* argv[])
{
  if (argc < 4)
  {
    std::cerr << "usage: TestReaderRobustness scratch-folder Data-folder seed.png\n";
    return 2;
  }
  Dir = argv[1];
  fs::create_directories(Dir);
  DataDir = argv[2];
  Png = ReadAll(argv[3]).substr(1); // corpus seeds carry a leading byte
  Good = Write("good.txt", "1 2 3\n4 5 6\n7 8 10\n");
  RandomBytesNeverCrash();
  SparseFileReportsProgressAndAborts();
  LongLinesBeforeAnyParticle();
  FileChangingWhileRead();
  FileTruncatedWhileMapped();
  DirectoryWhereAFileWasExpected();
  PermissionDenied();
  SliceStackWithOneCorruptImage();
  ReExecutesWhenTheFileChanges();
  return octoray_test::Result();
}
