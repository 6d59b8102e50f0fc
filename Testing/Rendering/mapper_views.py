"""What the mapper tests of Testing/Rendering share: an offscreen window
drawing a mapper's volume, with the mapper's messages gathered."""
import vtk


def gathered(obj, events=(vtk.vtkCommand.WarningEvent, vtk.vtkCommand.ErrorEvent)):
    """The texts of `obj`'s warnings and errors from now on, in a list that
    grows as they come."""
    said = []

    def observe(caller, event, text):
        said.append(text)
    observe.CallDataType = vtk.VTK_STRING
    for event in events:
        obj.AddObserver(event, observe)
    return said


def offscreen_view(mapper, size=(32, 32)):
    """A window drawing `mapper`'s volume, with the mapper's warnings and
    errors gathered: (window, [texts])."""
    said = gathered(mapper)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(vtk.vtkVolumeProperty())
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(*size)
    window.AddRenderer(ren)
    ren.ResetCamera()
    return window, said


def assert_said_once(window, said, text, frames=3):
    """Draws `window` `frames` times; the mapper said exactly one message
    over them, holding `text` (a warning is said once, not every frame)."""
    for _ in range(frames):
        window.Render()
    assert len(said) == 1 and text in said[0], said
