// The fuzz findings that made GDCM 3.0 abort or allocate gigabytes
// (Testing/Fuzz/regressions/slice_stack/dicom_*): the DICOM structure check
// (octorayDicomCheck.h) gives each its message, and vtkSliceStackReader,
// after a good read of the bundled CT_small, fails on each in both passes
// with that message naming the file, and keeps its output.
#include "octorayDicomCheck.h"
#include "octorayTestCheck.h"

#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkPolyData.h"
#include "vtkSliceStackReader.h"
#include "vtkTestUtilities.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace
{
struct Finding
{
  const char* Name;
  const char* Message;
};

std::vector<unsigned char> ReadFile(const std::string& name)
{
  std::ifstream in(name, std::ios::binary);
  return std::vector<unsigned char>(
    (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A finding's first byte picks the fuzz target's file extension; the rest
// is the file.
void TestFinding(const Finding& f, const std::string& data, const std::string& regressions,
  const std::string& scratch)
{
  const std::vector<unsigned char> bytes = ReadFile(regressions + "/" + f.Name);
  CHECK(bytes.size() > 132);
  if (bytes.size() <= 132)
  {
    return;
  }
  CHECK_EQ_STR(octoray::CheckDicomStructure(bytes.data() + 1, bytes.size() - 1), f.Message);
  // The reader, metadata path and full read, after a good read of the
  // bundled series: the error names the file, the output stays.
  const std::string path = scratch + "/" + f.Name + ".dcm";
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data() + 1), bytes.size() - 1);
  }
  vtkNew<vtkSliceStackReader> r;
  r->AddFileName((data + "/DICOM/CT_small/CT_small.dcm").c_str());
  r->SetBackgroundRange(-5000, 0);
  r->Update();
  const vtkIdType before = r->GetOutput()->GetNumberOfPoints();
  CHECK(before > 0);
  r->ClearFileNames();
  r->AddFileName(path.c_str());
  r->UpdateInformation();
  const std::string expected = "cannot read DICOM slice '" + path + "': " + f.Message;
  CHECK_EQ_STR(r->GetErrorMessage(), expected);
  r->Update();
  CHECK_EQ_STR(r->GetErrorMessage(), expected);
  CHECK(r->GetOutput()->GetNumberOfPoints() == before);
}
} // namespace

int TestDicomFindings(int argc, char* argv[])
{
  char* root = vtkTestUtilities::GetDataRoot(argc, argv);
  char* temporary = vtkTestUtilities::GetArgOrEnvOrDefault("-T", argc, argv, "VTK_TEMP_DIR", ".");
  const std::string data = std::string(root) + "/Data";
  const std::string regressions = std::string(root) + "/Testing/Fuzz/regressions/slice_stack";
  const std::string scratch = std::string(temporary) + "/TestDicomFindings";
  delete[] root;
  delete[] temporary;
  std::filesystem::create_directories(scratch);

  const Finding findings[] = {
    { "dicom_meta_assert",
      "DICOM element (0002,2E31) at byte 192 (file meta group) has no valid VR: found '59' where "
      "explicit VR little endian expects one" },
    { "dicom_readcompat_assert",
      "DICOM element (0010,0010) at byte 870 claims 16394 bytes, the file has 3936" },
    { "dicom_huge_length_oom",
      "DICOM element (0803,0000) at byte 530 has no valid VR: found '\\x00\\x00' where explicit "
      "VR little endian expects one" },
    { "dicom_meta_end_assert", "the DICOM file ends at byte 146 with its file meta group: no data set follows it" },
    { "dicom_attribute_vr_assert",
      "DICOM element (0028,0011) at byte 1838 has VR IS where the standard gives US, which GDCM 3.0 "
      "cannot read" },
  };
  vtkObject::GlobalWarningDisplayOff();
  for (const Finding& f : findings)
  {
    TestFinding(f, data, regressions, scratch);
  }
  return octoray_test::Result();
}
