//! Cutters: ball, flat and bull-nose (torus) end mills with their shank and holder, the
//! geometry every CAM stage shares — strategies place them, gouge checks test them, the
//! verifying simulation sweeps them. Dimensions in mm; the command line's `SPEC` strings parse
//! here.

use std::fmt;
use std::str::FromStr;

/// The cutting end of a tool, by the shape of its profile: a corner radius `r` on a tool of
/// radius `R` (ball: `r = R`; flat: `r = 0`; bull-nose: `0 < r < R`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CutterShape {
    Ball { radius: f64 },
    Flat { radius: f64 },
    BullNose { radius: f64, corner_radius: f64 },
}

/// A cylinder along the tool axis, starting `from` mm above the tool tip: the shank or holder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    pub radius: f64,
    pub from: f64,
    pub length: f64,
}

/// A whole tool: the cutting end, its flute length, and the non-cutting shank and holder
/// that the global gouge check keeps off the part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cutter {
    pub shape: CutterShape,
    /// Height of the cutting part above the tip.
    pub flute_length: f64,
    pub shank: Cylinder,
    pub holder: Cylinder,
}

impl CutterShape {
    /// Tool radius `R`.
    pub fn radius(&self) -> f64 {
        match *self {
            CutterShape::Ball { radius }
            | CutterShape::Flat { radius }
            | CutterShape::BullNose { radius, .. } => radius,
        }
    }

    /// Corner (torus tube) radius `r`.
    pub fn corner_radius(&self) -> f64 {
        match *self {
            CutterShape::Ball { radius } => radius,
            CutterShape::Flat { .. } => 0.0,
            CutterShape::BullNose { corner_radius, .. } => corner_radius,
        }
    }
}

impl Cutter {
    /// A tool of this shape with the proportions of a stock end mill: flutes 3·D, a shank of
    /// the tool's radius to 5·D, then a holder of radius 2·D, 40 mm long.
    pub fn standard(shape: CutterShape) -> Cutter {
        let d = 2.0 * shape.radius();
        Cutter {
            shape,
            flute_length: 3.0 * d,
            shank: Cylinder {
                radius: shape.radius(),
                from: 3.0 * d,
                length: 2.0 * d,
            },
            holder: Cylinder {
                radius: 2.0 * d,
                from: 5.0 * d,
                length: 40.0,
            },
        }
    }
}

/// Why a tool specification was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CutterSpecError {
    #[error("tool '{0}': expected ball:D, flat:D or bull:D:r (diameter D, corner radius r, mm)")]
    Form(String),
    #[error("tool '{spec}': {what} must be a finite number > 0")]
    Number { spec: String, what: &'static str },
    #[error("tool '{0}': the corner radius must be less than half the diameter (use ball:D)")]
    Corner(String),
}

impl FromStr for CutterShape {
    type Err = CutterSpecError;

    /// The command line's `SPEC`: `ball:D`, `flat:D`, `bull:D:r`.
    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let number = |text: &str, what| {
            text.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or(CutterSpecError::Number {
                    spec: spec.to_owned(),
                    what,
                })
        };
        let parts: Vec<&str> = spec.split(':').collect();
        match parts.as_slice() {
            [kind, d] if kind.eq_ignore_ascii_case("ball") => Ok(CutterShape::Ball {
                radius: number(d, "the diameter")? / 2.0,
            }),
            [kind, d] if kind.eq_ignore_ascii_case("flat") => Ok(CutterShape::Flat {
                radius: number(d, "the diameter")? / 2.0,
            }),
            [kind, d, r] if kind.eq_ignore_ascii_case("bull") => {
                let radius = number(d, "the diameter")? / 2.0;
                let corner_radius = number(r, "the corner radius")?;
                if corner_radius >= radius {
                    return Err(CutterSpecError::Corner(spec.to_owned()));
                }
                Ok(CutterShape::BullNose {
                    radius,
                    corner_radius,
                })
            }
            _ => Err(CutterSpecError::Form(spec.to_owned())),
        }
    }
}

impl fmt::Display for CutterShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            CutterShape::Ball { radius } => write!(f, "ball:{}", 2.0 * radius),
            CutterShape::Flat { radius } => write!(f, "flat:{}", 2.0 * radius),
            CutterShape::BullNose {
                radius,
                corner_radius,
            } => write!(f, "bull:{}:{}", 2.0 * radius, corner_radius),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_print_back() {
        for spec in ["ball:6", "flat:10", "bull:12:2"] {
            let shape: CutterShape = spec.parse().unwrap();
            assert_eq!(shape.to_string(), spec);
        }
        let bull: CutterShape = "bull:12:2".parse().unwrap();
        assert_eq!((bull.radius(), bull.corner_radius()), (6.0, 2.0));
        assert_eq!(
            "ball:6".parse::<CutterShape>().unwrap().corner_radius(),
            3.0
        );
    }

    #[test]
    fn bad_specs_are_refused() {
        for spec in [
            "ball", "ball:-1", "ball:x", "cone:6", "bull:6:3", "flat:6:1", "ball:inf",
        ] {
            assert!(spec.parse::<CutterShape>().is_err(), "{spec}");
        }
    }
}
