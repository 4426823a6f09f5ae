//! Geometry entities (ISO 10303-42) to `tezgah-geom` types: `CARTESIAN_POINT`; B-spline
//! surfaces (with knots or an implied-knot form, plain or the rational complex instance) →
//! [`NurbsSurface`]; B-spline curves the same way and `SURFACE_CURVE`/`SEAM_CURVE` wrappers →
//! [`Nurbs`] edge curves. Coordinates are scaled to mm here; knots are parameters and kept.

use tezgah_geom::basis::MAX_DEGREE;
use tezgah_geom::{Nurbs, NurbsSurface, Vec3};

use super::entity::{real_of, Entity, Resolve};
use super::error::StepError;
use super::exchange::{Exchange, Instance, Param};

/// What geometry is read against: the exchange, the length unit's mm and the plane angle
/// unit's radians.
pub(crate) struct Geometry<'a> {
    pub ex: &'a Exchange,
    pub mm: f64,
    pub angle: f64,
}

impl<'a> Geometry<'a> {
    /// A `CARTESIAN_POINT` (3-D) in mm.
    pub fn point(&self, id: u64, from: &Entity<'_>) -> Result<Vec3, StepError> {
        let e = self.ex.get(id, from)?;
        if e.name() != "CARTESIAN_POINT" || e.instance.complex {
            return Err(StepError::Unsupported {
                at: e.at(),
                role: format!("a point of {}", from.at()),
            });
        }
        let c = e.reals(1, "coordinates")?;
        if c.len() != 3 {
            return Err(e.invalid(format!("has {} coordinates, a 3-D point needs 3", c.len())));
        }
        Ok(Vec3::new(c[0], c[1], c[2]) * self.mm)
    }

    /// A `VERTEX_POINT`'s point.
    pub fn vertex(&self, id: u64, from: &Entity<'_>) -> Result<Vec3, StepError> {
        let v = self.ex.get(id, from)?;
        if v.name() != "VERTEX_POINT" {
            return Err(StepError::Unsupported {
                at: v.at(),
                role: format!("a vertex of {}", from.at()),
            });
        }
        self.point(v.reference(1, "vertex geometry")?, &v)
    }

    /// A B-spline surface, plain (`B_SPLINE_SURFACE_WITH_KNOTS`) or the complex instance
    /// `(BOUNDED_SURFACE() B_SPLINE_SURFACE(…) B_SPLINE_SURFACE_WITH_KNOTS(…)
    /// GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE(…) REPRESENTATION_ITEM('')
    /// SURFACE())`, in which the supertype's attributes sit in their own partial record.
    pub fn bspline_surface(&self, s: &Entity<'_>) -> Result<NurbsSurface, StepError> {
        // (the record holding degrees and points, index of u_degree in it)
        let (base, first) = if s.instance.complex {
            (s.part("B_SPLINE_SURFACE")?, 0)
        } else {
            (*s, 1)
        };
        let p = base.count(first, "u_degree")?;
        let q = base.count(first + 1, "v_degree")?;
        let rows = base.list(first + 2, "control_points_list")?;
        let mut grid: Vec<Vec<u64>> = Vec::with_capacity(rows.len());
        for row in rows {
            match row {
                Param::List(items) => grid.push(
                    items
                        .iter()
                        .map(|p| match p {
                            Param::Ref(id) => Ok(*id),
                            _ => Err(base.invalid("control_points_list must hold references")),
                        })
                        .collect::<Result<_, _>>()?,
                ),
                _ => return Err(base.invalid("control_points_list must be a list of rows")),
            }
        }
        let n_rows = grid.len();
        let n_cols = grid.first().map_or(0, Vec::len);
        if let Some(bad) = grid.iter().position(|r| r.len() != n_cols) {
            return Err(base.invalid(format!(
                "control point row {} has {} points, row 1 has {n_cols}",
                bad + 1,
                grid[bad].len()
            )));
        }
        let (ku, kv) = if s.instance.has("B_SPLINE_SURFACE_WITH_KNOTS") {
            let knots = if s.instance.complex {
                s.part("B_SPLINE_SURFACE_WITH_KNOTS")?
            } else {
                *s
            };
            let k0 = if s.instance.complex { 0 } else { first + 7 };
            (
                expand_knots(&knots, k0, k0 + 2, "u", n_rows, p)?,
                expand_knots(&knots, k0 + 1, k0 + 3, "v", n_cols, q)?,
            )
        } else {
            let form = implied_form(s, &BSPLINE_SURFACES)?;
            (
                implied_knots(s, form, "u", n_rows, p)?,
                implied_knots(s, form, "v", n_cols, q)?,
            )
        };
        let weights = if s.instance.has("RATIONAL_B_SPLINE_SURFACE") {
            let r = s.part("RATIONAL_B_SPLINE_SURFACE")?;
            let w = r.list(0, "weights_data")?;
            let mut flat = Vec::with_capacity(n_rows * n_cols);
            for row in w {
                let Param::List(items) = row else {
                    return Err(r.invalid("weights_data must be a list of rows"));
                };
                if items.len() != n_cols {
                    return Err(r.invalid(format!(
                        "a weights row has {} values, the control grid has {n_cols} columns",
                        items.len()
                    )));
                }
                for x in items {
                    flat.push(real_of(x).ok_or_else(|| r.invalid("weights must be numbers"))?);
                }
            }
            if flat.len() != n_rows * n_cols {
                return Err(r.invalid(format!(
                    "weights_data has {} rows, the control grid has {n_rows}",
                    w.len()
                )));
            }
            flat
        } else {
            vec![1.0; n_rows * n_cols]
        };
        let mut points = Vec::with_capacity(n_rows * n_cols);
        for id in grid.iter().flatten() {
            points.push(self.point(*id, &base)?);
        }
        NurbsSurface::new(p, q, &points, &weights, ku, kv).map_err(|e| s.invalid(e.to_string()))
    }

    /// The 3-D curve behind `SURFACE_CURVE`/`SEAM_CURVE`/`INTERSECTION_CURVE` wrappers (the
    /// curve itself otherwise).
    pub fn basis_curve(&self, mut c: Entity<'a>) -> Result<Entity<'a>, StepError> {
        for _ in 0..4 {
            if !matches!(
                c.name(),
                "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE"
            ) {
                break;
            }
            c = self.ex.get(c.reference(1, "curve_3d")?, &c)?;
        }
        Ok(c)
    }

    /// A 3-D edge curve: a B-spline (plain or rational), or the 3-D curve of a
    /// `SURFACE_CURVE`/`SEAM_CURVE`. `LINE`s are handled by the caller (an edge on a line is
    /// the segment between its vertices). `depth` bounds surface-curve chains.
    pub fn curve(&self, c: &Entity<'_>, depth: usize) -> Result<Nurbs, StepError> {
        if is_bspline(c.instance, &BSPLINE_CURVES) {
            return self.bspline_curve(c);
        }
        match c.name() {
            "SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE" if depth < 4 => {
                let inner = self.ex.get(c.reference(1, "curve_3d")?, c)?;
                self.curve(&inner, depth + 1)
            }
            _ => Err(StepError::Unsupported {
                at: c.at(),
                role: "an edge curve".to_string(),
            }),
        }
    }

    fn bspline_curve(&self, c: &Entity<'_>) -> Result<Nurbs, StepError> {
        self.bspline_curve_with(c, |id, from| self.point(id, from))
    }

    /// A B-spline curve whose control points `point(id, referrer)` reads (3-D points in mm,
    /// or a pcurve's 2-D parameters).
    pub fn bspline_curve_with(
        &self,
        c: &Entity<'_>,
        point: impl Fn(u64, &Entity<'_>) -> Result<Vec3, StepError>,
    ) -> Result<Nurbs, StepError> {
        let (base, first) = if c.instance.complex {
            (c.part("B_SPLINE_CURVE")?, 0)
        } else {
            (*c, 1)
        };
        let p = base.count(first, "degree")?;
        let ids = base.refs(first + 1, "control_points_list")?;
        let kv = if c.instance.has("B_SPLINE_CURVE_WITH_KNOTS") {
            let knots = if c.instance.complex {
                c.part("B_SPLINE_CURVE_WITH_KNOTS")?
            } else {
                *c
            };
            let k0 = if c.instance.complex { 0 } else { first + 5 };
            expand_knots(&knots, k0, k0 + 1, "", ids.len(), p)?
        } else {
            let form = implied_form(c, &BSPLINE_CURVES)?;
            implied_knots(c, form, "", ids.len(), p)?
        };
        let weights = if c.instance.has("RATIONAL_B_SPLINE_CURVE") {
            let r = c.part("RATIONAL_B_SPLINE_CURVE")?;
            let w = r.reals(0, "weights_data")?;
            if w.len() != ids.len() {
                return Err(r.invalid(format!(
                    "{} weights for {} control points",
                    w.len(),
                    ids.len()
                )));
            }
            w
        } else {
            vec![1.0; ids.len()]
        };
        let points = ids
            .iter()
            .map(|id| point(*id, &base))
            .collect::<Result<Vec<_>, _>>()?;
        Nurbs::new(p, &points, &weights, kv).map_err(|e| c.invalid(e.to_string()))
    }
}

/// B-spline surface forms: explicit knots, or knots implied by the subtype (ISO 10303-42
/// `uniform_surface`, `quasi_uniform_surface`, `bezier_surface`).
pub(crate) const BSPLINE_SURFACES: [&str; 4] = [
    "B_SPLINE_SURFACE_WITH_KNOTS",
    "UNIFORM_SURFACE",
    "QUASI_UNIFORM_SURFACE",
    "BEZIER_SURFACE",
];
/// The same for curves.
pub(crate) const BSPLINE_CURVES: [&str; 4] = [
    "B_SPLINE_CURVE_WITH_KNOTS",
    "UNIFORM_CURVE",
    "QUASI_UNIFORM_CURVE",
    "BEZIER_CURVE",
];

/// Whether the instance is one of the B-spline `forms` (as itself or a partial record).
pub(crate) fn is_bspline(instance: &Instance, forms: &[&str; 4]) -> bool {
    forms.iter().any(|f| instance.has(f))
}

#[derive(Clone, Copy)]
enum Implied {
    Uniform,
    QuasiUniform,
    Bezier,
}

fn implied_form(e: &Entity<'_>, forms: &[&str; 4]) -> Result<Implied, StepError> {
    let has = |name: &str| e.instance.has(name);
    Ok(if has(forms[1]) {
        Implied::Uniform
    } else if has(forms[2]) {
        Implied::QuasiUniform
    } else if has(forms[3]) {
        Implied::Bezier
    } else {
        return Err(e.invalid("a B-spline needs knots or a uniform, quasi-uniform or Bézier form"));
    })
}

/// The knots ISO 10303-42 implies for `points` control points of `degree`: uniform
/// `−degree, …, points`; quasi-uniform `0` and `points − degree` repeated `degree + 1` times
/// around `1, 2, …`; Bézier `0, 1, …, k` (k = (points − 1)/degree pieces), the ends repeated
/// `degree + 1` times and the inner ones `degree` times.
fn implied_knots(
    e: &Entity<'_>,
    form: Implied,
    dir: &str,
    points: usize,
    degree: usize,
) -> Result<Vec<f64>, StepError> {
    let d = if dir.is_empty() {
        String::new()
    } else {
        format!("{dir} ")
    };
    if degree == 0 || degree > MAX_DEGREE {
        return Err(e.invalid(format!(
            "{d}degree is {degree}; tezgah reads degrees 1 to {MAX_DEGREE}"
        )));
    }
    if points < degree + 1 {
        return Err(e.invalid(format!(
            "{d}direction has {points} control points, degree {degree} needs {}",
            degree + 1
        )));
    }
    let (n, p) = (points, degree);
    Ok(match form {
        Implied::Uniform => (0..n + p + 1).map(|i| i as f64 - p as f64).collect(),
        Implied::QuasiUniform => {
            let last = (n - p) as f64;
            let mut k = vec![0.0; p + 1];
            k.extend((1..n - p).map(|i| i as f64));
            k.extend(std::iter::repeat_n(last, p + 1));
            k
        }
        Implied::Bezier => {
            if (n - 1) % p != 0 {
                return Err(e.invalid(format!(
                    "a Bézier {d}direction of degree {p} needs degree·k + 1 control points, not {n}"
                )));
            }
            let pieces = (n - 1) / p;
            let mut k = vec![0.0; p + 1];
            for i in 1..pieces {
                k.extend(std::iter::repeat_n(i as f64, p));
            }
            k.extend(std::iter::repeat_n(pieces as f64, p + 1));
            k
        }
    })
}

/// The full knot vector from distinct knots and their multiplicities (ISO 10303-42
/// `b_spline_*_with_knots`): each knot repeated by its multiplicity, and the sum must be
/// `control points + degree + 1`.
fn expand_knots(
    e: &Entity<'_>,
    mult_at: usize,
    knot_at: usize,
    dir: &str,
    points: usize,
    degree: usize,
) -> Result<Vec<f64>, StepError> {
    let label = |s: &str| {
        if dir.is_empty() {
            s.to_string()
        } else {
            format!("{dir}_{s}")
        }
    };
    let mults = e.counts(mult_at, &label("multiplicities"))?;
    let knots = e.reals(knot_at, &label("knots"))?;
    if degree == 0 || degree > MAX_DEGREE {
        return Err(e.invalid(format!(
            "{} is {degree}; tezgah reads degrees 1 to {MAX_DEGREE}",
            label("degree")
        )));
    }
    let d = if dir.is_empty() {
        String::new()
    } else {
        format!("{dir} ")
    };
    if mults.len() != knots.len() {
        return Err(e.invalid(format!(
            "{d}multiplicities list has {} entries but {d}knots has {}",
            mults.len(),
            knots.len()
        )));
    }
    let sum = mults.iter().try_fold(0usize, |a, &m| a.checked_add(m));
    let need = points + degree + 1;
    if sum != Some(need) {
        return Err(e.invalid(format!(
            "{d}multiplicities sum to {}, but {points} control points of degree {degree} need {need}",
            sum.map_or_else(|| "more than usize".to_string(), |s| s.to_string())
        )));
    }
    let mut out = Vec::with_capacity(need);
    for (k, m) in knots.iter().zip(&mults) {
        out.extend(std::iter::repeat_n(*k, *m));
    }
    Ok(out)
}
