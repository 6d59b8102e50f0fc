/**
 * @class   vtkParticleTextWriter
 * @brief   Writes point data as a particle text file that vtkParticleTextReader reads back.
 *
 * One line per point, after a header line that names the columns:
 * `# x y z [r g b] [reflectivity refraction] [scalar] [extras...]`. The
 * columns come from the point arrays `Colors` (3 components, 0-255),
 * `Reflectivity`, `Refraction`, `Scalars` and, with WriteAllArrays, every
 * other one-component numeric point array (by its name). Numbers are written
 * with the shortest text that reads back to the same value (float or
 * double), so a write/read round trip is exact.
 */
#ifndef vtkParticleTextWriter_h
#define vtkParticleTextWriter_h

#include "octorayIOParticlesModule.h" // for export macro
#include "vtkWriter.h"

class OCTORAYIOPARTICLES_EXPORT vtkParticleTextWriter : public vtkWriter
{
public:
  static vtkParticleTextWriter* New();
  vtkTypeMacro(vtkParticleTextWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /// Also write every other one-component numeric point array (default on).
  vtkSetMacro(WriteAllArrays, bool);
  vtkGetMacro(WriteAllArrays, bool);
  vtkBooleanMacro(WriteAllArrays, bool);
  ///@}

protected:
  vtkParticleTextWriter();
  ~vtkParticleTextWriter() override;

  void WriteData() override;
  int FillInputPortInformation(int port, vtkInformation* info) override;

  char* FileName = nullptr;
  bool WriteAllArrays = true;

private:
  vtkParticleTextWriter(const vtkParticleTextWriter&) = delete;
  void operator=(const vtkParticleTextWriter&) = delete;
};

#endif
