//! A model's own part of the machine file. `[kinematics]` holds two keys the machine reads
//! (`type`, which picks the model, and `tcp`); every other key belongs to the model, which
//! declares them in its section struct (serde, unknown fields refused with their name, line and
//! column) and validates them against the machine's joints in [`FromSection::from_section`].
//! Each model's file implements it; nothing here knows a model's fields.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{
    value::MapAccessDeserializer, DeserializeOwned, DeserializeSeed, IgnoredAny, IntoDeserializer,
    MapAccess, Visitor,
};
use serde::{Deserialize, Deserializer};

use super::check::{invalid, positive, MachineError};
use super::joint::Joint;
use crate::error::KinematicsError;
use crate::kinematics::{Kinematics, Tolerances};
use crate::pose::{JointKind, JointLimit};

/// The `[kinematics]` keys the machine reads itself; a model's section never sees them.
const MACHINE_KEYS: [&str; 2] = ["type", "tcp"];

/// A kinematic model built from its `[kinematics]` section and the machine's joints.
pub(crate) trait FromSection: Kinematics + Sized {
    /// The model's `[kinematics]` fields, `#[serde(deny_unknown_fields)]`: a field the model
    /// must have is an `Option` checked with [`super::check::require`], so that its error
    /// names the field as `kinematics.<name>`.
    type Section: DeserializeOwned;

    /// The model for `section` and `joints` (validated, in file units). `kind` is the
    /// `kinematics.type` (one model may serve several: `table-ac`, `table-bc`).
    fn from_section(
        kind: &'static str,
        section: Self::Section,
        joints: &[Joint],
    ) -> Result<Self, MachineError>;
}

/// Reads `[kinematics]` of the machine file `text` as `M`'s section and builds `M`. The text
/// is read again (the machine's own pass has checked everything else) so that a bad field's
/// error keeps its line and column.
pub(crate) fn build<M: FromSection>(
    kind: &'static str,
    text: &str,
    joints: &[Joint],
) -> Result<M, MachineError> {
    let file: ModelFile<M::Section> = toml::from_str(text).map_err(|e| MachineError::Toml {
        // serde's "unknown field `x`, expected …" lists the model's fields: say which model.
        message: format!("{} (for type `{kind}`)", e.to_string().trim_end()),
    })?;
    M::from_section(kind, file.kinematics.0, joints)
}

/// The machine file as a model reads it: its section, every other table ignored.
#[derive(Deserialize)]
struct ModelFile<S> {
    kinematics: ModelFields<S>,
}

/// `[kinematics]` without [`MACHINE_KEYS`], read as `S`.
struct ModelFields<S>(S);

impl<'de, S: Deserialize<'de>> Deserialize<'de> for ModelFields<S> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(FieldsVisitor(PhantomData))
    }
}

struct FieldsVisitor<S>(PhantomData<S>);

impl<'de, S: Deserialize<'de>> Visitor<'de> for FieldsVisitor<S> {
    type Value = ModelFields<S>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("the [kinematics] table")
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        S::deserialize(MapAccessDeserializer::new(WithoutMachineKeys(map))).map(ModelFields)
    }
}

/// The table's entries with the machine's keys skipped.
struct WithoutMachineKeys<A>(A);

impl<'de, A: MapAccess<'de>> MapAccess<'de> for WithoutMachineKeys<A> {
    type Error = A::Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, A::Error> {
        while let Some(key) = self.0.next_key::<String>()? {
            if MACHINE_KEYS.contains(&key.as_str()) {
                self.0.next_value::<IgnoredAny>()?;
            } else {
                return seed
                    .deserialize(IntoDeserializer::<A::Error>::into_deserializer(key))
                    .map(Some);
            }
        }
        Ok(None)
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, A::Error> {
        self.0.next_value_seed(seed)
    }
}

/// The inverse kinematics' tolerances from a section's optional fields (degrees and mm),
/// each `None` the default of [`Tolerances`].
pub(crate) fn tolerances(
    axis_tolerance_deg: Option<f64>,
    pole_cone_deg: Option<f64>,
    centre_tolerance_mm: Option<f64>,
) -> Result<Tolerances, MachineError> {
    let d = Tolerances::default();
    let or = |field: &str, v: Option<f64>, default: f64| match v {
        Some(v) => positive(field, v),
        None => Ok(default),
    };
    Ok(Tolerances {
        axis_rad: or(
            "kinematics.axis_tolerance_deg",
            axis_tolerance_deg.map(f64::to_radians),
            d.axis_rad,
        )?,
        pole_cone_rad: or(
            "kinematics.pole_cone_deg",
            pole_cone_deg.map(f64::to_radians),
            d.pole_cone_rad,
        )?,
        centre_mm: or(
            "kinematics.centre_tolerance_mm",
            centre_tolerance_mm,
            d.centre_mm,
        )?,
    })
}

/// The joints' limits in internal units, the models' constructors' input.
pub(crate) fn limits(joints: &[Joint]) -> Vec<JointLimit> {
    joints.iter().map(Joint::limit).collect()
}

/// A model constructor's refusal as a field error of the section.
pub(crate) fn refused(field: &str) -> impl Fn(KinematicsError) -> MachineError + '_ {
    move |e| invalid(field, e.to_string())
}

/// The joints `kind` needs, in order: their number and whether each is linear or rotary.
pub(crate) fn check_joint_kinds(
    kind: &str,
    joints: &[Joint],
    expected: &[JointKind],
) -> Result<(), MachineError> {
    if joints.len() != expected.len() {
        return Err(invalid(
            "joint",
            format!(
                "{kind} needs {} joints, the file has {}",
                expected.len(),
                joints.len()
            ),
        ));
    }
    for (i, (j, e)) in joints.iter().zip(expected).enumerate() {
        if j.kind != *e {
            return Err(invalid(
                format!("joint[{i}].kind"),
                format!(
                    "{kind} needs a {} joint here",
                    if *e == JointKind::Linear {
                        "linear"
                    } else {
                        "rotary"
                    }
                ),
            ));
        }
    }
    Ok(())
}
