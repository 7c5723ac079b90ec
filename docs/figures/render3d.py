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
import sys

from paraview.simple import (Calculator, CellDatatoPointData, ColorBy, CreateView,
                             ExtractSurface, GetColorTransferFunction, GetScalarBar, Glyph,
                             OpenDataFile, Render, SaveScreenshot, Show, Sphere, Threshold, Tube,
                             Clip)

run, png = sys.argv[1], sys.argv[2]
W, H = 1200, 900


def last_frame(name):
    src = OpenDataFile(f"{run}/{name}.pvd")
    ts = list(getattr(src, "TimestepValues", []) or [])
    t = ts[-1] if ts else 0.0
    src.UpdatePipeline(t)
    return src, t


view = CreateView("RenderView")
view.ViewSize = [W, H]
view.OrientationAxesVisibility = 0
view.Background = [1.0, 1.0, 1.0]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass

spheres, t = last_frame("spheres")
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


# Spheres: glyphs of the sphere source (radius 1) scaled by each radius.
ball = Sphere(Radius=1.0, ThetaResolution=24, PhiResolution=16)
glyphs = Glyph(Input=front_half(spheres), GlyphType=ball)
glyphs.ScaleArray = ["POINTS", "radius"]
glyphs.ScaleFactor = 1.0
glyphs.GlyphMode = "All Points"
gd = Show(glyphs, view)
gd.ColorArrayName = ["POINTS", ""]
gd.AmbientColor = gd.DiffuseColor = [0.80, 0.83, 0.87]
gd.Opacity = 0.35

contacts, _ = last_frame("contacts")
fmax = contacts.CellData["fn"].GetRange()[1]
loaded = Threshold(Input=front_half(contacts))
loaded.Scalars = ["CELLS", "fn"]
try:
    loaded.LowerThreshold = 1e-6 * fmax
    loaded.UpperThreshold = fmax
except AttributeError:
    loaded.ThresholdRange = [1e-6 * fmax, fmax]
points = CellDatatoPointData(Input=ExtractSurface(Input=loaded))
mN = Calculator(Input=points)
mN.ResultArrayName = "fn_mN"
mN.Function = "1000*fn"
tubes = Tube(Input=mN)
tubes.Scalars = ["POINTS", "fn_mN"]
tubes.Vectors = [None, ""]
tubes.VaryRadius = "By Scalar"
tubes.Radius = 1.5e-4
tubes.RadiusFactor = 12.0
tubes.NumberofSides = 10
td = Show(tubes, view)
ColorBy(td, ("POINTS", "fn_mN"))
lut = GetColorTransferFunction("fn_mN")
lut.ApplyPreset("Inferno (matplotlib)", True)
lut.InvertTransferFunction()
lut.RescaleTransferFunction(0.0, 1000 * fmax)
td.SetScalarBarVisibility(view, True)
bar = GetScalarBar(lut, view)
bar.Title = "contact normal force f_n (mN)"
bar.ComponentTitle = ""
bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
bar.TitleFontSize = 18
bar.LabelFontSize = 16
bar.RangeLabelFormat = "%-#.0f"
bar.WindowLocation = "Any Location"
bar.Orientation = "Horizontal"
bar.Position = [0.30, 0.02]
bar.ScalarBarLength = 0.40

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
