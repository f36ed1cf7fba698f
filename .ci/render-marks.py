"""Draws the .vtu files `halo4d check --mark` writes side by side, as a ParaView user would
threshold them: the tetrahedra with a fault (`fault` 1 to 2047; 2048 alone marks a cavity)
in red with their edges, the rest of the mesh as its translucent grey boundary, each panel
titled. VTK renders offscreen; without a display, run it under xvfb-run.
Usage: render-marks.py OUT.png TITLE=MARKED.vtu [TITLE=MARKED.vtu ...]
The README's docs/check-marks.png:
  for f in nested-balls cube-overlapping cube-hanging-vertex; do
    halo4d check fixtures/tetmeshes/faults/$f.vtk --mark /tmp/$f.vtu; done
  xvfb-run -a python .ci/render-marks.py docs/check-marks.png \\
    "nested balls=/tmp/nested-balls.vtu" "overlapping=/tmp/cube-overlapping.vtu" \\
    "hanging vertex=/tmp/cube-hanging-vertex.vtu\""""
import sys

import vtk



def actor(mapper, source, colour, opacity=1.0, edges=False):
    """An actor drawing `source`'s output through `mapper` in one colour."""
    mapper.SetInputConnection(source.GetOutputPort())
    mapper.ScalarVisibilityOff()
    a = vtk.vtkActor()
    a.SetMapper(mapper)
    a.GetProperty().SetColor(*colour)
    a.GetProperty().SetOpacity(opacity)
    if edges:
        a.GetProperty().EdgeVisibilityOn()
    return a


out, panels = sys.argv[1], [a.split("=", 1) for a in sys.argv[2:]]
side = 400
rw = vtk.vtkRenderWindow()
rw.SetOffScreenRendering(1)
rw.SetSize(side * len(panels), side)
for k, (title, path) in enumerate(panels):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    ren = vtk.vtkRenderer()
    ren.SetBackground(1, 1, 1)
    ren.SetViewport(k / len(panels), 0, (k + 1) / len(panels), 1)
    rw.AddRenderer(ren)
    shell = vtk.vtkDataSetSurfaceFilter()
    shell.SetInputData(grid)
    ren.AddActor(actor(vtk.vtkPolyDataMapper(), shell, (0.72, 0.72, 0.76), opacity=0.22))
    faulty = vtk.vtkThreshold()
    faulty.SetInputData(grid)
    faulty.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_CELLS, "fault")
    faulty.SetLowerThreshold(1)
    faulty.SetUpperThreshold(2047)
    faulty.SetThresholdFunction(vtk.vtkThreshold.THRESHOLD_BETWEEN)
    faulty.Update()
    count = faulty.GetOutput().GetNumberOfCells()
    if count == 0:
        sys.exit(f"{path}: no tetrahedron is marked")
    ren.AddActor(actor(vtk.vtkDataSetMapper(), faulty, (0.85, 0.1, 0.1), edges=True))
    text = vtk.vtkTextActor()
    text.SetInput(f"{title}: {count} marked")
    text.GetTextProperty().SetColor(0.1, 0.1, 0.1)
    text.GetTextProperty().SetFontSize(18)
    text.SetPosition(10, side - 30)
    ren.AddViewProp(text)
    ren.ResetCamera()
    ren.GetActiveCamera().Azimuth(35)
    ren.GetActiveCamera().Elevation(25)
    ren.ResetCamera()
    print(f"{path}: {count} tetrahedra marked")
rw.Render()
grab = vtk.vtkWindowToImageFilter()
grab.SetInput(rw)
grab.Update()
writer = vtk.vtkPNGWriter()
writer.SetFileName(out)
writer.SetInputConnection(grab.GetOutputPort())
writer.Write()
