#include "vtkOctreeLODVolume.h"

#include "vtkBoundingBox.h"
#include "vtkLODProp3D.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOctreeVolumeMapper.h"

vtkStandardNewMacro(vtkOctreeLODVolume);

//----------------------------------------------------------------------------
int vtkOctreeLODVolume::RenderOpaqueGeometry(vtkViewport* vp)
{
  return this->DrawsOctree() ? this->Draw(vp, &vtkLODProp3D::RenderOpaqueGeometry)
                             : this->Superclass::RenderOpaqueGeometry(vp);
}

int vtkOctreeLODVolume::RenderTranslucentPolygonalGeometry(vtkViewport* vp)
{
  return this->DrawsOctree() ? this->Draw(vp, &vtkLODProp3D::RenderTranslucentPolygonalGeometry)
                             : this->Superclass::RenderTranslucentPolygonalGeometry(vp);
}

int vtkOctreeLODVolume::RenderVolumetricGeometry(vtkViewport* vp)
{
  return this->DrawsOctree() ? this->Draw(vp, &vtkLODProp3D::RenderVolumetricGeometry)
                             : this->Superclass::RenderVolumetricGeometry(vp);
}

//----------------------------------------------------------------------------
double* vtkOctreeLODVolume::GetBounds()
{
  const int lod = this->SelectLOD();
  auto* mapper = lod >= 0 ? vtkOctreeVolumeMapper::SafeDownCast(this->LODProp->GetLODMapper(lod)) : nullptr;
  if (!mapper)
  {
    return this->Superclass::GetBounds();
  }
  double cube[6];
  mapper->GetVoxelBounds(cube);
  vtkMath::UninitializeBounds(this->Bounds);
  if (!vtkMath::AreBoundsInitialized(cube))
  {
    return this->Bounds;
  }
  // The corners through the volume's matrix (position, scale, ...).
  vtkBoundingBox box;
  vtkMatrix4x4* matrix = this->GetMatrix();
  for (int corner = 0; corner < 8; ++corner)
  {
    double p[4] = { cube[corner & 1], cube[2 + ((corner >> 1) & 1)], cube[4 + ((corner >> 2) & 1)], 1.0 };
    matrix->MultiplyPoint(p, p);
    box.AddPoint(p[0] / p[3], p[1] / p[3], p[2] / p[3]);
  }
  box.GetBounds(this->Bounds);
  return this->Bounds;
}

//----------------------------------------------------------------------------
bool vtkOctreeLODVolume::DrawsOctree()
{
  const int lod = this->LODProp->GetSelectedLODID();
  return lod >= 0 && vtkOctreeVolumeMapper::SafeDownCast(this->LODProp->GetLODMapper(lod));
}

int vtkOctreeLODVolume::Draw(vtkViewport* vp, int (vtkLODProp3D::*pass)(vtkViewport*))
{
  const int drawn = (this->LODProp->*pass)(vp);
  this->EstimatedRenderTime = this->LODProp->GetEstimatedRenderTime();
  return drawn;
}
