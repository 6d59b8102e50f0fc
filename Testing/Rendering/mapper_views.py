"""What the mapper tests of Testing/Rendering share: an offscreen window
drawing a mapper's volume, with the mapper's messages gathered."""
import vtk


def offscreen_view(mapper, size=(32, 32)):
    """A window drawing `mapper`'s volume, with the mapper's warnings and
    errors gathered: (window, [texts])."""
    said = []

    def observe(caller, event, text):
        said.append(text)
    observe.CallDataType = vtk.VTK_STRING
    mapper.AddObserver(vtk.vtkCommand.WarningEvent, observe)
    mapper.AddObserver(vtk.vtkCommand.ErrorEvent, observe)
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
