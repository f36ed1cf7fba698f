"""A partitioned mesh as VTK's parallel writer writes it: vtkXMLPUnstructuredGridWriter
asks its source for one piece at a time, and this source gives piece k as `make(k)`, a
vtkUnstructuredGrid. Shared by .ci/tetmesh-corpus.py and benches/pvtu/run.py."""

import vtk
from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase


class Pieces(VTKPythonAlgorithmBase):
    """A source that gives the piece the writer asks for: `make(k)` for piece k."""

    def __init__(self, make):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1, outputType="vtkUnstructuredGrid")
        self.make = make

    def RequestInformation(self, request, in_info, out_info):
        out_info.GetInformationObject(0).Set(vtk.vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)
        return 1

    def RequestData(self, request, in_info, out_info):
        k = out_info.GetInformationObject(0).Get(vtk.vtkStreamingDemandDrivenPipeline.UPDATE_PIECE_NUMBER())
        vtk.vtkUnstructuredGrid.GetData(out_info).ShallowCopy(self.make(k))
        return 1


def write_pvtu(path, make, pieces, appended_raw=False):
    """Writes `pieces` pieces, piece k being `make(k)`, as a .pvtu and its pieces' .vtu
    files beside it (VTK's default data mode, or appended raw data)."""
    source = Pieces(make)
    w = vtk.vtkXMLPUnstructuredGridWriter()
    w.SetInputConnection(source.GetOutputPort())
    w.SetFileName(str(path))
    w.SetNumberOfPieces(pieces)
    w.SetStartPiece(0)
    w.SetEndPiece(pieces - 1)
    if appended_raw:
        w.SetDataModeToAppended()
        w.EncodeAppendedDataOff()
    if w.Write() != 1:
        raise RuntimeError(f"VTK could not write {path}")
