
# ---- the view (cd/src/core/paraview/view_main.py; the function above is
# docs/figures/chains.py, the README picture's force chains) ----------------
# ParaView view of this cdsim run: the grains of its last snapshot (3D
# polyhedra: their faces) and its force chains (every contact with f_n > 0
# as a tube from centre to centre, through the contact point between
# polyhedra, radius and colour by f_n), styled as the README's picture.
# cdsim writes this file into the run folder with the first snapshot.
#   paraview --script=view.py          the GUI, with the view set up
#   pvbatch view.py picture.png         headless (needs an X server or
#                                       xvfb-run): writes the picture
import os
import sys

from paraview.simple import GetActiveViewOrCreate, Render, SaveScreenshot, Show

try:
    RUN = os.path.dirname(os.path.abspath(__file__))
except NameError:  # a console that does not set __file__: run it from the folder
    RUN = os.getcwd()


view = GetActiveViewOrCreate("RenderView")
white_view(view)
if os.path.exists(os.path.join(RUN, "shapes.pvd")):  # 2D: true outlines and walls
    grains, t = last_frame(RUN, "shapes")
    show_outlines(view, grains, last_frame(RUN, "walls")[0])
    view.InteractionMode = "2D"
    rmax = last_frame(RUN, "particles")[0].PointData["radius"].GetRange()[1]
elif os.path.exists(os.path.join(RUN, "polyhedra.pvd")):  # 3D polyhedra: their faces, see-through
    grains, t = last_frame(RUN, "polyhedra")
    faces = Show(grains, view)
    faces.SetRepresentationType("Surface With Edges")
    faces.ColorArrayName = ["CELLS", ""]
    faces.AmbientColor = faces.DiffuseColor = [0.80, 0.83, 0.87]
    faces.EdgeColor = [0.55, 0.57, 0.60]
    faces.Opacity = 0.35
    rmax = grains.CellData["radius"].GetRange()[1]  # circumradii
else:  # 3D: spheres of their radius, see-through so that the chains show
    grains, t = last_frame(RUN, "spheres")
    show_spheres(view, grains)
    rmax = grains.PointData["radius"].GetRange()[1]
view.ViewTime = t

# The tubes: from 1/30 of the largest grain's radius for the weakest contact
# to 15 times that for the strongest.
contacts, _ = last_frame(RUN, "contacts")
fmax = contacts.CellData["fn"].GetRange()[1]
if fmax > 0:
    show_chains(view, contacts, radius=rmax / 30, radius_factor=15.0, fmax=fmax)
view.ResetCamera()
Render(view)
if len(sys.argv) > 1 and sys.argv[1].endswith(".png"):
    SaveScreenshot(sys.argv[1], view, ImageResolution=[1200, 900])
    print(f"{sys.argv[1]}: t = {t:g} s, f_n max {fmax:.3g} N")
