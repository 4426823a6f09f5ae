//! Gouge checks for a placed cutter: local (curvature interference at the contact), rear
//! (the cutting end, the flutes and a shank of the tool's radius against the surface, exact
//! to the tolerance through a spatial index of surface samples) and global (a shank of
//! another radius and the holder against the surface, with a clearance). The
//! strategies call [`GougeChecker::check`] for every cutter location and correct the tool
//! axis or report the point; nothing gouging is emitted silently. The checks run against the
//! machined face and any other faces of the part given ([`CheckFace`]), each only inside its
//! trim.

pub mod global;
pub mod index;
pub mod local;
pub mod rear;
pub mod sweep;

use nalgebra::Unit;
use tezgah_geom::{NurbsSurface, Vec3};

use crate::cutter::Cutter;
use crate::error::{positive, CamError};
use crate::region::FaceRegion;
use index::PointGrid;

/// A face the tool must not cut into: its surface and, for a trimmed face, its region in
/// (u, v) (`None`: the whole surface).
#[derive(Debug, Clone, PartialEq)]
pub struct CheckFace {
    pub surface: NurbsSurface,
    pub region: Option<FaceRegion>,
}

/// Which part of the tool meets the surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolPart {
    /// The cutting end (ball, torus or flat bottom and the flutes up to two radii).
    CuttingEnd,
    /// The flutes above the cutting end.
    Flutes,
    Shank,
    Holder,
}

/// What kind of gouge a cutter location has.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gouge {
    /// The cutter is more curved than the surface is concave in some direction at the contact
    /// point; `margin` is the most negative eigenvalue of `K_cutter − K_surface` (1/mm).
    Local { margin: f64 },
    /// A surface point lies `depth` mm inside the given part of the tool.
    Interference {
        part: ToolPart,
        depth: f64,
        point: Vec3,
    },
}

/// Settings of the rear and global checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GougeSettings {
    /// Spacing of the surface samples of the rear check (mm); Can (2010) scans at 0.15 mm.
    pub rear_spacing: f64,
    /// Spacing of the samples for the shank/holder check (mm); the check keeps a clearance of
    /// this spacing so the surface between samples cannot reach the tool unseen.
    pub global_spacing: f64,
    /// Penetration below which a surface point does not count as a rear gouge (mm).
    pub depth_tolerance: f64,
    /// The same for the part's other faces ([`CheckFace`]): where one meets the machined face
    /// at a concave crease, cutting the face to its edge reaches into it (a D6 ball reaches
    /// 0.073 mm into the lofted blade's #876 from #17), so how deep is the user's to say
    /// (`tezgah cam --check-tolerance`).
    pub neighbour_depth_tolerance: f64,
    pub rear: bool,
    pub global: bool,
}

impl Default for GougeSettings {
    fn default() -> Self {
        GougeSettings {
            rear_spacing: 0.3,
            global_spacing: 1.0,
            depth_tolerance: 0.002,
            neighbour_depth_tolerance: 0.002,
            rear: true,
            global: true,
        }
    }
}

/// The faces indexed for the checks of one cutter.
#[derive(Debug, Clone)]
pub struct GougeChecker {
    cutter: Cutter,
    settings: GougeSettings,
    /// One rear index per face, with its depth tolerance.
    fine: Vec<(rear::RearIndex, f64)>,
    /// How high the rear check's solid reaches ([`rear::checked_height`]).
    height: f64,
    /// The samples of every face inside its trim, together.
    coarse: Option<PointGrid>,
}

impl GougeChecker {
    /// Samples and indexes the whole of `surface` for `cutter`.
    pub fn new(
        surface: &NurbsSurface,
        cutter: &Cutter,
        settings: GougeSettings,
    ) -> Result<GougeChecker, CamError> {
        GougeChecker::of_faces(&[(surface, None)], cutter, settings)
    }

    /// Samples and indexes `faces` (each a surface and its trim, if any) for `cutter`: the
    /// machined face first, then the part's other faces.
    pub fn of_faces(
        faces: &[(&NurbsSurface, Option<&FaceRegion>)],
        cutter: &Cutter,
        settings: GougeSettings,
    ) -> Result<GougeChecker, CamError> {
        positive("gouge rear_spacing", settings.rear_spacing)?;
        positive("gouge global_spacing", settings.global_spacing)?;
        positive("gouge depth_tolerance", settings.depth_tolerance)?;
        positive(
            "gouge neighbour_depth_tolerance",
            settings.neighbour_depth_tolerance,
        )?;
        let r = cutter.shape.radius();
        let sample = |surface, spacing| {
            index::sample_surface(surface, spacing).ok_or(CamError::TooLarge {
                what: "gouge-check samples (raise the gouge spacing)",
                limit: index::MAX_SAMPLES,
            })
        };
        let mut fine = Vec::new();
        if settings.rear {
            for (k, &(surface, region)) in faces.iter().enumerate() {
                let samples = sample(surface, settings.rear_spacing)?;
                let tolerance = if k == 0 {
                    settings.depth_tolerance
                } else {
                    settings.neighbour_depth_tolerance
                };
                fine.push((
                    rear::RearIndex::within(surface, region, samples, 2.0 * r),
                    tolerance,
                ));
            }
        }
        let coarse = if settings.global {
            let mut points = Vec::new();
            for &(surface, region) in faces {
                let lattice = sample(surface, settings.global_spacing)?;
                // The shank and holder keep a clearance of the spacing, so the face between
                // its last sample and its trim cannot reach them unseen.
                points.extend(lattice.samples.iter().filter(|s| {
                    let (u, v) = (lattice.u[s.node[0] as usize], lattice.v[s.node[1] as usize]);
                    region.is_none_or(|r| r.contains(u, v))
                }));
            }
            if points.len() > index::MAX_SAMPLES {
                return Err(CamError::TooLarge {
                    what: "gouge-check samples (raise the gouge spacing)",
                    limit: index::MAX_SAMPLES,
                });
            }
            Some(PointGrid::new(
                points,
                (2.0 * r).max(4.0 * settings.global_spacing),
            ))
        } else {
            None
        };
        Ok(GougeChecker {
            cutter: *cutter,
            settings,
            height: rear::checked_height(cutter),
            fine,
            coarse,
        })
    }

    /// The part of the tool `z` mm above its tip, within the rear check's solid.
    fn part_at(&self, z: f64) -> ToolPart {
        if z <= rear::CUTTING_END_RADII * self.cutter.shape.radius() {
            ToolPart::CuttingEnd
        } else if z <= self.cutter.flute_length {
            ToolPart::Flutes
        } else {
            ToolPart::Shank
        }
    }

    /// Whether the cutter standing at `tip` along `axis` (any length) passes [`Self::check`].
    pub fn clear(&self, tip: &Vec3, axis: &Vec3) -> bool {
        self.check(tip, &Unit::new_normalize(*axis)).is_none()
    }

    /// Rear and global checks of the cutter standing at `tip` along `axis` (the local check
    /// needs the contact's curvature and lives in [`local`]).
    pub fn check(&self, tip: &Vec3, axis: &Unit<Vec3>) -> Option<Gouge> {
        self.check_sweep(&sweep::Sweep::still(tip, axis))
    }

    /// Rear and global checks of the cutter moving along `sweep`: the rear check over every
    /// pose of it ([`rear::RearIndex::first_penetration_along`]), the global check (shank and
    /// holder, which keep a clearance of the global spacing) at its middle.
    pub fn check_sweep(&self, sweep: &sweep::Sweep) -> Option<Gouge> {
        for (index, tolerance) in &self.fine {
            if let Some(rear::Penetration { depth, point, at }) =
                index.first_penetration_within(&self.cutter.shape, self.height, sweep, *tolerance)
            {
                let (tip, axis) = sweep.pose(at);
                return Some(Gouge::Interference {
                    part: self.part_at((point - tip).dot(&axis)),
                    depth,
                    point,
                });
            }
        }
        if let Some(grid) = &self.coarse {
            let (tip, axis) = sweep.pose(0.5);
            if let Some(hit) = global::collision(
                grid,
                &self.cutter,
                &tip,
                &axis,
                self.settings.global_spacing,
            ) {
                return Some(Gouge::Interference {
                    part: hit.part,
                    depth: hit.depth,
                    point: hit.point,
                });
            }
        }
        None
    }
}
