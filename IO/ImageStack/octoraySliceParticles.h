// The particles of a slice stack (the reader's output 0) from its image:
// one per sample that is not background, among the pixels the region of
// interest and the stride select and, with filling, the planes interpolated
// between slices (octorayLattice.h); and the lattice they lie on, in the
// field-data array PointLattice, for the octree mapper's leaf grid.
// Private to the module; not wrapped.
#ifndef octoraySliceParticles_h
#define octoraySliceParticles_h

#include <string>

class vtkImageData;
class vtkPolyData;

namespace octoray
{
namespace slices
{
// vtkSliceStackReader's properties of the same names.
struct ParticleOptions
{
  int RegionOfInterest[6] = { -1, -1, -1, -1, -1, -1 };
  int Stride[3] = { 1, 1, 1 };
  bool FillBetweenSlices = true;
  double BackgroundRange[2] = { 0, 0 };
  bool GenerateVertices = true;
  bool GradientNormals = false;
};

// What is wrong with `options` for a stack of dims[0] x dims[1] pixels and
// dims[2] slices, naming the property: a stride below 1, a region of
// interest whose minimum lies above its maximum or past the stack's edge.
// Empty when nothing is.
std::string ParticleOptionsProblem(const int dims[3], const ParticleOptions& options);

// Points (float), `Scalars` (intensity: grey, or the mean of R, G, B), for
// colour images `Colors` (RGB bytes), for grey ones with GradientNormals
// `Normals` (octorayLattice.h's GradientNormal), vertex cells, PointLattice;
// no points when the region of interest is empty (options as
// ParticleOptionsProblem passes them).
void MakeParticles(vtkImageData* image, const ParticleOptions& options, vtkPolyData* output);
} // namespace slices
} // namespace octoray

#endif
