"""Shared helpers for the octoray reader tests (run by ctest, label python).

The tests import octoray the way a script does: `import vtk, octoray` in
Debian's python3, with PYTHONPATH pointing at the build tree's package.
"""
import os

import pytest
import vtk  # noqa: F401  (ParaView's VTK 9.2, as a script would import it)
import octoray  # noqa: F401
from vtk.util.numpy_support import vtk_to_numpy

DATA = os.environ.get(
    "OCTORAY_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "Data"))


class Messages:
    """Collects the error and warning events of an algorithm, so tests check
    messages by content (and VTK does not print them)."""

    def __init__(self, algorithm):
        self.errors = []
        self.warnings = []

        @vtk.calldata_type(vtk.VTK_STRING)
        def on_error(obj, event, text):
            self.errors.append(text)

        @vtk.calldata_type(vtk.VTK_STRING)
        def on_warning(obj, event, text):
            self.warnings.append(text)

        # Keep references: the wrapper holds only weak ones.
        self._callbacks = (on_error, on_warning)
        algorithm.AddObserver("ErrorEvent", on_error)
        algorithm.AddObserver("WarningEvent", on_warning)
        # The executive reports a failed request too; keep that quiet.
        algorithm.GetExecutive().AddObserver("ErrorEvent", lambda *a: None)


@pytest.fixture
def data_dir():
    return os.path.abspath(DATA)


def array(data, name):
    a = data.GetPointData().GetArray(name)
    return None if a is None else vtk_to_numpy(a)


def points(data):
    return vtk_to_numpy(data.GetPoints().GetData())
