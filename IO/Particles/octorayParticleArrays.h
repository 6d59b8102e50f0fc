// The output arrays of a particle text file, for vtkParticleTextReader's
// parser (octorayParticleTextParser.h): made once at their final size from
// the column layout, so that parsing threads store each point's columns in
// place; compacted over the lines that lenient mode skips; handed to the
// polydata. Private to the module; not wrapped.
#ifndef octorayParticleArrays_h
#define octorayParticleArrays_h

#include "octorayParticleTextFormat.h"

#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

namespace octoray
{
namespace ptext
{
template <typename Real>
class ParticleArrays
{
public:
  // Arrays of n points for these columns: Points always, Colors for r g b,
  // Reflectivity, Refraction, Scalars and the extras where a column names
  // them. False when the memory is not there (a file of billions of short
  // lines can ask for more than there is): say so instead of writing
  // through a null pointer.
  bool Allocate(const std::vector<Column>& columns, const std::vector<std::string>& extras,
    vtkIdType n)
  {
    this->Columns = &columns;
    this->Total = n;
    bool has[static_cast<int>(Sink::Extra)] = {};
    for (const auto& c : columns)
    {
      if (c.Target != Sink::Extra)
      {
        has[static_cast<int>(c.Target)] = true;
      }
    }
    this->PointsArray = this->MakeArray("Points", 3);
    this->Out.Points = this->PointsArray->GetPointer(0);
    if (has[static_cast<int>(Sink::R)])
    {
      this->Colors = vtkSmartPointer<vtkUnsignedCharArray>::New();
      this->Colors->SetName("Colors");
      this->Colors->SetNumberOfComponents(3);
      this->Colors->SetNumberOfTuples(n);
      this->Out.Colors = this->Colors->GetPointer(0);
    }
    auto optional = [&](Sink sink, const char* name, vtkSmartPointer<RealArray>& a, Real*& out) {
      if (has[static_cast<int>(sink)])
      {
        a = this->MakeArray(name, 1);
        out = a->GetPointer(0);
      }
    };
    optional(Sink::Reflectivity, "Reflectivity", this->Reflectivity, this->Out.Reflectivity);
    optional(Sink::Refraction, "Refraction", this->Refraction, this->Out.Refraction);
    optional(Sink::Scalar, "Scalars", this->Scalars, this->Out.Scalars);
    for (const auto& name : extras)
    {
      this->Extras.push_back(this->MakeArray(name.c_str(), 1));
      this->Out.Extras.push_back(this->Extras.back()->GetPointer(0));
    }
    bool ok = true;
    for (vtkDataArray* a : this->All())
    {
      ok = ok && a->GetNumberOfTuples() == n;
    }
    return ok;
  }

  // The columns' values of point pt, in the order of the columns.
  void Store(const Real* values, vtkIdType pt) const
  {
    const Sinks& out = this->Out;
    const std::vector<Column>& columns = *this->Columns;
    Real rgb[3] = { 0, 0, 0 };
    for (size_t f = 0; f < columns.size(); ++f)
    {
      const Real v = values[f];
      switch (columns[f].Target)
      {
        case Sink::X:
          out.Points[3 * pt] = v;
          break;
        case Sink::Y:
          out.Points[3 * pt + 1] = v;
          break;
        case Sink::Z:
          out.Points[3 * pt + 2] = v;
          break;
        case Sink::R:
          rgb[0] = v;
          break;
        case Sink::G:
          rgb[1] = v;
          break;
        case Sink::B:
          rgb[2] = v;
          break;
        case Sink::Reflectivity:
          out.Reflectivity[pt] = v;
          break;
        case Sink::Refraction:
          out.Refraction[pt] = v;
          break;
        case Sink::Scalar:
          out.Scalars[pt] = v;
          break;
        case Sink::Extra:
          out.Extras[columns[f].Extra][pt] = v;
          break;
      }
    }
    if (out.Colors)
    {
      for (int k = 0; k < 3; ++k)
      {
        // rgb is in [0, 255] (checked by the parser): adding 0.5 rounds half up.
        out.Colors[3 * pt + k] = static_cast<unsigned char>(rgb[k] + Real(0.5));
      }
    }
  }

  // Keeps the points whose `valid` is not 0, in the file's order; returns
  // how many.
  vtkIdType Compact(const std::vector<unsigned char>& valid)
  {
    const Sinks& out = this->Out;
    vtkIdType w = 0;
    for (vtkIdType i = 0; i < this->Total; ++i)
    {
      if (!valid[i])
      {
        continue;
      }
      if (w != i)
      {
        std::copy_n(out.Points + 3 * i, 3, out.Points + 3 * w);
        if (out.Colors)
          std::copy_n(out.Colors + 3 * i, 3, out.Colors + 3 * w);
        if (out.Reflectivity)
          out.Reflectivity[w] = out.Reflectivity[i];
        if (out.Refraction)
          out.Refraction[w] = out.Refraction[i];
        if (out.Scalars)
          out.Scalars[w] = out.Scalars[i];
        for (Real* x : out.Extras)
          x[w] = x[i];
      }
      ++w;
    }
    for (vtkDataArray* a : this->All())
    {
      a->Resize(w);
      a->SetNumberOfTuples(w);
    }
    return w;
  }

  // The points and the point data of output.
  void Fill(vtkPolyData* output) const
  {
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetData(this->PointsArray);
    output->SetPoints(points);
    vtkPointData* pd = output->GetPointData();
    if (this->Colors)
    {
      pd->AddArray(this->Colors);
      // Colors drive direct-RGB rendering; VTK treats them as scalars too.
      pd->SetScalars(this->Colors);
    }
    if (this->Scalars)
    {
      pd->AddArray(this->Scalars);
      pd->SetActiveScalars(this->Colors ? this->Colors->GetName() : this->Scalars->GetName());
    }
    if (this->Reflectivity)
    {
      pd->AddArray(this->Reflectivity);
    }
    if (this->Refraction)
    {
      pd->AddArray(this->Refraction);
    }
    for (auto& a : this->Extras)
    {
      pd->AddArray(a);
    }
  }

private:
  using RealArray = typename std::conditional<std::is_same<Real, double>::value, vtkDoubleArray,
    vtkFloatArray>::type;

  // Where Store writes: the arrays' memory.
  struct Sinks
  {
    Real* Points = nullptr;
    unsigned char* Colors = nullptr;
    Real* Reflectivity = nullptr;
    Real* Refraction = nullptr;
    Real* Scalars = nullptr;
    std::vector<Real*> Extras;
  };

  vtkSmartPointer<RealArray> MakeArray(const char* name, int components)
  {
    auto a = vtkSmartPointer<RealArray>::New();
    a->SetName(name);
    a->SetNumberOfComponents(components);
    a->SetNumberOfTuples(this->Total);
    return a;
  }

  // Every array made.
  std::vector<vtkDataArray*> All() const
  {
    std::vector<vtkDataArray*> arrays{ this->PointsArray.Get() };
    for (vtkDataArray* a : { static_cast<vtkDataArray*>(this->Colors.Get()),
           static_cast<vtkDataArray*>(this->Reflectivity.Get()),
           static_cast<vtkDataArray*>(this->Refraction.Get()),
           static_cast<vtkDataArray*>(this->Scalars.Get()) })
    {
      if (a)
      {
        arrays.push_back(a);
      }
    }
    for (const auto& a : this->Extras)
    {
      arrays.push_back(a);
    }
    return arrays;
  }

  const std::vector<Column>* Columns = nullptr;
  vtkIdType Total = 0;
  vtkSmartPointer<RealArray> PointsArray, Reflectivity, Refraction, Scalars;
  vtkSmartPointer<vtkUnsignedCharArray> Colors;
  std::vector<vtkSmartPointer<RealArray>> Extras;
  Sinks Out;
};

} // namespace ptext
} // namespace octoray

#endif
