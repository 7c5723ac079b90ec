
# ---- the view (cd/src/core/paraview/view_main.py; the function above is
# docs/figures/chains.py, the README picture's force chains) ----------------
# ParaView view of this cdsim run: the grains of its last snapshot and its
# force chains (every contact with f_n > 0 as a tube from centre to centre,
# radius and colour by f_n), styled as the README's picture. cdsim writes
# this file into the run folder with the first snapshot.
#   paraview --script=view.py          the GUI, with the view set up
#   pvbatch view.py picture.png         headless (needs an X server or
#                                       xvfb-run): writes the picture
import os
import sys

from paraview.simple import GetActiveViewOrCreate, Glyph, OpenDataFile, Render, SaveScreenshot, Sphere

try:
    RUN = os.path.dirname(os.path.abspath(__file__))
except NameError:  # a console that does not set __file__: run it from the folder
    RUN = os.getcwd()


def last_frame(name):
    src = OpenDataFile(os.path.join(RUN, name + ".pvd"))
    ts = list(getattr(src, "TimestepValues", []) or [])
    t = ts[-1] if ts else 0.0
    src.UpdatePipeline(t)
    return src, t


view = GetActiveViewOrCreate("RenderView")
view.OrientationAxesVisibility = 0
view.Background = [1.0, 1.0, 1.0]
try:  # ParaView >= 5.10 takes the background from the palette unless told
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
if os.path.exists(os.path.join(RUN, "shapes.pvd")):  # 2D: true outlines and walls
    grains, t = last_frame("shapes")
    gd = Show(grains, view)
    gd.ColorArrayName = ["POINTS", ""]
    gd.AmbientColor = gd.DiffuseColor = [0.86, 0.88, 0.90]
    gd.SetRepresentationType("Surface With Edges")
    gd.EdgeColor = [0.55, 0.57, 0.60]
    walls, _ = last_frame("walls")
    wd = Show(walls, view)
    wd.ColorArrayName = ["POINTS", ""]
    wd.AmbientColor = wd.DiffuseColor = [0.1, 0.1, 0.1]
    wd.LineWidth = 3.0
    view.InteractionMode = "2D"
else:  # 3D: spheres of their radius, see-through so that the chains show
    grains, t = last_frame("spheres")
    ball = Sphere(Radius=1.0, ThetaResolution=24, PhiResolution=16)
    glyphs = Glyph(Input=grains, GlyphType=ball)
    glyphs.ScaleArray = ["POINTS", "radius"]
    glyphs.ScaleFactor = 1.0
    glyphs.GlyphMode = "All Points"
    gd = Show(glyphs, view)
    gd.ColorArrayName = ["POINTS", ""]
    gd.AmbientColor = gd.DiffuseColor = [0.80, 0.83, 0.87]
    gd.Opacity = 0.35
view.ViewTime = t

# The tubes: from 1/30 of the largest grain's radius for the weakest contact
# to 15 times that for the strongest.
contacts, _ = last_frame("contacts")
fmax = contacts.CellData["fn"].GetRange()[1]
sizes = last_frame("particles" if os.path.exists(os.path.join(RUN, "particles.pvd")) else "spheres")[0]
rmax = sizes.PointData["radius"].GetRange()[1]
if fmax > 0:
    show_chains(view, contacts, radius=rmax / 30, radius_factor=15.0, fmax=fmax)
view.ResetCamera()
Render(view)
if len(sys.argv) > 1 and sys.argv[1].endswith(".png"):
    SaveScreenshot(sys.argv[1], view, ImageResolution=[1200, 900])
    print(f"{sys.argv[1]}: t = {t:g} s, f_n max {fmax:.3g} N")
