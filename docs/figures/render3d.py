# Renders the README's 3D picture: the spheres of a cdsim `dimension = 3`
# run (configs/pile3d.toml) at rest, cut in half along the box's mid-plane
# so that the inside shows, with the force chains of the cut half: every
# force-bearing contact a tube from centre to centre (or to the wall),
# coloured and sized by its normal force f_n.
#
#   pvbatch docs/figures/render3d.py RUN_DIR OUT.png
#
# RUN_DIR holds spheres.pvd and contacts.pvd (cdsim's 3D snapshots); the
# last snapshot is drawn. `make figures` calls this under xvfb-run (see
# render.py for why ParaView is run that way).
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from chains import last_frame, show_chains, show_spheres, white_view  # noqa: E402
from paraview.simple import Clip, CreateView, Render, SaveScreenshot  # noqa: E402

run, png = sys.argv[1], sys.argv[2]
W, H = 1200, 900

view = CreateView("RenderView")
view.ViewSize = [W, H]
white_view(view)

spheres, t = last_frame(run, "spheres")
view.ViewTime = t
x0, x1, y0, y1, z0, z1 = spheres.GetDataInformation().GetBounds()
ym = 0.5 * (y0 + y1)


def front_half(src):
    """The part of src behind the plane y = ym (the camera looks along +y)."""
    c = Clip(Input=src)
    c.ClipType = "Plane"
    c.ClipType.Origin = [0.0, ym, 0.0]
    c.ClipType.Normal = [0.0, -1.0, 0.0]
    c.Invert = 1
    try:
        c.Crinkleclip = 1  # whole cells: spheres and contact lines are not cut
    except AttributeError:
        pass
    return c


show_spheres(view, front_half(spheres))

contacts, _ = last_frame(run, "contacts")
fmax = contacts.CellData["fn"].GetRange()[1]
show_chains(view, front_half(contacts), radius=1.5e-4, radius_factor=12.0, fmax=fmax)

# An oblique view from the cut side, slightly above the pile.
Render(view)
cam = view.GetActiveCamera()
cx, cz = 0.5 * (x0 + x1), 0.5 * (z0 + z1)
span = max(x1 - x0, z1 - z0)
cam.SetFocalPoint(cx, ym, cz)
cam.SetPosition(cx - 0.9 * span, ym - 2.6 * span, cz + 1.3 * span)
cam.SetViewUp(0.0, 0.0, 1.0)
view.ResetCamera(False)
cam.Zoom(1.15)
Render(view)
SaveScreenshot(png, view, ImageResolution=[W, H], CompressionLevel="9")
print(f"{png}: t = {t:g} s, front half of the pile, contacts with f_n > 0 drawn, f_n max {fmax:.3g} N")
