# The standard view of a bbm run in ParaView: blocks and zones coloured by the
# vertical stress (σyy, tension positive, Pa), broken contacts drawn on top
# coloured by mode (2 tensile, 3 shear), at the last time step, seen in 2D.
#
#   pvpython examples/paraview_view.py out/tunnel/tunnel_trigon   # opens the view
#   pvpython examples/paraview_view.py DIR --screenshot           # writes DIR/paraview.png
# or in the ParaView GUI: View > Python Shell > Run Script (reads out/tunnel/tunnel_trigon).
import os
import sys

from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, Interact, PVDReader, ResetCamera,
                             SaveScreenshot, Show, Threshold)

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
