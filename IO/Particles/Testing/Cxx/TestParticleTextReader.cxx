// vtkParticleTextReader and vtkParticleTextWriter: formats, strict and
// lenient errors, parallel parsing equal to serial parsing, write/read
// round trip, empty and missing files, CanReadFile.
#include "octorayTestCheck.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkParticleTextReader.h"
#include "vtkParticleTextWriter.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkTestUtilities.h"
#include "vtkUnsignedCharArray.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace
{
std::string Dir;

std::string Write(const std::string& name, const std::string& text)
{
  const std::string path = Dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// Swallows the reader's error and warning output, and its executive's
// "returned failure" (the test driver fails a test that prints errors); the
// tests check GetErrorMessage().
void Quiet(vtkAlgorithm* a)
{
  vtkNew<vtkCallbackCommand> cb;
  cb->SetCallback([](vtkObject*, unsigned long, void*, void*) {});
  a->AddObserver(vtkCommand::ErrorEvent, cb);
  a->AddObserver(vtkCommand::WarningEvent, cb);
  a->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, cb);
}

// Thesis format with a header in another order and an extra column.
void TestHeaderOrder()
{
  vtkNew<vtkParticleTextReader> r;
  r->SetFileName(Write("a.txt", "# r g b x y z reflectivity refraction id\n"
                                "255 128 0 1.5 2.5 3.5 0.25 1.33 7\n"
                                "0 0 0 -1 -2 -3 1 0 8\n")
                   .c_str());
  r->Update();
  vtkPolyData* out = r->GetOutput();
  CHECK(out->GetNumberOfPoints() == 2);
  CHECK(out->GetNumberOfVerts() == 2);
  double p[3];
  out->GetPoint(0, p);
  CHECK(p[0] == 1.5 && p[1] == 2.5 && p[2] == 3.5);
  auto* colors = vtkUnsignedCharArray::SafeDownCast(out->GetPointData()->GetArray("Colors"));
  CHECK(colors && colors->GetValue(0) == 255 && colors->GetValue(1) == 128);
  CHECK(out->GetPointData()->GetArray("Reflectivity")->GetComponent(0, 0) == 0.25);
  CHECK(out->GetPointData()->GetArray("id")->GetComponent(1, 0) == 8);
  CHECK(std::string(r->GetErrorMessage()).empty());
}

// Strict: the error names file, line, column and what was expected; blank
// and comment lines between the data lines count in the line numbers.
// Lenient: both bad lines skipped, counted and listed.
void TestStrictAndLenient()
{
  vtkNew<vtkParticleTextReader> r;
  Quiet(r);
  const std::string path = Write("bad.txt", "1 2 3\n\n  # between\n4 5 6\n7 8 zz\n1 2\n");
  r->SetFileName(path.c_str());
  r->Update();
  CHECK(r->GetOutput()->GetNumberOfPoints() == 0);
  CHECK(std::string(r->GetErrorMessage()) ==
    path + ":5:5: expected a number for column 3 (z), found 'zz'");
  r->LenientOn();
  r->Update();
  CHECK(r->GetOutput()->GetNumberOfPoints() == 2);
  CHECK(r->GetNumberOfSkippedLines() == 2);
  auto* lines =
    vtkIdTypeArray::SafeDownCast(r->GetOutput()->GetFieldData()->GetArray("SkippedLineNumbers"));
  CHECK(lines && lines->GetNumberOfTuples() == 2 && lines->GetValue(0) == 5 &&
    lines->GetValue(1) == 6);
}

// Parallel and serial parsing give the same points, in file order; the
// writer writes them back exactly.
void TestParallelAndRoundTrip()
{
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-100, 100);
  std::string text;
  for (int i = 0; i < 200000; ++i)
  {
    char line[128];
    std::snprintf(line, sizeof line, "%.6f\t%.6f,%.6f %d\n", u(rng), u(rng), u(rng), i);
    text += line;
  }
  const std::string path = Write("many.txt", text);
  vtkNew<vtkParticleTextReader> serial, parallel;
  serial->SetFileName(path.c_str());
  serial->SetNumberOfThreads(1);
  parallel->SetFileName(path.c_str());
  parallel->SetNumberOfThreads(4);
  serial->Update();
  parallel->Update();
  vtkPolyData* a = serial->GetOutput();
  vtkPolyData* b = parallel->GetOutput();
  CHECK(a->GetNumberOfPoints() == 200000 && b->GetNumberOfPoints() == 200000);
  bool same = true;
  vtkDataArray* sa = a->GetPointData()->GetArray("Scalars");
  vtkDataArray* sb = b->GetPointData()->GetArray("Scalars");
  for (vtkIdType i = 0; i < 200000 && same; ++i)
  {
    double pa[3], pb[3];
    a->GetPoint(i, pa);
    b->GetPoint(i, pb);
    same = pa[0] == pb[0] && pa[1] == pb[1] && pa[2] == pb[2] && sa->GetComponent(i, 0) == i &&
      sb->GetComponent(i, 0) == i;
  }
  CHECK(same);

  vtkNew<vtkParticleTextWriter> w;
  w->SetInputData(a);
  const std::string copy = Dir + "/copy.txt";
  w->SetFileName(copy.c_str());
  CHECK(w->Write() == 1);
  vtkNew<vtkParticleTextReader> back;
  back->SetFileName(copy.c_str());
  back->Update();
  CHECK(std::string(back->GetColumnNames()) == "x y z scalar");
  bool equal = back->GetOutput()->GetNumberOfPoints() == 200000;
  for (vtkIdType i = 0; i < 200000 && equal; i += 997)
  {
    double pa[3], pb[3];
    a->GetPoint(i, pa);
    back->GetOutput()->GetPoint(i, pb);
    equal = pa[0] == pb[0] && pa[1] == pb[1] && pa[2] == pb[2];
  }
  CHECK(equal);
}

void TestEmptyAndMissing()
{
  vtkNew<vtkParticleTextReader> r;
  Quiet(r);
  const std::string empty = Write("empty.txt", "");
  r->SetFileName(empty.c_str());
  r->Update();
  CHECK_CONTAINS(r->GetErrorMessage(), empty + ": the file is empty (0 bytes)");
  r->SetFileName((Dir + "/missing.txt").c_str());
  r->Update();
  CHECK_CONTAINS(r->GetErrorMessage(), "missing.txt: cannot open the file");
}

// CanReadFile: the content decides for names other than .particles (a
// reader factory asks it for .txt, .csv, .xyz), a .particles name is ours.
void TestCanReadFile()
{
  std::string numbers;
  for (int i = 0; i < 5000; ++i) // more than the 64 KiB looked at
  {
    numbers += std::to_string(i) + ".5 " + std::to_string(-i) + " 3.25\n";
  }
  const struct
  {
    const char* Name;
    std::string Text;
    int Expected;
  } cases[] = {
    { "thesis.txt", "# x y z r g b reflectivity refraction\n1 2 3 4 5 6 0.5 0\n", 1 },
    { "xyz.xyz", "1 2 3\n4 5 6\n", 1 },
    { "scalar.txt", "1 2 3 0.5\r\n4 5 6 0.25\r\n", 1 },
    { "rgb.csv", "1,2,3,255,0,0\n4,5,6,0,255,0\n", 1 },
    { "named.csv", "x,y,z,intensity,return\n1,2,3,0.5,1\n", 1 },
    { "comments.txt", "# scan 7\n\n1 2 3 # first\n4 5 6\n", 1 },
    { "long.txt", numbers, 1 },
    { "text.csv", "name,value,unit\nfoo,1,m\n", 0 },
    { "xyzfirst.csv", "a,b,c\n1,2,3\n", 0 }, // 3 names, but not x y z
    { "five.csv", "1,2,3,4,5\n", 0 },
    { "ragged.txt", "1 2 3\n4 5\n", 0 },
    { "word.txt", "1 2 3\n4 5 six\n", 0 },
    { "molecule.xyz", "3\nwater\nO 0 0 0\nH 1 0 0\nH 0 1 0\n", 0 },
    { "note.txt", "hello world\n", 0 },
    { "header-only.csv", "x,y,z\n", 0 },
    { "binary.txt", std::string("1 2 3\n\0\x01\x02\n", 10), 0 },
    { "empty.txt", "", 0 },
    { "bad.particles", "not particles at all\n", 1 }, // the reader reports what is wrong
  };
  for (const auto& c : cases)
  {
    const std::string path = Write(c.Name, c.Text);
    const int got = vtkParticleTextReader::CanReadFile(path.c_str());
    if (got != c.Expected)
    {
      std::cerr << "CanReadFile(" << c.Name << ") = " << got << ", expected " << c.Expected
                << std::endl;
    }
    CHECK(got == c.Expected);
  }
  CHECK(vtkParticleTextReader::CanReadFile((Dir + "/missing.txt").c_str()) == 0);
  CHECK(vtkParticleTextReader::CanReadFile(Dir.c_str()) == 0); // a directory
  CHECK(vtkParticleTextReader::CanReadFile(nullptr) == 0);
}
} // namespace

int TestParticleTextReader(int argc, char* argv[])
{
  char* temporary = vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", ".");
  Dir = std::string(temporary) + "/TestParticleTextReader";
  delete[] temporary;
  std::filesystem::create_directories(Dir);

  TestHeaderOrder();
  TestStrictAndLenient();
  TestParallelAndRoundTrip();
  TestEmptyAndMissing();
  TestCanReadFile();
  return octoray_test::Result();
}
