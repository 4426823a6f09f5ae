//! Length units (ISO 10303-41): the file's `LENGTH_UNIT` — an `SI_UNIT` with a prefix or a
//! `CONVERSION_BASED_UNIT` such as the inch — as millimetres per file unit, so that every
//! coordinate is scaled to tezgah's mm as it is read.

use super::entity::{Entity, Resolve};
use super::error::StepError;
use super::exchange::{Exchange, Param};

/// Conversion chains (inch → mm → …) longer than this are refused, which also ends a
/// reference cycle in a hostile file.
const MAX_CHAIN: usize = 8;

/// The length unit of the file's geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct LengthUnit {
    /// As the file names it: `MILLI METRE`, `METRE`, `INCH`, … (`mm (assumed)` when the file
    /// assigns none).
    pub name: String,
    /// Millimetres per unit of the file's coordinates.
    pub mm: f64,
}

impl LengthUnit {
    pub fn millimetre_assumed() -> Self {
        LengthUnit {
            name: "mm (assumed)".to_string(),
            mm: 1.0,
        }
    }
}

/// What a unit measures: the partial type that marks it, the SI base unit's name and its size
/// in tezgah's unit (mm, rad).
#[derive(Clone, Copy)]
struct Kind {
    marker: &'static str,
    si_name: &'static str,
    base: f64,
}

const LENGTH: Kind = Kind {
    marker: "LENGTH_UNIT",
    si_name: "METRE",
    base: 1000.0,
};
const PLANE_ANGLE: Kind = Kind {
    marker: "PLANE_ANGLE_UNIT",
    si_name: "RADIAN",
    base: 1.0,
};

/// Radians per unit of the file's plane angles (cone semi-angles, angle parameters): the
/// `PLANE_ANGLE_UNIT` of the unit contexts (radian when none; OpenCascade and most writers
/// use radians).
pub(crate) fn plane_angle(ex: &Exchange) -> Result<f64, StepError> {
    Ok(unit_of(ex, PLANE_ANGLE)?.map_or(1.0, |u| u.mm))
}

/// The length unit of every `GLOBAL_UNIT_ASSIGNED_CONTEXT` in the file; several contexts
/// must agree (tezgah reads one part, not an assembly with parts in different units).
pub(crate) fn length_unit(ex: &Exchange) -> Result<LengthUnit, StepError> {
    Ok(unit_of(ex, LENGTH)?.unwrap_or_else(LengthUnit::millimetre_assumed))
}

/// The unit of `kind` the contexts assign, as a `LengthUnit` (name and size in mm or rad).
fn unit_of(ex: &Exchange, kind: Kind) -> Result<Option<LengthUnit>, StepError> {
    let mut found: Option<LengthUnit> = None;
    for id in ex.ids() {
        let Some(context) = ex.entity(id) else {
            continue;
        };
        if !context.instance.has("GLOBAL_UNIT_ASSIGNED_CONTEXT") {
            continue;
        }
        let units = context.part("GLOBAL_UNIT_ASSIGNED_CONTEXT")?;
        for unit in units.refs(0, "units")? {
            let u = ex.get(unit, &units)?;
            if !u.instance.has(kind.marker) {
                continue;
            }
            let this = unit_mm(ex, &u, kind, 0)?;
            match &found {
                Some(f) if (f.mm - this.mm).abs() > 1e-12 * f.mm => {
                    return Err(StepError::MixedUnits {
                        first: f.name.clone(),
                        second: this.name,
                    })
                }
                Some(_) => {}
                None => found = Some(this),
            }
        }
    }
    Ok(found)
}

/// Millimetres (radians) per `unit`, an instance with a `LENGTH_UNIT` (`PLANE_ANGLE_UNIT`)
/// part.
fn unit_mm(
    ex: &Exchange,
    unit: &Entity<'_>,
    kind: Kind,
    depth: usize,
) -> Result<LengthUnit, StepError> {
    if depth > MAX_CHAIN {
        return Err(unit.invalid(format!("unit conversions chained deeper than {MAX_CHAIN}")));
    }
    if unit.instance.has("SI_UNIT") {
        let si = unit.part("SI_UNIT")?;
        // SI_UNIT(prefix, name); a simple instance may carry a leading dimensions attribute.
        let n = si.record.params.len();
        let (prefix, name) = (
            si.param(n.saturating_sub(2), "prefix")?,
            si.param(n.saturating_sub(1), "name")?,
        );
        let name = match name {
            Param::Enum(e) => e.as_str(),
            _ => return Err(si.invalid("SI unit name must be an enumeration")),
        };
        if name != kind.si_name {
            let what = if kind.si_name == "METRE" {
                "length"
            } else {
                "plane angle"
            };
            return Err(si.invalid(format!("{what} unit .{name}. is not a {what}")));
        }
        let (prefix_name, scale) = match prefix {
            Param::Unset => ("", 1.0),
            Param::Enum(p) => (
                p.as_str(),
                si_prefix(p).ok_or_else(|| si.invalid(format!("unknown SI prefix .{p}.")))?,
            ),
            _ => return Err(si.invalid("SI prefix must be an enumeration or $")),
        };
        let label = if prefix_name.is_empty() {
            kind.si_name.to_string()
        } else {
            format!("{prefix_name} {}", kind.si_name)
        };
        return Ok(LengthUnit {
            name: label,
            mm: kind.base * scale,
        });
    }
    if unit.instance.has("CONVERSION_BASED_UNIT") {
        let cbu = unit.part("CONVERSION_BASED_UNIT")?;
        let label = match cbu.param(0, "name")? {
            Param::String(s) => s.clone(),
            _ => String::new(),
        };
        let measure = ex.get(cbu.reference(1, "conversion factor")?, &cbu)?;
        // LENGTH_MEASURE_WITH_UNIT / MEASURE_WITH_UNIT(value_component, unit_component),
        // simple or the MEASURE_WITH_UNIT part of a complex instance.
        let m = if measure.instance.has("MEASURE_WITH_UNIT") {
            measure.part("MEASURE_WITH_UNIT")?
        } else {
            measure
        };
        let value = m.real(0, "value component")?;
        let base = ex.get(m.reference(1, "unit component")?, &m)?;
        let base_mm = unit_mm(ex, &base, kind, depth + 1)?.mm;
        let mm = value * base_mm;
        if !(mm.is_finite() && mm > 0.0) {
            return Err(cbu.invalid(format!("conversion factor gives {mm} mm per unit")));
        }
        return Ok(LengthUnit { name: label, mm });
    }
    Err(StepError::Unsupported {
        at: unit.at(),
        role: format!("a {}", kind.marker.to_ascii_lowercase().replace('_', " ")),
    })
}

/// ISO 10303-41 `si_prefix`, as powers of ten.
fn si_prefix(p: &str) -> Option<f64> {
    Some(match p {
        "EXA" => 1e18,
        "PETA" => 1e15,
        "TERA" => 1e12,
        "GIGA" => 1e9,
        "MEGA" => 1e6,
        "KILO" => 1e3,
        "HECTO" => 1e2,
        "DECA" => 1e1,
        "DECI" => 1e-1,
        "CENTI" => 1e-2,
        "MILLI" => 1e-3,
        "MICRO" => 1e-6,
        "NANO" => 1e-9,
        "PICO" => 1e-12,
        "FEMTO" => 1e-15,
        "ATTO" => 1e-18,
        _ => return None,
    })
}
