# Renders the front picture of the README: the grains of a cdsim run and its
# force chains, every force-bearing contact drawn as a tube from centre to
# centre, coloured and sized by its normal force f_n.
#
#   pvbatch docs/figures/render.py RUN_DIR OUT.png
#
# RUN_DIR is a cdsim output folder (shapes.pvd, contacts.pvd, walls.pvd); the
# last snapshot is drawn. `make figures` runs the default scene and calls
# this under xvfb-run: Debian's ParaView 5.11 renders through GLX only (no
# EGL, no OSMesa), so it needs an X server, and its Python package
# (python3-paraview) conflicts with python3-vtk9, which libvtk9-dev needs, so
# the Makefile unpacks it beside the build instead of installing it.
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from chains import last_frame, show_chains, show_outlines, white_view  # noqa: E402
from paraview.simple import CreateView, Render, SaveScreenshot  # noqa: E402

run, png = sys.argv[1], sys.argv[2]
W, H = 1200, 840  # pixels; the default pile is 40 d wide and ~27 d high

view = CreateView("RenderView")
view.ViewSize = [W, H]
white_view(view)

shapes, t = last_frame(run, "shapes")
view.ViewTime = t
show_outlines(view, shapes, last_frame(run, "walls")[0])

# Force-bearing contacts only (f_n > 0), as tubes whose radius grows
# linearly with f_n: from 0.02 mm for the weakest to 0.3 mm (0.3 d_mean)
# for the strongest.
contacts, _ = last_frame(run, "contacts")
fmax = contacts.CellData["fn"].GetRange()[1]
show_chains(view, contacts, radius=2e-5, radius_factor=15.0, fmax=fmax, label_step=0.5)

# Frame the pile, not the whole box (the box is 70 d high for the initial
# lattice), with a band at the bottom for the colour bar.
x0, x1, y0, y1 = shapes.GetDataInformation().GetBounds()[:4]
aspect = W / H
half_h = 0.5 * max(y1 - y0, (x1 - x0) / aspect) * 1.04
bar_band = 0.12 * half_h
cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1) - bar_band
view.InteractionMode = "2D"
view.CameraParallelProjection = 1
Render(view)  # the first render resets the camera: place it afterwards
cam = view.GetActiveCamera()
cam.SetFocalPoint(cx, cy, 0.0)
cam.SetPosition(cx, cy, 1.0)
cam.SetViewUp(0.0, 1.0, 0.0)
cam.SetParallelScale(half_h + bar_band)
Render(view)
SaveScreenshot(png, view, ImageResolution=[W, H], CompressionLevel="9")
print(f"{png}: t = {t:g} s, contacts with f_n > 0 drawn, f_n max {fmax:.3g} N")
