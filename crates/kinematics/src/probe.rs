//! The simulated touch probe: the machine file's `[probe]` section (or a file of its own given
//! on the command line) describes solids in the workpiece frame and the stylus ball's radius;
//! a G38 move asks it, period by period, whether the probe input is on (ball touching a solid).
//!
//! The solids are half-spaces bounded by planes (a table or part top, a side wall) and
//! axis-aligned boxes (a part, a vise jaw). The stylus is a ball of `tool_radius_mm` centred on
//! the tool tip, so a Z-down probe onto the plane z = h trips at z = h + r and a +X probe onto a
//! box's face at x = x₀ at x = x₀ − r.

use serde::Deserialize;
use tezgah_geom::Vec3;

use crate::machine::MachineError;

/// A solid the probe can touch.
#[derive(Debug, Clone, PartialEq)]
pub enum Solid {
    /// The half-space behind a plane: points p with (p − point)·normal ≤ 0 (`normal` unit,
    /// pointing out of the material).
    HalfSpace {
        /// A point of the plane, mm.
        point: Vec3,
        /// Unit normal out of the material.
        normal: Vec3,
    },
    /// An axis-aligned box, mm.
    Box {
        /// The corner of least X, Y and Z, mm.
        min: Vec3,
        /// The corner of greatest X, Y and Z, mm.
        max: Vec3,
    },
}

impl Solid {
    /// Signed distance from `p` to the solid's surface, mm: > 0 outside, ≤ 0 inside.
    pub fn distance(&self, p: &Vec3) -> f64 {
        match self {
            Solid::HalfSpace { point, normal } => (p - point).dot(normal),
            Solid::Box { min, max } => {
                // Per axis, how far outside the slab (negative: inside by that much).
                let d = Vec3::new(
                    (min.x - p.x).max(p.x - max.x),
                    (min.y - p.y).max(p.y - max.y),
                    (min.z - p.z).max(p.z - max.z),
                );
                let outside = Vec3::new(d.x.max(0.0), d.y.max(0.0), d.z.max(0.0)).norm();
                outside + d.x.max(d.y).max(d.z).min(0.0)
            }
        }
    }
}

/// The simulated probe: solids and the stylus ball.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeModel {
    /// Stylus ball radius, mm (0: a point probe).
    pub tool_radius: f64,
    /// What the ball can touch.
    pub solids: Vec<Solid>,
}

impl ProbeModel {
    /// Whether the probe input is on with the ball centred at `p` (touching or inside a
    /// solid).
    pub fn touches(&self, p: &Vec3) -> bool {
        self.solids
            .iter()
            .any(|s| s.distance(p) <= self.tool_radius)
    }

    /// A probe file's text: the fields of a machine file's `[probe]` section at top level.
    pub fn from_toml_str(text: &str) -> Result<ProbeModel, MachineError> {
        let raw: RawProbe = toml::from_str(text).map_err(|e| MachineError::Toml {
            message: e.to_string().trim_end().to_owned(),
        })?;
        raw.build("")
    }
}

/// `[probe]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawProbe {
    #[serde(default)]
    tool_radius_mm: f64,
    #[serde(default)]
    plane: Vec<RawPlane>,
    #[serde(default, rename = "box")]
    boxes: Vec<RawBox>,
}

/// `[[probe.plane]]`: a point on the plane and the normal out of the material.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPlane {
    point: [f64; 3],
    normal: [f64; 3],
}

/// `[[probe.box]]`: opposite corners.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBox {
    min: [f64; 3],
    max: [f64; 3],
}

impl RawProbe {
    /// Validated; `prefix` is the section's dotted path for errors (`probe.` in a machine
    /// file, empty in a probe file).
    pub(crate) fn build(self, prefix: &str) -> Result<ProbeModel, MachineError> {
        let invalid = |field: String, reason: &str| MachineError::Invalid {
            field,
            reason: reason.to_owned(),
        };
        let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
        if !(self.tool_radius_mm >= 0.0 && self.tool_radius_mm.is_finite()) {
            return Err(invalid(
                format!("{prefix}tool_radius_mm"),
                "must be ≥ 0 and finite",
            ));
        }
        let mut solids = Vec::new();
        for (i, p) in self.plane.iter().enumerate() {
            let normal = Vec3::from(p.normal);
            let length = normal.norm();
            if !(finite(&p.point) && finite(&p.normal) && length > 1e-12) {
                return Err(invalid(
                    format!("{prefix}plane[{i}]"),
                    "point and normal must be finite, the normal not zero",
                ));
            }
            solids.push(Solid::HalfSpace {
                point: Vec3::from(p.point),
                normal: normal / length,
            });
        }
        for (i, b) in self.boxes.iter().enumerate() {
            if !(finite(&b.min) && finite(&b.max) && (0..3).all(|k| b.min[k] < b.max[k])) {
                return Err(invalid(
                    format!("{prefix}box[{i}]"),
                    "min must be below max on every axis, all finite",
                ));
            }
            solids.push(Solid::Box {
                min: Vec3::from(b.min),
                max: Vec3::from(b.max),
            });
        }
        if solids.is_empty() {
            return Err(invalid(
                format!("{prefix}plane"),
                "the probe needs at least one plane or box to touch",
            ));
        }
        Ok(ProbeModel {
            tool_radius: self.tool_radius_mm,
            solids,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_and_a_plane_parse_and_touch_at_the_ball_radius() {
        let m = ProbeModel::from_toml_str(
            "tool_radius_mm = 2\n[[plane]]\npoint = [0, 0, -50]\nnormal = [0, 0, 3]\n\
             [[box]]\nmin = [10, -5, -20]\nmax = [30, 5, 0]\n",
        )
        .unwrap();
        assert_eq!(m.solids.len(), 2);
        // Above the plane by exactly the radius: touching; a hair higher: not.
        assert!(m.touches(&Vec3::new(-50.0, 0.0, -48.0)));
        assert!(!m.touches(&Vec3::new(-50.0, 0.0, -47.999)));
        // The box's −X face at x = 10, 2 mm out; its top corner edge at distance √(1² + 1²).
        assert!(m.touches(&Vec3::new(8.0, 0.0, -10.0)));
        assert!(!m.touches(&Vec3::new(7.99, 0.0, -10.0)));
        let corner = Solid::Box {
            min: Vec3::new(10.0, -5.0, -20.0),
            max: Vec3::new(30.0, 5.0, 0.0),
        };
        assert!((corner.distance(&Vec3::new(9.0, 0.0, 1.0)) - 2f64.sqrt()).abs() < 1e-12);
        // Inside: minus the nearest face's depth.
        assert!((corner.distance(&Vec3::new(20.0, 0.0, -1.0)) + 1.0).abs() < 1e-12);
    }

    #[test]
    fn bad_sections_are_refused_by_field() {
        let err = |t: &str| ProbeModel::from_toml_str(t).unwrap_err().to_string();
        assert_eq!(
            err("[[box]]\nmin = [0, 0, 0]\nmax = [1, 0, 1]\n"),
            "box[0]: min must be below max on every axis, all finite"
        );
        assert_eq!(
            err("[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\n"),
            "plane[0]: point and normal must be finite, the normal not zero"
        );
        assert_eq!(
            err("tool_radius_mm = 1\n"),
            "plane: the probe needs at least one plane or box to touch"
        );
        assert!(err("tool_radius = 1\n").contains("unknown field"));
    }
}
