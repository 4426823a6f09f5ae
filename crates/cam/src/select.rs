//! Tool selection (Can, 2010, §3.4.7.2): the largest cutter of a standard set that fits the
//! surface's tightest concave curvature. A ball fits if its radius is below the smallest concave
//! radius; a flat end mill needs a lead ("Sturz") angle with `r / sin S ≤ ρ`, capped at `S_max`
//! (20° in 001), so its radius is at most `ρ sin S_max`, snapped down to a standard size, and
//! the lead recomputed as `asin(r/ρ)`. The tightest radius is read from the principal
//! curvatures over the whole surface (Can scans only the two iso-parametric directions).

use tezgah_geom::NurbsSurface;

use crate::error::CamError;
use crate::region::FaceRegion;

/// Metric end-mill diameters (mm) offered by default.
pub const STANDARD_DIAMETERS: [f64; 14] = [
    1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 32.0,
];

/// A proposed flat end mill and the lead it needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatProposal {
    pub diameter: f64,
    pub lead_deg: f64,
}

/// The largest ball and flat end mills of the set that fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proposal {
    /// Ball diameter (strictly below twice the tightest concave radius).
    pub ball: Option<f64>,
    pub flat: Option<FlatProposal>,
}

/// The smallest concave radius (mm) of the surface seen from the side its normal points to
/// (reversed with `reverse_normal`): `1/κ₁` maximised over a `lattice × lattice` grid of
/// parameters — over the face's region's box and inside it on a trimmed face, so a tight place
/// of the surface beyond the trim does not shrink the tool. `None` where it is nowhere concave.
pub fn tightest_concave_radius(
    surface: &NurbsSurface,
    region: Option<&FaceRegion>,
    lattice: usize,
    reverse_normal: bool,
) -> Option<f64> {
    let domain = (surface.domain_u(), surface.domain_v());
    let ((u0, u1), (v0, v1)) = region
        .and_then(|r| r.clip_box(domain.0, domain.1))
        .unwrap_or(domain);
    let n = lattice.max(2);
    let mut worst = 0.0f64;
    for i in 0..=n {
        for j in 0..=n {
            let u = u0 + (u1 - u0) * i as f64 / n as f64;
            let v = v0 + (v1 - v0) * j as f64 / n as f64;
            if region.is_some_and(|r| !r.contains(u, v)) {
                continue;
            }
            if let Some(pc) = surface.principal_curvatures(u, v) {
                let k = if reverse_normal { -pc.k2 } else { pc.k1 };
                worst = worst.max(k);
            }
        }
    }
    (worst > 0.0).then(|| 1.0 / worst)
}

/// The largest flat-end radius that curvature matching allows on `radius` at `max_lead_deg`:
/// `ρ sin S_max` (Can, 2010, §3.4.7.2).
pub fn max_flat_radius(radius: f64, max_lead_deg: f64) -> f64 {
    radius * max_lead_deg.to_radians().sin()
}

/// Proposes the largest ball and flat end mills of `standard` (diameters, mm) for a surface
/// whose tightest concave radius is `concave_radius` (`None`: nowhere concave, so the largest
/// of the set, the flat one untilted).
pub fn propose(
    concave_radius: Option<f64>,
    standard: &[f64],
    max_lead_deg: f64,
) -> Result<Proposal, CamError> {
    if standard.is_empty() || standard.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
        return Err(CamError::NoCutter(
            "the standard set must hold finite diameters > 0".into(),
        ));
    }
    if !(max_lead_deg > 0.0 && max_lead_deg < 90.0) {
        return Err(CamError::Setting {
            name: "max_lead",
            want: "between 0 and 90 degrees",
            got: max_lead_deg,
        });
    }
    let largest = |fits: &dyn Fn(f64) -> bool| {
        standard
            .iter()
            .copied()
            .filter(|d| fits(*d))
            .fold(None, |best: Option<f64>, d| {
                Some(best.map_or(d, |b| b.max(d)))
            })
    };
    match concave_radius {
        None => {
            let d = largest(&|_| true);
            Ok(Proposal {
                ball: d,
                flat: d.map(|diameter| FlatProposal {
                    diameter,
                    lead_deg: 0.0,
                }),
            })
        }
        Some(rho) if rho.is_finite() && rho > 0.0 => {
            let ball = largest(&|d| d < 2.0 * rho);
            let limit = 2.0 * max_flat_radius(rho, max_lead_deg);
            let flat = largest(&|d| d <= limit).map(|diameter| FlatProposal {
                diameter,
                lead_deg: (diameter / 2.0 / rho).asin().to_degrees(),
            });
            Ok(Proposal { ball, flat })
        }
        Some(rho) => Err(CamError::Setting {
            name: "concave radius",
            want: "finite and > 0",
            got: rho,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    /// The sizes Can's (2010) tables use (its standard table is not given): with 12 mm in the
    /// set its §3.4.7.2 example (ρ = 20, S ≤ 20°) would pick 12, so the thesis's own set evidently
    /// lacked it.
    const THESIS_SET: [f64; 4] = [6.0, 10.0, 16.0, 20.0];

    #[test]
    fn reference_001_tool_selection_cases() {
        // T1: ρ = 20, S_max = 20° → r = 6.84, D = 13.68 → D = 10 → S = 14.4775°.
        assert!((max_flat_radius(20.0, 20.0) - 6.840_402_866_513_374).abs() < 1e-12);
        let p = propose(Some(20.0), &THESIS_SET, 20.0).unwrap();
        let flat = p.flat.unwrap();
        assert_eq!(flat.diameter, 10.0);
        assert!((flat.lead_deg - 14.477_512_185_929_92).abs() < 1e-9);
        // T2: ρ = 100 → r = 34.20 (D ≈ 68, impractical: the set's largest is proposed).
        assert!((max_flat_radius(100.0, 20.0) - 34.202_014_332_566_87).abs() < 1e-12);
        assert_eq!(
            propose(Some(100.0), &THESIS_SET, 20.0)
                .unwrap()
                .flat
                .unwrap()
                .diameter,
            20.0
        );
        // T3 (EK-B): min concave 26.0544985816258 → ball D < 52.11, flat D = 16 at
        // 17.8814613349°.
        let rho = 26.054_498_581_625_8;
        let p = propose(
            Some(rho),
            &[6.0, 10.0, 12.0, 16.0, 20.0, 50.0, 52.0, 60.0],
            20.0,
        )
        .unwrap();
        assert_eq!(p.ball, Some(52.0));
        let flat = p.flat.unwrap();
        assert_eq!(flat.diameter, 16.0);
        assert!((flat.lead_deg - 17.881_461_334_9).abs() < 1e-9);
    }

    #[test]
    fn tightest_radius_of_known_surfaces() {
        // Inside a trough of radius 20 every point is concave 1/20 across it.
        let r =
            tightest_concave_radius(&testing::cylinder(20.0, 50.0, false), None, 8, false).unwrap();
        assert!((r - 20.0).abs() < 1e-9, "{r}");
        // The roller is convex: nothing concave, unless machined from inside.
        assert_eq!(
            tightest_concave_radius(&testing::cylinder(20.0, 50.0, true), None, 8, false),
            None
        );
        let r = tightest_concave_radius(&testing::sphere(30.0), None, 8, true).unwrap();
        assert!((r - 30.0).abs() < 1e-9, "{r}");
        // Saddle z = (x² − y²)/80 over [−50, 50]²: the sharpest concave curvature is at the
        // centre along x, 1/40.
        let r = tightest_concave_radius(&testing::saddle(50.0, 40.0), None, 10, false).unwrap();
        assert!((r - 40.0).abs() < 1e-9, "{r}");
        let p = propose(Some(r), &STANDARD_DIAMETERS, 20.0).unwrap();
        assert_eq!(p.ball, Some(32.0));
        assert_eq!(p.flat.unwrap().diameter, 25.0);
        assert!(propose(Some(r), &[], 20.0).is_err());
    }

    #[test]
    fn a_trimmed_face_is_sized_on_itself_not_its_surface() {
        // The saddle trimmed to x ∈ [30, 50] (u ∈ [0.8, 1]): the centre's radius 40 is beyond
        // the trim; the tightest place left is the trim's middle (30, 0), where the section
        // z = x²/80 has radius 40·(1 + (30/40)²)^{3/2} = 78.125.
        let saddle = testing::saddle(50.0, 40.0);
        let strip =
            FaceRegion::new(vec![vec![(0.8, 0.0), (1.0, 0.0), (1.0, 1.0), (0.8, 1.0)]]).unwrap();
        let r = tightest_concave_radius(&saddle, Some(&strip), 10, false).unwrap();
        assert!((r - 78.125).abs() < 1e-9, "{r}");
    }
}
