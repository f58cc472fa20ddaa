# The standard view of a bbm run in ParaView: blocks and zones coloured by the
# vertical stress (σyy, tension positive, Pa), broken contacts drawn on top
# coloured by mode (2 tensile, 3 shear), at the last time step, seen in 2D. The
# colour range spans the 2nd to 98th percentile of the blocks' σyy (by area), so that
# a few loaded blocks (at a wall, along the far field's interface) do not take it all.
#
#   pvpython examples/paraview_view.py out/tunnel/tunnel_trigon   # opens the view
#   pvpython examples/paraview_view.py DIR --screenshot           # writes DIR/paraview.png
# or in the ParaView GUI: View > Python Shell > Run Script (reads out/tunnel/tunnel_trigon).
import os
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction, Interact,
                             PVDReader, ResetCamera, SaveScreenshot, Show, Threshold)
from vtkmodules.util.numpy_support import vtk_to_numpy


def robust_range(source, array, component, low=2.0, high=98.0):
    """The low-th and high-th percentiles of a cell array's component, weighted by
    cell area; None when the data hold no such array."""
    data = servermanager.Fetch(source)
    grids = [data.GetBlock(i) for i in range(data.GetNumberOfBlocks())] if data.IsA('vtkMultiBlockDataSet') else [data]
    values, weights = [], []
    for g in grids:
        if g is None or g.GetCellData().GetArray(array) is None:
            continue
        values.append(vtk_to_numpy(g.GetCellData().GetArray(array))[:, component])
        sizes = g.GetCellData().GetArray('area')
        weights.append(vtk_to_numpy(sizes) if sizes is not None else np.ones(g.GetNumberOfCells()))
    if not values:
        return None
    v, w = np.concatenate(values), np.concatenate(weights)
    order = np.argsort(v)
    cumulative = np.cumsum(w[order]) / w.sum()
    lo, hi = (v[order][np.searchsorted(cumulative, q / 100.0)] for q in (low, high))
    return (lo, hi) if hi > lo else None

args = [a for a in sys.argv[1:] if not a.startswith('--')]
out = args[0] if args else 'out/tunnel/tunnel_trigon'
blocks = PVDReader(registrationName='blocks', FileName=os.path.join(out, 'blocks.pvd'))
contacts = PVDReader(registrationName='contacts', FileName=os.path.join(out, 'contacts.pvd'))
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.GoToLast()

view = GetActiveViewOrCreate('RenderView')
shown = Show(blocks, view)
ColorBy(shown, ('CELLS', 'stress', 'YY'))
shown.RescaleTransferFunctionToDataRange(False, True)
span = robust_range(blocks, 'stress', 1)
if span:
    GetColorTransferFunction('stress').RescaleTransferFunction(*span)
    print('σyy colour range %.3g to %.3g Pa (2nd to 98th percentile by area)' % span)
shown.SetScalarBarVisibility(view, True)

cracks = Threshold(registrationName='cracks', Input=contacts, Scalars=['CELLS', 'state'])
if hasattr(cracks, 'LowerThreshold'):  # ParaView 5.10 and later
    cracks.LowerThreshold, cracks.UpperThreshold = 2, 3
else:
    cracks.ThresholdRange = [2, 3]
crack_display = Show(cracks, view)
ColorBy(crack_display, ('CELLS', 'state'))
crack_display.LineWidth = 3.0

view.InteractionMode = '2D'
ResetCamera(view)
if '--screenshot' in sys.argv:
    SaveScreenshot(os.path.join(out, 'paraview.png'), view, ImageResolution=[1600, 1600])
elif __name__ == '__main__' and 'pvpython' in os.path.basename(sys.executable):
    Interact(view)
