# The pipeline pieces shared by render.py (2D), render3d.py (3D) and every
# run's view.py (cd/src/core/paraview/view_main.py appended to this file):
# the last frame of a collection, a white view, the grains' styles, and
# the force chains: the force-bearing contacts of a contacts.pvd frame (f_n > 0) as tubes from
# centre to centre whose radius grows linearly with f_n, coloured by f_n in
# mN (light for weak contacts, dark for the chains), with a horizontal
# colour bar at the bottom of the view.
import os

from paraview.simple import (Calculator, CellDatatoPointData, ColorBy, ExtractSurface, Glyph,
                             GetColorTransferFunction, GetScalarBar, OpenDataFile, Show, Sphere,
                             Threshold, Tube)


def last_frame(run, name):
    """The collection run/name.pvd at its last time, and that time."""
    src = OpenDataFile(os.path.join(run, name + ".pvd"))
    ts = list(getattr(src, "TimestepValues", []) or [])
    t = ts[-1] if ts else 0.0
    src.UpdatePipeline(t)
    return src, t


def white_view(view):
    view.OrientationAxesVisibility = 0
    view.Background = [1.0, 1.0, 1.0]
    try:  # ParaView >= 5.10 takes the background from the palette unless told
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass


def show_outlines(view, shapes, walls):
    """2D grains with their true outlines (flat grey, a backdrop) and the walls."""
    gd = Show(shapes, view)
    gd.ColorArrayName = ["POINTS", ""]
    gd.AmbientColor = gd.DiffuseColor = [0.86, 0.88, 0.90]
    gd.Ambient, gd.Diffuse = 1.0, 0.0
    gd.SetRepresentationType("Surface With Edges")
    gd.EdgeColor = [0.55, 0.57, 0.60]
    wd = Show(walls, view)
    wd.ColorArrayName = ["POINTS", ""]
    wd.AmbientColor = wd.DiffuseColor = [0.1, 0.1, 0.1]
    wd.LineWidth = 3.0
    return gd


def show_spheres(view, spheres):
    """3D spheres: glyphs of a unit sphere scaled by each radius, see-through."""
    ball = Sphere(Radius=1.0, ThetaResolution=24, PhiResolution=16)
    glyphs = Glyph(Input=spheres, GlyphType=ball)
    glyphs.ScaleArray = ["POINTS", "radius"]
    glyphs.ScaleFactor = 1.0
    glyphs.GlyphMode = "All Points"
    gd = Show(glyphs, view)
    gd.ColorArrayName = ["POINTS", ""]
    gd.AmbientColor = gd.DiffuseColor = [0.80, 0.83, 0.87]
    gd.Opacity = 0.35
    return gd


def show_chains(view, contacts, radius, radius_factor, fmax, label_step=None):
    """contacts: a pipeline source of contact lines with cell array fn (N);
    radius: the weakest tube's radius (m); radius_factor: strongest/weakest."""
    loaded = Threshold(Input=contacts)
    loaded.Scalars = ["CELLS", "fn"]
    try:  # ParaView 5.10+: lower/upper thresholds
        loaded.LowerThreshold = 1e-6 * fmax
        loaded.UpperThreshold = fmax
    except AttributeError:
        loaded.ThresholdRange = [1e-6 * fmax, fmax]
    # Threshold gives an unstructured grid; Tube needs polydata. Each contact
    # line has its own two points, so point data is the line's f_n exactly.
    points = CellDatatoPointData(Input=ExtractSurface(Input=loaded))
    mN = Calculator(Input=points)  # labels in mN read better than 1e-3 N
    mN.ResultArrayName = "fn_mN"
    mN.Function = "1000*fn"
    tubes = Tube(Input=mN)
    tubes.Scalars = ["POINTS", "fn_mN"]
    tubes.Vectors = [None, ""]
    tubes.VaryRadius = "By Scalar"
    tubes.Radius = radius
    tubes.RadiusFactor = radius_factor
    tubes.NumberofSides = 12
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
    bar.RangeLabelFormat = "%-#.2f" if label_step else "%-#.0f"
    if label_step:
        bar.UseCustomLabels = 1
        bar.CustomLabels = [label_step * k for k in range(1, int(1000 * fmax / label_step) + 1)]
        bar.LabelFormat = "%-#.1f"
    bar.WindowLocation = "Any Location"
    bar.Orientation = "Horizontal"
    bar.Position = [0.30, 0.02]
    bar.ScalarBarLength = 0.40
    return td
