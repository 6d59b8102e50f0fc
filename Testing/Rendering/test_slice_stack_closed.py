"""A slice stack read by vtkSliceStackReader draws as a closed volume
(label python, vtk; run under Xvfb by ctest).

A solid block is written as 16-bit PNG slices 3 pixel spacings apart and
read back; its particles (output 0) and its volume (output 1, a
vtkImageData) are drawn by the octree mapper on the CPU from the side, with
the slice axis across the view, where gaps between slices would show as
stripes of background. No pixel inside the block's silhouette may show the
background; the silhouette is VTK's drawing of the block's box (the voxel
centres' bounds) with the same camera, shrunk by two pixels; and nothing may
be drawn far outside it. The pictures are left in pytest's tmp_path.
"""
import os

import numpy as np
import pytest
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

import octoray

SIZE = 240
SPACING = (1.0, 1.0, 3.0)  # slices 3 pixel spacings apart
# The block: columns 2..17 of 20, rows 2..11 of 14, slices 1..5 of 7; value
# 1000 on 0. In world coordinates (rows flipped so that j grows upwards):
BLOCK = (2.0, 17.0, 2.0, 11.0, 3.0, 15.0)


def write_block(folder):
    vol = np.zeros((7, 14, 20), np.uint16)
    vol[1:6, 2:12, 2:18] = 1000
    os.makedirs(folder, exist_ok=True)
    for k, s in enumerate(vol):
        image = vtk.vtkImageData()
        image.SetDimensions(s.shape[1], s.shape[0], 1)
        image.GetPointData().SetScalars(numpy_to_vtk(np.ascontiguousarray(s[::-1]).ravel(), deep=1))
        w = vtk.vtkPNGWriter()
        w.SetInputData(image)
        w.SetFileName(os.path.join(folder, "block_%02d.png" % k))
        w.Write()
    return vol


def read(folder, fill=None):
    r = octoray.vtkSliceStackReader()
    r.SetDirectoryName(folder)
    r.SetSpacing(*SPACING)
    if fill is not None:
        r.SetFillBetweenSlices(fill)
    r.Update()
    assert r.GetErrorMessage() == ""
    return r


def aim(ren, view):
    """view: (direction from the camera, view up, parallel)."""
    direction, up, parallel = view
    c = [0.5 * (BLOCK[0] + BLOCK[1]), 0.5 * (BLOCK[2] + BLOCK[3]), 0.5 * (BLOCK[4] + BLOCK[5])]
    cam = ren.GetActiveCamera()
    cam.SetFocalPoint(c)
    cam.SetPosition(*[c[a] - 100 * direction[a] for a in range(3)])
    cam.SetViewUp(*up)
    cam.SetViewAngle(30)
    cam.SetParallelProjection(parallel)
    ren.ResetCamera(BLOCK)
    ren.ResetCameraClippingRange([BLOCK[a] + (10 if a % 2 else -10) for a in range(6)])


def capture(ren, path=None):
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(SIZE, SIZE)
    window.AddRenderer(ren)
    window.Render()
    pictures = []
    for kind in ("rgb", "z"):
        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(window)
        grab.ReadFrontBufferOff()
        grab.SetInputBufferTypeToZBuffer() if kind == "z" else grab.SetInputBufferTypeToRGB()
        grab.Update()
        a = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars())
        pictures.append(a.reshape(SIZE, SIZE, -1))
        if path and kind == "rgb":
            w = vtk.vtkPNGWriter()
            w.SetFileName(path)
            w.SetInputConnection(grab.GetOutputPort())
            w.Write()
    return pictures[0], pictures[1][..., 0]


def box_mask(bounds, view):
    """Pixels VTK covers drawing the box `bounds` (camera aimed at the block)."""
    cube = vtk.vtkCubeSource()
    cube.SetBounds(bounds)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputConnection(cube.GetOutputPort())
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    ren = vtk.vtkRenderer()
    ren.AddActor(actor)
    aim(ren, view)
    return capture(ren)[1] < 1.0


def morph(mask, r):
    """Shrink (r > 0) or grow (r < 0) a mask by |r| pixels (square window)."""
    a = abs(r)
    padded = np.pad(mask, a, constant_values=False)
    shifted = [padded[a + dy:a + dy + SIZE, a + dx:a + dx + SIZE]
               for dy in range(-a, a + 1) for dx in range(-a, a + 1)]
    return np.logical_and.reduce(shifted) if r > 0 else np.logical_or.reduce(shifted)


def draw(data, view, path, image=False, fill=True, shade=False):
    mapper = octoray.vtkCPUOctreeVolumeMapper()
    mapper.SetInputData(data)
    if not fill:
        mapper.SetFillBetweenSlices(False)
    prop = vtk.vtkVolumeProperty()
    prop.SetShade(shade)
    ctf = vtk.vtkColorTransferFunction()
    ctf.AddRGBPoint(0, 0.9, 0.8, 0.4)
    ctf.AddRGBPoint(1000, 0.9, 0.8, 0.4)
    prop.SetColor(ctf)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    aim(ren, view)
    rgb, z = capture(ren, path)
    return rgb, z, mapper


VIEWS = {
    "side-parallel": ((0, 1, 0), (0, 0, 1), True),   # looking along +y, slices horizontal
    "side": ((0, 1, 0), (0, 0, 1), False),
    "side-x": ((-1, 0, 0), (0, 0, 1), True),          # looking along -x
    "grazing": ((0.34, 0.94, -0.05), (0, 0, 1), False),
}


def holes_and_spill(rgb, z, view, leaf):
    """Pixels inside the silhouette, background ones among them, and pixels
    drawn outside the block grown by a leaf across the slices and by a slice
    spacing along them (where the interpolated values between the block's
    last slice and the empty one next to it are still above the
    background), and by two pixels."""
    inside = morph(box_mask(BLOCK, view), 2)
    grow = (leaf, leaf, max(leaf, SPACING[2]))
    grown = [BLOCK[a] + (grow[a // 2] if a % 2 else -grow[a // 2]) for a in range(6)]
    near = morph(box_mask(grown, view), -2)
    drawn = z < 1.0
    background = ~drawn | (rgb.max(axis=2) == 0)
    return int(inside.sum()), int((inside & background).sum()), int((drawn & ~near).sum())


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    folder = str(tmp_path_factory.mktemp("block"))
    vol = write_block(folder)
    return folder, vol


@pytest.mark.parametrize("name", sorted(VIEWS))
def test_particles_close_the_gaps(block, tmp_path, name):
    folder, vol = block
    r = read(folder)  # FillBetweenSlices on by default
    out = r.GetOutput()
    view = VIEWS[name]
    rgb, z, mapper = draw(out, view, str(tmp_path / ("particles-%s.png" % name)))
    leaf = mapper.GetLeafSize()
    inside, holes, spill = holes_and_spill(rgb, z, view, leaf)
    print("%s: %d particles, leaf %g, %d pixels inside the silhouette, %d background, %d drawn outside"
          % (name, out.GetNumberOfPoints(), leaf, inside, holes, spill))
    assert inside > SIZE * SIZE / 20
    assert holes == 0
    assert spill == 0
    # The particles are no farther apart along the slice axis than across
    # it, and the leaves are the pixel size.
    p = vtk_to_numpy(out.GetPoints().GetData())
    zs = np.unique(np.round(p[:, 2], 5))
    assert np.allclose(np.diff(zs), SPACING[0]), zs
    assert abs(leaf - SPACING[0]) < 1e-6

    # The stack's volume (output 1) given to the mapper: the same rule, the
    # same points, the same picture.
    rgb2, z2, mapper2 = draw(r.GetImageOutput(), view, str(tmp_path / ("image-%s.png" % name)), image=True)
    assert mapper2.GetNumberOfOctreePoints() == out.GetNumberOfPoints()
    assert mapper2.GetLeafSize() == leaf
    assert np.array_equal(rgb2, rgb)


def test_shaded_particles_draw_as_the_shaded_image(block, tmp_path):
    """Shaded (Phong, the headlight), the particles with their gradient
    normals (vtkSliceStackReader's GradientNormals) draw as the stack's
    volume with the mapper's gradient normals (ImageGradientNormals): the
    same normals, the same picture. Without them the particles' faces were
    lit by the octree's occupancy."""
    folder, vol = block
    r = read(folder)
    r.SetGradientNormals(True)
    r.Update()
    view = VIEWS["grazing"]
    rgb, z, mapper = draw(r.GetOutput(), view, str(tmp_path / "particles-shaded.png"), shade=True)
    rgb2, z2, mapper2 = draw(r.GetImageOutput(), view, str(tmp_path / "image-shaded.png"), image=True, shade=True)
    assert np.array_equal(rgb2, rgb)
    r.SetGradientNormals(False)
    r.Update()
    rgb3, z3, mapper3 = draw(r.GetOutput(), view, str(tmp_path / "particles-occupancy-normals.png"), shade=True)
    assert not np.array_equal(rgb3, rgb)


def test_unfilled_particles_are_closed_with_larger_leaves(block, tmp_path):
    """FillBetweenSlices off: the slices' pixels only; the mapper's leaves
    are then as large as the slice spacing, and the block is still closed."""
    folder, vol = block
    r = read(folder, fill=False)
    out = r.GetOutput()
    assert out.GetNumberOfPoints() == np.count_nonzero(vol)
    view = VIEWS["side-parallel"]
    rgb, z, mapper = draw(out, view, str(tmp_path / "particles-unfilled.png"))
    inside, holes, spill = holes_and_spill(rgb, z, view, mapper.GetLeafSize())
    assert abs(mapper.GetLeafSize() - SPACING[2]) < 1e-6
    assert inside > SIZE * SIZE / 20 and holes == 0 and spill == 0
    rgb2, z2, mapper2 = draw(r.GetImageOutput(), view, str(tmp_path / "image-unfilled.png"), image=True,
                             fill=False)
    assert np.array_equal(rgb2, rgb)


def test_moved_particles_lose_their_lattice(block):
    """A filter that moves the points keeps the field-data array naming the
    lattice; the mapper sees that the points left it and chooses the leaves
    as for any point set (the picture is then not checked)."""
    folder, vol = block
    out = read(folder).GetOutput()
    shift = vtk.vtkTransform()
    shift.Translate(0.37, 0, 0)
    moved = vtk.vtkTransformPolyDataFilter()
    moved.SetInputData(out)
    moved.SetTransform(shift)
    moved.Update()
    assert moved.GetOutput().GetFieldData().GetArray("PointLattice") is not None
    _, _, on = draw(out, VIEWS["side"], None)
    _, _, off = draw(moved.GetOutput(), VIEWS["side"], None)
    assert on.GetLeafSize() == SPACING[0]
    assert off.GetLeafSize() != SPACING[0]
