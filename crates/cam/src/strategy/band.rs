//! The one-sided tolerance band: after a pass is placed, the machine's straight motion between
//! its cutter locations must never cut into the part, only leave a little material. Each
//! chord's sag against the exact cutter-location (CL) surface is measured, chords sagging more
//! than the chord tolerance either way get a midpoint, and every location is shifted out along
//! the surface normal by the inward sag of its chords plus what the later stages (the post's
//! linearisation, the controller's blending) may add inward. Flat and bull-nose passes also
//! run on past their ends (`run_out`). The strategies then size side steps for the scallop
//! minus the band's outward width ([`Band::outward`]).
//!
//! The sag of a chord is the chord-height (sagitta) error of CAM stepping (Choi 1991; Can,
//! 2010, §3.4.3.1, `ε ≈ L²κ/8` on a path of curvature κ) taken on the CL surface, not on the
//! contact curve: for a ball on a convex section of radius ρ the centre's chord sags `(1 + R/ρ)`
//! times the contacts' chord, and lead changes between locations add their own. So it is measured,
//! not modelled: at a contact `c(s)` between the two, the tip that touches there with the
//! machine's interpolated axis is compared with the chord point it projects to; the normal
//! component is the depth (positive inward). Maximised over the chord with geom's
//! `deviation::maximise` (every local peak refined, so both humps of an inflected span count).

use nalgebra::Unit;
use tezgah_geom::deviation::maximise;

use super::{Context, Placed};
use crate::error::CamError;
use crate::forward_step::{SurfacePath, MAX_POINTS};
use crate::gouge::sweep::Sweep;
use crate::orientation::ContactFrame;
use crate::toolpath::CutterLocation;

/// Samples per chord before the golden-section refinement of every peak.
const SAG_SAMPLES: usize = 8;
/// Rounds of midpoint insertion before the chords are left as they are (each round halves the
/// offending chords, so the sag drops fourfold).
const MAX_ROUNDS: usize = 6;

/// The one-sided band's setting: what the stages after the strategy may add to the motion
/// between the emitted points on either side of it (the post's linearisation deviation plus
/// the controller's corner blending, `G64 P`), mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    pub motion: f64,
}

impl Band {
    /// How far outside the exact CL surface the machine may run with chord tolerance
    /// `chord`: a convex chord's ends are shifted out by its sag (≤ `chord`) plus `motion`
    /// and the motion may add `motion` outward again; a concave chord runs out by its sag
    /// plus the same. The scallop ridge between two passes rises by at most this, so side
    /// steps are planned for the target minus it.
    pub fn outward(&self, chord: f64) -> f64 {
        chord + 2.0 * self.motion
    }

    pub(super) fn validate(&self) -> Result<(), CamError> {
        if self.motion.is_finite() && self.motion >= 0.0 {
            Ok(())
        } else {
            Err(CamError::Setting {
                name: "band motion",
                want: "a finite number ≥ 0 (mm)",
                got: self.motion,
            })
        }
    }
}

/// How far a chord between two cutter locations leaves the exact CL surface, mm: `inward` the
/// deepest it cuts below it, `outward` the farthest it runs above it (both ≥ 0).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChordSag {
    pub inward: f64,
    pub outward: f64,
}

impl Context<'_> {
    /// The sag of the move from `a` (contact at `ta` on `path`) to `b` (at `tb`) against the
    /// exact CL surface (module comment).
    pub(super) fn chord_sag(
        &self,
        path: &impl SurfacePath,
        (ta, tb): (f64, f64),
        a: &CutterLocation,
        b: &CutterLocation,
    ) -> ChordSag {
        let chord = b.tip - a.tip;
        let len2 = chord.norm_squared();
        if !(len2 > 0.0 && len2.is_finite()) {
            return ChordSag::default();
        }
        // The axis the post holds the machine to: on the great circle between the two.
        let motion = Sweep::between(
            (&a.tip, &Unit::new_normalize(a.axis)),
            (&b.tip, &Unit::new_normalize(b.axis)),
        );
        let depth = |s: f64| -> f64 {
            let (u, v) = path.uv(ta + (tb - ta) * s);
            let d = self.surface.derivs(u, v);
            let Some(n) = d.normal() else { return 0.0 };
            let n = if self.settings.reverse_normal { -n } else { n };
            let Some(frame) = ContactFrame::new(n, chord) else {
                return 0.0;
            };
            // The tip touching at c(s) with the axis the machine has where it passes c(s):
            // two rounds of projecting onto the chord settle the fraction.
            let mut sigma = s;
            let mut tip = a.tip;
            for _ in 0..2 {
                let (_, axis) = motion.pose(sigma);
                tip = self.shape().tip_for_contact(&d.point, &frame, &axis);
                sigma = ((tip - a.tip).dot(&chord) / len2).clamp(0.0, 1.0);
            }
            n.dot(&(tip - (a.tip + chord * sigma)))
        };
        let inward = maximise(depth, 0.0, 1.0, SAG_SAMPLES).distance;
        let outward = maximise(|s| -depth(s), 0.0, 1.0, SAG_SAMPLES).distance;
        ChordSag {
            inward: inward.max(0.0),
            outward: outward.max(0.0),
        }
    }

    /// Halves every chord between two placed locations that sags more than the chord
    /// tolerance either way (the contacts' chord error does not bound the CL's), placing the
    /// new contacts; `ts` are the contacts' path parameters and `contact_at` builds a contact.
    pub(super) fn refine_chords(
        &self,
        path: &impl SurfacePath,
        ts: &mut Vec<f64>,
        placed: &mut Vec<Result<Placed, super::GougeReport>>,
        contact_at: impl Fn(f64) -> super::Contact,
    ) {
        let tolerance = self.settings.tolerance;
        for _ in 0..MAX_ROUNDS {
            let split: Vec<bool> = (0..ts.len().saturating_sub(1))
                .map(|i| match (&placed[i], &placed[i + 1]) {
                    (Ok(a), Ok(b)) => {
                        let sag =
                            self.chord_sag(path, (ts[i], ts[i + 1]), &a.location, &b.location);
                        sag.inward.max(sag.outward) > tolerance
                    }
                    _ => false,
                })
                .collect();
            let count = split.iter().filter(|s| **s).count();
            if count == 0 || ts.len() + count > MAX_POINTS {
                return;
            }
            let mut new_ts = Vec::with_capacity(ts.len() + count);
            let mut new_placed = Vec::with_capacity(ts.len() + count);
            for (i, item) in std::mem::take(placed).into_iter().enumerate() {
                new_ts.push(ts[i]);
                new_placed.push(item);
                if split.get(i).copied().unwrap_or(false) {
                    let t = 0.5 * (ts[i] + ts[i + 1]);
                    let c = contact_at(t);
                    new_ts.push(t);
                    new_placed.push(self.place(c.uv.0, c.uv.1, c.tangent, 0.0));
                }
            }
            *ts = new_ts;
            *placed = new_placed;
        }
    }

    /// Shifts every placed location out along its surface normal by `band.motion` plus the
    /// inward sag of the chords it ends (a chord only joins locations that are neighbours in
    /// the pass, both placed), so no chord nor the motion around it cuts into the part.
    pub(super) fn shift_outward(
        &self,
        path: &impl SurfacePath,
        ts: &[f64],
        placed: &mut [Result<Placed, super::GougeReport>],
        band: Band,
    ) {
        let mut shift = vec![band.motion; placed.len()];
        for i in 0..placed.len().saturating_sub(1) {
            if let (Ok(a), Ok(b)) = (&placed[i], &placed[i + 1]) {
                let sag = self.chord_sag(path, (ts[i], ts[i + 1]), &a.location, &b.location);
                shift[i] = shift[i].max(band.motion + sag.inward);
                shift[i + 1] = shift[i + 1].max(band.motion + sag.inward);
            }
        }
        for (p, s) in placed.iter_mut().zip(shift) {
            if let Ok(p) = p {
                p.location.tip += p.location.normal * s;
            }
        }
    }
}

/// Rounds of raising the leads at the ends of a chord whose sweep gouges.
const CHORD_ROUNDS: usize = 4;
/// Lead added per round at both ends of such a chord, degrees.
const CHORD_LEAD_STEP_DEG: f64 = 1.0;

impl Context<'_> {
    /// The machine sweeps the cutter along a straight tip move with the axis turning on a
    /// great circle between two placed locations; the rear and global checks only saw the
    /// ends. The whole sweep is checked (lifted as the band will lift its ends, so the
    /// chord's own sag near the contact, which the band removes, does not count; the rear
    /// check bounds every pose of it, [`crate::gouge::rear::RearIndex::first_penetration_along`],
    /// the shank and holder are checked half-way), and where it gouges both ends are placed
    /// again leaning further (by [`CHORD_LEAD_STEP_DEG`] a round); ends whose chords still
    /// gouge after [`CHORD_ROUNDS`] are refused (reported, never emitted). Checking the middle
    /// alone let a flat end's rim sweep across a rise 30 % of the way along a chord (4 µm on
    /// the free-form patch's corner).
    pub(super) fn clear_chords(
        &self,
        path: &impl SurfacePath,
        ts: &[f64],
        contacts: &[super::Contact],
        placed: &mut [Result<Placed, super::GougeReport>],
        band: Band,
    ) {
        let step = CHORD_LEAD_STEP_DEG.to_radians();
        for round in 0..=CHORD_ROUNDS {
            let mut gouging = vec![None; placed.len()];
            for i in 0..placed.len().saturating_sub(1) {
                if let (Ok(a), Ok(b)) = (&placed[i], &placed[i + 1]) {
                    let (a, b) = (&a.location, &b.location);
                    // Both ends will be lifted along their normals by at least the band's
                    // motion plus this chord's inward sag (`shift_outward`): the chord as
                    // the machine will sweep it.
                    let sag = self.chord_sag(path, (ts[i], ts[i + 1]), a, b);
                    let lift = band.motion + sag.inward;
                    let (tip_a, tip_b) = (a.tip + a.normal * lift, b.tip + b.normal * lift);
                    let sweep = Sweep::between(
                        (&tip_a, &Unit::new_normalize(a.axis)),
                        (&tip_b, &Unit::new_normalize(b.axis)),
                    );
                    if let Some(g) = self.checker.check_sweep(&sweep) {
                        gouging[i] = Some(g);
                        gouging[i + 1] = Some(g);
                    }
                }
            }
            if gouging.iter().all(Option::is_none) {
                return;
            }
            for (i, g) in gouging.into_iter().enumerate() {
                let (Some(g), Ok(p)) = (g, &placed[i]) else {
                    continue;
                };
                let c = contacts[i];
                let report = super::GougeReport {
                    uv: c.uv,
                    contact: p.location.contact,
                    refusal: super::Refusal::Gouge(g),
                };
                let lead = p.lead + step;
                let max_lead = match self.settings.axis {
                    super::ToolAxis::Surface { max_lead_deg, .. } => max_lead_deg.to_radians(),
                    super::ToolAxis::Fixed(_) => f64::NEG_INFINITY,
                };
                placed[i] = if round == CHORD_ROUNDS || lead > max_lead + 1e-12 {
                    Err(report)
                } else {
                    self.place(c.uv.0, c.uv.1, c.tangent, lead)
                };
            }
        }
    }
}

/// How one tolerance `T` (what the machine's motion may depart from the exact CL surface;
/// ARCHITECTURE.md, "One tolerance budget") is shared between the stages when the band is on: the
/// strategy's chords `T/2`, the post's linearisation `T/8`, the controller's blending (`G64 P`)
/// `T/8`. The band's motion is linearisation + blending (`T/4`), so its outward width
/// `T/2 + 2·T/4` is exactly `T`: the motion runs between 0 and `T` outside the exact CL
/// surface, and side steps are planned for `h − T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToleranceShares {
    pub chord: f64,
    pub linearisation: f64,
    pub blend: f64,
}

impl ToleranceShares {
    pub fn of(total: f64) -> ToleranceShares {
        ToleranceShares {
            chord: 0.5 * total,
            linearisation: 0.125 * total,
            blend: 0.125 * total,
        }
    }

    /// The band the strategy is given: linearisation and blending may each move the motion
    /// that far to either side of the chords.
    pub fn band(&self) -> Band {
        Band {
            motion: self.linearisation + self.blend,
        }
    }
}

/// Halvings of a run-out that gouges before it is left out.
const RUN_OUT_TRIALS: usize = 4;
/// Largest step between the checked poses of a run-out, mm: between two poses a surface
/// point's depth in the cutter changes by at most the step (the depth is 1-Lipschitz), and
/// the poses' bottoms overlap.
const RUN_OUT_POSE_STEP: f64 = 0.25;

impl Context<'_> {
    /// A flat or bull-nose cutter's run-out past the end of a pass (`prev` then `last`):
    /// its footprint's front edge curves back from the contact, so where the pass stops the
    /// strip across the feed beside the contact is never swept and keeps the full cusp. The
    /// cusp lies `w/2` beside the pass (`w` the side step there); an edge circle of radius ρ
    /// trails the contact by `ρ − √(ρ² − y²)` at a lateral offset `y`, so moving on along the
    /// feed (tangent to the surface, same axis) by that at `y = 0.75 w` (a margin for
    /// neighbouring passes spaced wider) with ρ the smallest edge circle (`R − r`, the flat
    /// part's rim; `y` itself where that circle is narrower) sweeps the strip. A ball's
    /// footprint is symmetric about the contact: no run-out. Kept short because the tangent
    /// move leaves the surface's curvature behind; shortened while it would gouge, left out if
    /// it still does.
    pub(super) fn run_out(
        &self,
        prev: &CutterLocation,
        last: &CutterLocation,
    ) -> Option<CutterLocation> {
        if matches!(self.shape(), crate::cutter::CutterShape::Ball { .. }) {
            return None;
        }
        let n = last.normal;
        // Along the contacts' path: the tips may also step sideways where the lean changes.
        let along = last.contact - prev.contact;
        let feed = along - n * along.dot(&n);
        let len = feed.norm();
        if !(len.is_finite() && len > 0.0) {
            return None;
        }
        let feed = feed / len;
        let tangent_uv = (last.uv.0 - prev.uv.0, last.uv.1 - prev.uv.1);
        let radius = self.shape().radius();
        let w = self
            .local(last.uv.0, last.uv.1, tangent_uv)
            .and_then(|l| self.side_step(&l))
            .unwrap_or(radius);
        let axis = Unit::new_normalize(last.axis);
        let y = 0.75 * w;
        let rho = radius - self.shape().corner_radius();
        let mut d = if y < rho {
            rho - (rho * rho - y * y).sqrt()
        } else {
            y.min(radius)
        };
        for _ in 0..RUN_OUT_TRIALS {
            // The whole move, not only where it ends: poses every RUN_OUT_POSE_STEP along it
            // (a tangent move over a surface curving up ahead cuts in mid-way and clears
            // again at its end: 2.3 µm on the STEP patch, bull-nose D6 at 5° lead).
            let poses = (d / RUN_OUT_POSE_STEP).ceil().max(1.0) as usize;
            let clear = (1..=poses).all(|k| {
                let tip = last.tip + feed * (d * k as f64 / poses as f64);
                self.checker.check(&tip, &axis).is_none()
            });
            if clear {
                return Some(CutterLocation {
                    tip: last.tip + feed * d,
                    ..*last
                });
            }
            d *= 0.5;
        }
        None
    }
}
