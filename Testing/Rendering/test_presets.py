"""CT transfer-function presets (vtkOctreeVolumePresets, octoray.apply_preset)
from Python: each name puts the documented control points on a
vtkVolumeProperty, an unknown name is an error that names the known ones.

The expected control points are this file's own copy of the class
documentation (VTK's FixedPointVolumeRayCastMapperCT example, as 3D Slicer's
presets.xml repeats them): (value, r, g, b, midpoint, sharpness) and
(value, opacity, midpoint, sharpness).
"""
import math

import pytest
import vtk

import octoray

COLOUR = {
    "ct-bone": [(-3024, 0, 0, 0, 0.5, 0), (-16, 0.73, 0.25, 0.30, 0.49, 0.61), (641, 0.90, 0.82, 0.56, 0.5, 0),
                (3071, 1, 1, 1, 0.5, 0)],
    "ct-skin": [(-3024, 0, 0, 0, 0.5, 0), (-1000, 0.62, 0.36, 0.18, 0.5, 0), (-500, 0.88, 0.60, 0.29, 0.33, 0.45),
                (3071, 0.83, 0.66, 1, 0.5, 0)],
    "ct-muscle": [(-3024, 0, 0, 0, 0.5, 0), (-155, 0.55, 0.25, 0.15, 0.5, 0.92), (217, 0.88, 0.60, 0.29, 0.33, 0.45),
                  (420, 1, 0.94, 0.95, 0.5, 0), (3071, 0.83, 0.66, 1, 0.5, 0)],
}
OPACITY = {
    "ct-bone": [(-3024, 0, 0.5, 0), (-16, 0, 0.49, 0.61), (641, 0.72, 0.5, 0), (3071, 0.71, 0.5, 0)],
    "ct-skin": [(-3024, 0, 0.5, 0), (-1000, 0, 0.5, 0), (-500, 1, 0.33, 0.45), (3071, 1, 0.5, 0)],
    "ct-muscle": [(-3024, 0, 0.5, 0), (-155, 0, 0.5, 0.92), (217, 0.68, 0.33, 0.45), (420, 0.83, 0.5, 0),
                  (3071, 0.80, 0.5, 0)],
}
# The value from which the octree's surface modes draw: where the opacity
# first reaches half its maximum (computed independently below too).
THRESHOLD = {"ct-bone": 306, "ct-skin": -750, "ct-muscle": 34}


def nodes(function, width):
    """The nodes of a colour (width 6) or opacity (width 4) transfer function."""
    out = []
    for i in range(function.GetSize()):
        v = [0.0] * width
        function.GetNodeValue(i, v)
        out.append(tuple(v))
    return out


def colour_nodes(ctf):
    return nodes(ctf, 6)


def opacity_nodes(pwf):
    return nodes(pwf, 4)


def same(got, want):
    return len(got) == len(want) and all(
        len(g) == len(w) and all(math.isclose(a, b, abs_tol=1e-9) for a, b in zip(g, w)) for g, w in zip(got, want))


def test_names():
    assert octoray.preset_names() == ["ct-bone", "ct-skin", "ct-muscle"]
    p = octoray.vtkOctreeVolumePresets()
    names = p.GetNames()
    assert [names.GetValue(i) for i in range(names.GetNumberOfValues())] == octoray.preset_names()
    assert p.GetNamesAsString() == "ct-bone, ct-skin, ct-muscle"
    assert p.GetName(3) is None and p.GetName(-1) is None
    for name in octoray.preset_names():
        assert p.HasPreset(name) and p.GetDescription(name)
    # Case and '_' for '-' do not matter.
    assert p.HasPreset("CT_Bone") and p.HasPreset("CT-SKIN")
    assert not p.HasPreset("bone") and not p.HasPreset("") and not p.HasPreset(None)


@pytest.mark.parametrize("name", sorted(COLOUR))
def test_apply_sets_the_documented_points(name):
    prop = vtk.vtkVolumeProperty()
    shared = vtk.vtkColorTransferFunction()
    shared.AddRGBPoint(0, 1, 0, 0)
    prop.SetColor(shared)
    threshold = octoray.apply_preset(name.upper(), prop)
    assert same(colour_nodes(prop.GetRGBTransferFunction(0)), COLOUR[name])
    assert same(opacity_nodes(prop.GetScalarOpacity(0)), OPACITY[name])
    # New function objects: a function shared with another property is left alone.
    assert prop.GetRGBTransferFunction(0) is not shared and shared.GetSize() == 1
    assert prop.GetShade(0) == 1
    assert (prop.GetAmbient(0), prop.GetDiffuse(0), prop.GetSpecular(0), prop.GetSpecularPower(0)) == \
        pytest.approx((0.1, 0.9, 0.2, 10.0))
    assert prop.GetInterpolationType() == vtk.VTK_LINEAR_INTERPOLATION
    assert threshold == THRESHOLD[name] == octoray.vtkOctreeVolumePresets.GetSurfaceThreshold(name)
    # The threshold is where the preset's opacity first reaches half its maximum.
    pwf = prop.GetScalarOpacity(0)
    top = max(o[1] for o in OPACITY[name])
    first = next(x for x in range(-3024, 3072) if pwf.GetValue(x) >= 0.5 * top)
    assert threshold == first


def test_apply_to_functions():
    p = octoray.vtkOctreeVolumePresets()
    ctf, pwf = vtk.vtkColorTransferFunction(), vtk.vtkPiecewiseFunction()
    ctf.AddRGBPoint(5, 1, 1, 1)
    pwf.AddPoint(5, 0.3)
    assert p.Apply("ct-muscle", ctf, pwf)
    assert same(colour_nodes(ctf), COLOUR["ct-muscle"])
    assert same(opacity_nodes(pwf), OPACITY["ct-muscle"])
    assert p.GetLastError() == ""


def test_unknown_name_is_an_error_naming_the_known_ones():
    prop = vtk.vtkVolumeProperty()
    before = prop.GetRGBTransferFunction(0), prop.GetScalarOpacity(0), prop.GetShade(0)
    with pytest.raises(ValueError) as e:
        octoray.apply_preset("ct-lung", prop)
    message = str(e.value)
    assert "ct-lung" in message
    for name in octoray.preset_names():
        assert name in message
    assert (prop.GetRGBTransferFunction(0), prop.GetScalarOpacity(0), prop.GetShade(0)) == before

    # The C++ class itself: False, an ErrorEvent and GetLastError with the names.
    p = octoray.vtkOctreeVolumePresets()
    errors = []

    @vtk.calldata_type(vtk.VTK_STRING)
    def on_error(obj, event, text):
        errors.append(text)

    p.AddObserver("ErrorEvent", on_error)
    assert not p.Apply("bone", prop)
    assert len(errors) == 1 and "'bone'" in errors[0] and "ct-bone, ct-skin, ct-muscle" in errors[0]
    assert "ct-bone, ct-skin, ct-muscle" in p.GetLastError()
    assert (prop.GetRGBTransferFunction(0), prop.GetScalarOpacity(0), prop.GetShade(0)) == before
    assert math.isnan(p.GetSurfaceThreshold("bone"))
    assert p.GetDescription("bone") is None
