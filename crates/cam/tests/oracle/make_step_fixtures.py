#!/usr/bin/env python3
"""Generate the STEP fixtures of crates/cam/tests/step_occ.rs and their reference points.

OpenCascade (the `cadquery-ocp-novtk` wheel from PyPI) builds three surfaces, writes each as a
STEP AP214 file, reads the file back with its own STEPControl_Reader and evaluates every face of
the re-read shape at a grid of (u, v): point and first partial derivatives, in mm. The reader
works on the surface *as written in the file*, so the reference is at the file's parameters even
where the writer re-knotted or re-parametrised a surface.

Run once, commit the output (ordinary tests need no Python):

    python3 -m venv /tmp/ocpvenv && /tmp/ocpvenv/bin/pip install cadquery-ocp-novtk
    /tmp/ocpvenv/bin/python crates/cam/tests/oracle/make_step_fixtures.py crates/cam/tests/fixtures

Fixtures:
  freeform_patch.stp   bicubic 8x9 B-spline patch, ~100 x 100 mm, non-uniform knots (a face:
                       SHELL_BASED_SURFACE_MODEL / OPEN_SHELL / ADVANCED_FACE)
  freeform_patch_inch.stp  the same patch written in inches (CONVERSION_BASED_UNIT)
  rational_sphere.stp  a sphere of radius 40 converted to NURBS (rational, poles degenerate;
                       MANIFOLD_SOLID_BREP / CLOSED_SHELL)
  twisted_blade.stp    a solid lofted through 5 elliptic sections twisted by 15 degrees each,
                       converted to NURBS (rational B-spline sides, B-spline caps)
  freeform_patch_ap203.stp  the patch in AP203 (CONFIG_CONTROL_DESIGN)
  nurbs_cylinder.stp   a cylinder r = 20, h = 50 converted to NURBS: its side has a seam edge
                       (SEAM_CURVE with two pcurves on one surface)
  analytic_solids.stp  four solids on analytic surfaces as OCCT writes them (not converted): a
                       cylinder r 20 h 50, a cone r 20 -> 8 h 30 at x = 60, a sphere r 15 at
                       x = 120, a torus R 20 r 5 at x = 180 (CYLINDRICAL_, CONICAL_,
                       SPHERICAL_, TOROIDAL_SURFACE with their planes)
  analytic_solids_no_pcurves.stp  the same written without pcurves (write.surfacecurve.mode
                       0, as Parasolid-based writers do): extents from the 3-D loops
  filleted_block.stp   a 60 x 40 x 20 block, vertical edges filleted r 6, a through hole r 8,
                       without pcurves (quarter cylinders, a plane with a circular hole)
  swept_surfaces.stp   a B-spline S-curve extruded 30 mm (SURFACE_OF_LINEAR_EXTRUSION) and a
                       B-spline profile revolved 270 degrees about z (SURFACE_OF_REVOLUTION)
  trimmed_freeform.stp the free-form patch's surface trimmed in its parameters by an ellipse
                       (the outer loop) with a round hole: B-spline edges built from 2-D
                       conics on the surface (SURFACE_CURVE with pcurves)
  saddle_bump.stp, wavy_patch.stp, bowl_patch.stp  issue 23's free-form faces whose normals
                       pass through the vertical (bicubic fits of z = f(x, y), one face each)
  plate_with_holes.stp an 80 x 60 mm plane face with a circular and an elliptic hole (PLANE,
                       LINE, CIRCLE, ELLIPSE edges; three face bounds)
Each X.stp has X.json: {"faces": [{"u": [u0, u1], "v": [v0, v1], "reversed": bool, "area": mm²
(fixtures generated since the area was added), "samples":
[[u, v, x, y, z, dxdu, dydu, dzdu, dxdv, dydv, dzdv], ...]}, ...]} with faces in the order of the
re-read shape; (u, v) ranges are the face's UV bounds (BRepTools::UVBounds), "reversed" its
orientation in the shell.
"""
import json
import math
import os
import re
import sys

from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_NurbsConvert
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections
from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
from OCP.collections import Array1_double, Array1_int, Array2_gp_Pnt
from OCP.Geom import Geom_BSplineSurface, Geom_Ellipse
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt, gp_Vec
from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Reader, STEPControl_Writer
from OCP.BRepTools import BRepTools
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

# Samples per direction and face: 12 (144 per face) for files of up to three faces, 7 (49 per
# face, still a few hundred per file) for the larger ones, to keep the fixtures small.
SAMPLES_FEW_FACES = 12
SAMPLES_MANY_FACES = 7


def freeform_patch():
    """Bicubic 8 x 9 patch over [0, 100] x [0, 100] mm, a wavy z, non-uniform knots."""
    rows, cols = 8, 9
    poles = Array2_gp_Pnt(1, rows, 1, cols)
    for i in range(rows):
        for j in range(cols):
            x = 100.0 * i / (rows - 1)
            y = 100.0 * j / (cols - 1) + 3.0 * math.sin(0.7 * i)
            z = 8.0 * math.sin(0.9 * i + 0.3) * math.cos(0.6 * j) + 0.05 * x
            poles.SetValue(i + 1, j + 1, gp_Pnt(x, y, z))
    uk = [0.0, 0.13, 0.37, 0.52, 0.81, 1.0]  # 6 distinct, mults 4 1 1 1 1 4: 8 + 4 = 12 knots
    um = [4, 1, 1, 1, 1, 4]
    vk = [0.0, 0.08, 0.3, 0.45, 0.66, 0.7, 1.0]  # mults 4 1 1 1 1 1 4: 9 + 4 = 13 knots
    vm = [4, 1, 1, 1, 1, 1, 4]
    surf = Geom_BSplineSurface(poles, arr(uk), arr(vk), iarr(um), iarr(vm), 3, 3)
    return BRepBuilderAPI_MakeFace(surf, 1e-7).Face()


def trimmed_freeform():
    """The free-form patch inside the (u, v) ellipse centred (0.5, 0.5), semi-axes 0.42 along u
    and 0.34 along v, less the (u, v) disc of radius 0.1 about (0.62, 0.45)."""
    from OCP.BRepLib import BRepLib
    from OCP.Geom2d import Geom2d_Circle, Geom2d_Ellipse
    from OCP.gp import gp_Ax2d, gp_Dir2d, gp_Pnt2d
    surf = BRep_Tool.Surface_s(freeform_patch())

    def loop(curve, reverse):
        edge = BRepBuilderAPI_MakeEdge(curve, surf).Edge()
        BRepLib.BuildCurves3d_s(edge, 1e-7)
        wire = BRepBuilderAPI_MakeWire(edge).Wire()
        if reverse:
            wire.Reverse()
        return wire

    axis = gp_Ax2d(gp_Pnt2d(0.5, 0.5), gp_Dir2d(1.0, 0.0))
    make = BRepBuilderAPI_MakeFace(surf, loop(Geom2d_Ellipse(axis, 0.42, 0.34), False), True)
    make.Add(loop(Geom2d_Circle(gp_Ax2d(gp_Pnt2d(0.62, 0.45), gp_Dir2d(1.0, 0.0)), 0.1), True))
    from OCP.ShapeFix import ShapeFix_Face
    fix = ShapeFix_Face(make.Face())
    fix.Perform()
    return fix.Face()


def rational_sphere():
    return BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeSphere(40.0).Shape()).Shape()


def nurbs_cylinder():
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    return BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeCylinder(20.0, 50.0).Shape()).Shape()


def analytic_solids():
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeCone, BRepPrimAPI_MakeTorus
    from OCP.TopoDS import TopoDS_Compound
    from OCP.BRep import BRep_Builder
    b = BRep_Builder()
    c = TopoDS_Compound()
    b.MakeCompound(c)
    b.Add(c, BRepPrimAPI_MakeCylinder(20.0, 50.0).Shape())
    b.Add(c, BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(60, 0, 0), gp_Dir(0, 0, 1)), 20.0, 8.0, 30.0).Shape())
    b.Add(c, BRepPrimAPI_MakeSphere(gp_Pnt(120, 0, 0), 15.0).Shape())
    b.Add(c, BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(180, 0, 0), gp_Dir(0, 0, 1)), 20.0, 5.0).Shape())
    return c


def filleted_block():
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    box = BRepPrimAPI_MakeBox(60.0, 40.0, 20.0).Shape()
    fillet = BRepFilletAPI_MakeFillet(box)
    ex = TopExp_Explorer(box, TopAbs_EDGE)
    while ex.More():
        edge = TopoDS.Edge(ex.Current())
        c = BRepAdaptor_Curve(edge)
        d = c.Value(c.LastParameter()).XYZ() - c.Value(c.FirstParameter()).XYZ()
        if abs(d.X()) < 1e-9 and abs(d.Y()) < 1e-9:
            fillet.Add(6.0, edge)
        ex.Next()
    hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(30, 20, -1), gp_Dir(0, 0, 1)), 8.0, 22.0).Shape()
    return BRepAlgoAPI_Cut(fillet.Shape(), hole).Shape()


def swept_surfaces():
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism, BRepPrimAPI_MakeRevol
    from OCP.Geom import Geom_BSplineCurve
    from OCP.collections import Array1_gp_Pnt
    from OCP.gp import gp_Ax1
    from OCP.TopoDS import TopoDS_Compound
    from OCP.BRep import BRep_Builder

    def bspline(points):
        poles = Array1_gp_Pnt(1, len(points))
        for k, p in enumerate(points):
            poles.SetValue(k + 1, gp_Pnt(*p))
        n = len(points)
        knots = [0.0] + [k / (n - 3) for k in range(1, n - 3)] + [1.0]
        mults = [4] + [1] * (n - 4) + [4]
        return Geom_BSplineCurve(poles, arr(knots), iarr(mults), 3)

    s_curve = bspline([(0, 0, 0), (15, 10, 0), (30, -10, 0), (45, 12, 0), (60, 0, 0), (75, 5, 0)])
    prism = BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeEdge(s_curve).Edge(), gp_Vec(0, 0, 30)).Shape()
    profile = bspline([(10, 0, 0), (18, 0, 8), (12, 0, 16), (20, 0, 26), (14, 0, 34)])
    profile_edge = BRepBuilderAPI_MakeEdge(profile).Edge()
    revol = BRepPrimAPI_MakeRevol(profile_edge, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(270)).Shape()
    b = BRep_Builder()
    c = TopoDS_Compound()
    b.MakeCompound(c)
    b.Add(c, prism)
    b.Add(c, revol)
    return c


def twisted_blade():
    loft = BRepOffsetAPI_ThruSections(True, False, 1e-6)
    for k in range(5):
        z = 25.0 * k
        twist = math.radians(15.0 * k)
        axes = gp_Ax2(gp_Pnt(0.0, 0.0, z), gp_Dir(0, 0, 1), gp_Dir(math.cos(twist), math.sin(twist), 0))
        ellipse = Geom_Ellipse(axes, 30.0 - 2.0 * k, 6.0 + 0.5 * k)
        edge = BRepBuilderAPI_MakeEdge(ellipse).Edge()
        loft.AddWire(BRepBuilderAPI_MakeWire(edge).Wire())
    loft.Build()
    return BRepBuilderAPI_NurbsConvert(loft.Shape()).Shape()


def plate_with_holes():
    from OCP.gp import gp_Pln, gp_Circ, gp_Elips, gp_Ax3
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakePolygon
    plane = gp_Pln(gp_Ax3(gp_Pnt(0.0, 0.0, 5.0), gp_Dir(0, 0, 1), gp_Dir(1, 0, 0)))
    outer = BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 5), gp_Pnt(80, 0, 5), gp_Pnt(80, 60, 5), gp_Pnt(0, 60, 5), True).Wire()
    make = BRepBuilderAPI_MakeFace(plane, outer)
    circle = gp_Circ(gp_Ax2(gp_Pnt(25, 30, 5), gp_Dir(0, 0, 1)), 10.0)
    hole = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire()
    hole.Reverse()
    make.Add(hole)
    ellipse = gp_Elips(gp_Ax2(gp_Pnt(58, 30, 5), gp_Dir(0, 0, 1), gp_Dir(math.cos(0.5), math.sin(0.5), 0)), 12.0, 6.0)
    hole2 = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(ellipse).Edge()).Wire()
    hole2.Reverse()
    make.Add(hole2)
    return make.Face()


def grid_patch(f, x0, x1, y0, y1, n):
    """A bicubic B-spline approximating z = f(x, y) through an (n + 1)² grid over the box
    (OCCT's GeomAPI_PointsToBSplineSurface, within 1e-4 mm of the grid)."""
    from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface
    from OCP.GeomAbs import GeomAbs_C2
    poles = Array2_gp_Pnt(1, n + 1, 1, n + 1)
    for i in range(n + 1):
        for j in range(n + 1):
            x = x0 + (x1 - x0) * i / n
            y = y0 + (y1 - y0) * j / n
            poles.SetValue(i + 1, j + 1, gp_Pnt(x, y, f(x, y)))
    surf = GeomAPI_PointsToBSplineSurface(poles, 3, 3, GeomAbs_C2, 1e-4).Surface()
    return BRepBuilderAPI_MakeFace(surf, 1e-7).Face()


def saddle_bump():
    """Issue 23's saddle with a bump, 120 x 80 mm: z = (x^2 - y^2)/200 + a Gaussian hill 6 mm
    high off centre; the normal passes through the vertical at the saddle point and the top."""
    return grid_patch(lambda x, y: (x * x - y * y) / 200.0
                      + 6.0 * math.exp(-((x - 15.0) ** 2 + (y + 5.0) ** 2) / 200.0),
                      -60.0, 60.0, -40.0, 40.0, 24)


def wavy_patch():
    """Issue 23's wavy patch, 100 x 100 mm: z = 5 sin(2 pi x / 50) cos(2 pi y / 60); its
    normals sweep through the vertical at every crest, trough and saddle."""
    return grid_patch(lambda x, y: 5.0 * math.sin(2 * math.pi * x / 50.0)
                      * math.cos(2 * math.pi * y / 60.0), 0.0, 100.0, 0.0, 100.0, 32)


def bowl_patch():
    """Issue 23's bowl, 80 x 80 mm: the paraboloid z = (x^2 + y^2)/80 (vertical normal at
    its bottom, 45 degrees at the rim's middles)."""
    return grid_patch(lambda x, y: (x * x + y * y) / 80.0, -40.0, 40.0, -40.0, 40.0, 16)


def arr(values):
    a = Array1_double(1, len(values))
    for k, x in enumerate(values):
        a.SetValue(k + 1, x)
    return a


def iarr(values):
    a = Array1_int(1, len(values))
    for k, x in enumerate(values):
        a.SetValue(k + 1, x)
    return a


def write(shape, path, unit="MM", schema="AP214IS", pcurves=True):
    Interface_Static.SetCVal_s("write.step.schema", schema)
    Interface_Static.SetIVal_s("write.surfacecurve.mode", 1 if pcurves else 0)
    Interface_Static.SetCVal_s("write.step.unit", unit)
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    if w.Write(path) != IFSelect_RetDone:
        raise RuntimeError("cannot write " + path)
    # Drop the time stamp so that regenerating unchanged geometry gives the same bytes.
    with open(path) as f:
        text = f.read()
    text = re.sub(r"FILE_NAME\('[^']*','[^']*'",
                  "FILE_NAME('%s','2026-01-01T00:00:00'" % os.path.basename(path), text, count=1)
    text = re.sub(r"CALENDAR_DATE\(\d+,\d+,\d+\)", "CALENDAR_DATE(2026,1,1)", text)
    text = re.sub(r"LOCAL_TIME\(\d+,\d+,", "LOCAL_TIME(0,0,", text)
    with open(path, "w") as f:
        f.write(text)


def reference(path):
    r = STEPControl_Reader()
    if r.ReadFile(path) != IFSelect_RetDone:
        raise RuntimeError("cannot read " + path)
    r.TransferRoots()
    shape = r.OneShape()
    faces = []
    count = 0
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        count += 1
        ex.Next()
    n = SAMPLES_FEW_FACES if count <= 3 else SAMPLES_MANY_FACES
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        face = TopoDS.Face(ex.Current())
        surf = BRep_Tool.Surface_s(face)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        samples = []
        for a in range(n):
            for b in range(n):
                # Irregular spacing, ends included: knots and interiors both get hit.
                u = u0 + (u1 - u0) * (a / (n - 1)) ** 1.3
                v = v0 + (v1 - v0) * (b / (n - 1)) ** 0.8
                p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
                surf.D1(u, v, p, du, dv)
                samples.append([u, v, p.X(), p.Y(), p.Z(), du.X(), du.Y(), du.Z(), dv.X(), dv.Y(), dv.Z()])
        reversed_ = face.Orientation() == TopAbs_REVERSED
        # The face's area within its bounds (OCCT's Gauss integration over the trimmed face).
        from OCP.BRepGProp import BRepGProp
        from OCP.GProp import GProp_GProps
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(face, props)
        faces.append({"u": [u0, u1], "v": [v0, v1], "reversed": reversed_, "area": props.Mass(),
                      "samples": samples})
        ex.Next()
    return {"generator": "make_step_fixtures.py, OCCT via cadquery-ocp-novtk", "faces": faces}


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "fixtures")
    os.makedirs(out, exist_ok=True)
    cases = [
        ("freeform_patch", freeform_patch(), "MM"),
        ("freeform_patch_inch", freeform_patch(), "INCH"),
        ("rational_sphere", rational_sphere(), "MM"),
        ("twisted_blade", twisted_blade(), "MM"),
        ("freeform_patch_ap203", freeform_patch(), "MM"),
        ("plate_with_holes", plate_with_holes(), "MM"),
        ("nurbs_cylinder", nurbs_cylinder(), "MM"),
        ("analytic_solids", analytic_solids(), "MM"),
        ("analytic_solids_no_pcurves", analytic_solids(), "MM"),
        ("filleted_block", filleted_block(), "MM"),
        ("swept_surfaces", swept_surfaces(), "MM"),
        ("trimmed_freeform", trimmed_freeform(), "MM"),
        ("saddle_bump", saddle_bump(), "MM"),
        ("wavy_patch", wavy_patch(), "MM"),
        ("bowl_patch", bowl_patch(), "MM"),
    ]
    # Further arguments name the fixtures to (re)generate; none: all of them.
    only = set(sys.argv[2:])
    cases = [c for c in cases if not only or c[0] in only]
    for name, shape, unit in cases:
        stp = os.path.join(out, name + ".stp")
        write(shape, stp, unit, "AP203" if name.endswith("ap203") else "AP214IS",
              pcurves=not (name.endswith("no_pcurves") or name == "filleted_block"))
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(reference(stp), f, separators=(",", ":"))
            f.write("\n")
        print(name, os.path.getsize(stp), "bytes")


if __name__ == "__main__":
    main()
