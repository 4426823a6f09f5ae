"""Drop-cutter oracle for crates/cam/tests/ocl_oracle.rs: OpenCAMLib's BatchDropCutter.

usage: ocl_drop.py TRIANGLES.f64 CUTTER DIAMETER XY.f64 OUT.f64
  TRIANGLES.f64  little-endian doubles, 9 per triangle (three vertices x, y, z)
  CUTTER         ball | flat | bull:CORNER_RADIUS
  XY.f64         little-endian doubles, 2 per query point
  OUT.f64        written: little-endian doubles, the tool-tip z of each query point
"""
import sys
from array import array

import opencamlib as ocl


def read(path):
    a = array("d")
    with open(path, "rb") as f:
        a.frombytes(f.read())
    if sys.byteorder != "little":
        a.byteswap()
    return a


def main():
    tri_path, kind, diameter, xy_path, out_path = sys.argv[1:6]
    diameter = float(diameter)
    t = read(tri_path)
    surf = ocl.STLSurf()
    for k in range(0, len(t), 9):
        surf.addTriangle(
            ocl.Triangle(
                ocl.Point(t[k], t[k + 1], t[k + 2]),
                ocl.Point(t[k + 3], t[k + 4], t[k + 5]),
                ocl.Point(t[k + 6], t[k + 7], t[k + 8]),
            )
        )
    length = 10.0 * diameter
    if kind == "ball":
        cutter = ocl.BallCutter(diameter, length)
    elif kind == "flat":
        cutter = ocl.CylCutter(diameter, length)
    elif kind.startswith("bull:"):
        cutter = ocl.BullCutter(diameter, float(kind[5:]), length)
    else:
        raise SystemExit("unknown cutter " + kind)
    drop = ocl.BatchDropCutter()
    drop.setSTL(surf)
    drop.setCutter(cutter)
    xy = read(xy_path)
    low = min(t[2::3]) - 10.0 * diameter
    for k in range(0, len(xy), 2):
        drop.appendPoint(ocl.CLPoint(xy[k], xy[k + 1], low))
    drop.run()
    out = array("d", [p.z for p in drop.getCLPoints()])
    if sys.byteorder != "little":
        out.byteswap()
    with open(out_path, "wb") as f:
        f.write(out.tobytes())


if __name__ == "__main__":
    main()
