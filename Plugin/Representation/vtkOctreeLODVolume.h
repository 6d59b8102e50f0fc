/**
 * @class   vtkOctreeLODVolume
 * @brief   the volume of vtkOctreeVolumeRepresentation
 *
 * The volume of the representation: ParaView's vtkPVLODVolume, except
 *
 * - that it lets vtkOctreeVolumeMapper draw without scalars.
 *   vtkPVLODVolume::CanRender skips any vtkVolumeMapper whose input has no
 *   scalar array selected ("volume mappers are notorious for segfaulting when
 *   the scalar array is missing"); the octree mapper is not: without scalars
 *   it draws the points' own colours or white, and with an empty input it
 *   draws nothing. So "Solid Color" (e.g. PLY points with normals only)
 *   draws, and a rank with an empty piece is simply empty;
 * - that its bounds hold the voxels, not only the points
 *   (vtkOctreeVolumeMapper::GetVoxelBounds: out to the leaf grid): IceT crops each
 *   rank's picture to the screen rectangle of the renderer's prop bounds
 *   (vtkIceTCompositePass: ComputeVisiblePropBounds, icetBoundingVertices),
 *   and the voxels around the outermost points reach past the points' bounds
 *   by up to a leaf, so with the points' bounds the parallel picture lost
 *   the edge voxels' outer halves. (The view's camera reset also takes the
 *   props' bounds: it frames the voxels, up to a leaf wider than the
 *   points.)
 */
#ifndef vtkOctreeLODVolume_h
#define vtkOctreeLODVolume_h

#include "vtkPVLODVolume.h"

class vtkLODProp3D;

class vtkOctreeLODVolume : public vtkPVLODVolume
{
public:
  static vtkOctreeLODVolume* New();
  vtkTypeMacro(vtkOctreeLODVolume, vtkPVLODVolume);

  int RenderOpaqueGeometry(vtkViewport* vp) override;
  int RenderTranslucentPolygonalGeometry(vtkViewport* vp) override;
  int RenderVolumetricGeometry(vtkViewport* vp) override;
  double* GetBounds() override;

protected:
  vtkOctreeLODVolume() = default;
  ~vtkOctreeLODVolume() override = default;

private:
  vtkOctreeLODVolume(const vtkOctreeLODVolume&) = delete;
  void operator=(const vtkOctreeLODVolume&) = delete;

  // The LOD chosen for this frame (by SetAllocatedRenderTime) is the octree.
  bool DrawsOctree();
  // As vtkPVLODVolume's passes, less CanRender.
  int Draw(vtkViewport* vp, int (vtkLODProp3D::*pass)(vtkViewport*));
};

#endif
// VTK-HeaderTest-Exclude: vtkOctreeLODVolume.h
