//! Test fixtures: analytic surfaces as NURBS and ball-cutter zig-zag paths on them, built
//! directly (the strategies are another module's work).

#![allow(dead_code)]

use tezgah_cam::{Cutter, CutterLocation, CutterShape, Pass, ToolPath};
use tezgah_geom::{NurbsSurface, Vec3};

/// The plane z = 0 over [0, w] × [0, h] (u along x, v along y).
pub fn plane(w: f64, h: f64) -> NurbsSurface {
    let pts = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, h, 0.0),
        Vec3::new(w, 0.0, 0.0),
        Vec3::new(w, h, 0.0),
    ];
    NurbsSurface::bspline(
        1,
        1,
        &pts,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
    )
    .unwrap()
}

/// A convex cylinder of radius `rho` about the Y axis, the arc from −`half` to +`half` rad
/// (measured from +Z toward +X) in u — one rational quadratic arc — and y ∈ [0, len] in v.
pub fn cylinder(rho: f64, half: f64, len: f64) -> NurbsSurface {
    let w1 = half.cos();
    let apex = rho / half.cos();
    let arc = [
        Vec3::new(-rho * half.sin(), 0.0, rho * half.cos()),
        Vec3::new(0.0, 0.0, apex),
        Vec3::new(rho * half.sin(), 0.0, rho * half.cos()),
    ];
    let mut pts = Vec::new();
    let mut ws = Vec::new();
    for (k, p) in arc.iter().enumerate() {
        for y in [0.0, len] {
            pts.push(Vec3::new(p.x, y, p.z));
            ws.push(if k == 1 { w1 } else { 1.0 });
        }
    }
    NurbsSurface::new(
        2,
        1,
        &pts,
        &ws,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
    )
    .unwrap()
}

/// A ball cutter of radius `r` touching `surface` at (u, v) with its axis tilted from the
/// normal by `lead` rad toward the increasing-v direction.
pub fn ball_at(surface: &NurbsSurface, r: f64, u: f64, v: f64, lead: f64) -> CutterLocation {
    let d = surface.derivs(u, v);
    let n = d.su.cross(&d.sv).normalize();
    let f = (d.sv - n * n.dot(&d.sv)).normalize();
    let axis = (n * lead.cos() + f * lead.sin()).normalize();
    let contact = d.point;
    let centre = contact + n * r;
    CutterLocation {
        tip: centre - axis * r,
        axis,
        contact,
        normal: n,
        uv: (u, v),
    }
}

/// Zig-zag passes along v at `passes` evenly spaced u values over [0, 1], `steps` segments
/// per pass.
pub fn zigzag(surface: &NurbsSurface, r: f64, passes: usize, steps: usize, lead: f64) -> ToolPath {
    zigzag_along(surface, r, passes, steps, lead, false)
}

/// As [`zigzag`], the passes along u (at evenly spaced v) when `along_u`.
pub fn zigzag_along(
    surface: &NurbsSurface,
    r: f64,
    passes: usize,
    steps: usize,
    lead: f64,
    along_u: bool,
) -> ToolPath {
    let mut out = Vec::new();
    for i in 0..passes {
        let a = i as f64 / (passes - 1) as f64;
        let mut points: Vec<CutterLocation> = (0..=steps)
            .map(|j| {
                let b = j as f64 / steps as f64;
                if along_u {
                    ball_at(surface, r, b, a, lead)
                } else {
                    ball_at(surface, r, a, b, lead)
                }
            })
            .collect();
        if i % 2 == 1 {
            points.reverse();
        }
        out.push(Pass { points });
    }
    ToolPath {
        cutter: Cutter::standard(CutterShape::Ball { radius: r }),
        passes: out,
    }
}
