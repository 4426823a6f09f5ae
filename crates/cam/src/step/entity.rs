//! Typed views of entity instances: attribute access by position with errors that name the
//! instance (`#id TYPE (line n)`) and the attribute, and reference resolution that reports
//! dangling `#id`s. The geometry and topology mappers read the exchange through these.

use super::error::{At, StepError};
use super::exchange::{Exchange, Instance, Param, Record};

/// One record of one instance: the whole of a simple instance, or a named partial type of a
/// complex one (whose attributes are only that partial type's own).
#[derive(Clone, Copy)]
pub(crate) struct Entity<'a> {
    pub id: u64,
    pub instance: &'a Instance,
    pub record: &'a Record,
}

impl<'a> Entity<'a> {
    pub fn at(&self) -> At {
        At {
            id: self.id,
            entity: self.instance.type_name(),
            line: self.instance.line,
        }
    }

    pub fn name(&self) -> &'a str {
        &self.record.name
    }

    pub fn invalid(&self, message: impl Into<String>) -> StepError {
        StepError::Invalid {
            at: self.at(),
            message: message.into(),
        }
    }

    /// The same instance's partial record `name` (complex instances).
    pub fn part(&self, name: &str) -> Result<Entity<'a>, StepError> {
        self.instance
            .record(name)
            .map(|record| Entity {
                id: self.id,
                instance: self.instance,
                record,
            })
            .ok_or_else(|| self.invalid(format!("has no {name} part")))
    }

    pub fn param(&self, i: usize, what: &str) -> Result<&'a Param, StepError> {
        self.record.params.get(i).ok_or_else(|| {
            self.invalid(format!(
                "{} has {} attributes, {what} (attribute {}) is missing",
                self.record.name,
                self.record.params.len(),
                i + 1
            ))
        })
    }

    fn wrong(&self, i: usize, what: &str, expected: &str) -> StepError {
        self.invalid(format!("{what} (attribute {}) must be {expected}", i + 1))
    }

    pub fn real(&self, i: usize, what: &str) -> Result<f64, StepError> {
        real_of(self.param(i, what)?).ok_or_else(|| self.wrong(i, what, "a number"))
    }

    pub fn int(&self, i: usize, what: &str) -> Result<i64, StepError> {
        match self.param(i, what)? {
            Param::Integer(v) => Ok(*v),
            _ => Err(self.wrong(i, what, "an integer")),
        }
    }

    /// A count or degree: a non-negative integer that fits `usize`.
    pub fn count(&self, i: usize, what: &str) -> Result<usize, StepError> {
        usize::try_from(self.int(i, what)?).map_err(|_| self.wrong(i, what, "≥ 0"))
    }

    /// `.T.` / `.F.` (BOOLEAN or LOGICAL; `.U.` is refused where a decision hangs on it).
    pub fn boolean(&self, i: usize, what: &str) -> Result<bool, StepError> {
        match self.param(i, what)? {
            Param::Enum(e) if e == "T" => Ok(true),
            Param::Enum(e) if e == "F" => Ok(false),
            _ => Err(self.wrong(i, what, ".T. or .F.")),
        }
    }

    pub fn reference(&self, i: usize, what: &str) -> Result<u64, StepError> {
        match self.param(i, what)? {
            Param::Ref(id) => Ok(*id),
            _ => Err(self.wrong(i, what, "a reference #id")),
        }
    }

    pub fn list(&self, i: usize, what: &str) -> Result<&'a [Param], StepError> {
        match self.param(i, what)? {
            Param::List(items) => Ok(items),
            _ => Err(self.wrong(i, what, "a list")),
        }
    }

    pub fn refs(&self, i: usize, what: &str) -> Result<Vec<u64>, StepError> {
        self.list(i, what)?
            .iter()
            .map(|p| match p {
                Param::Ref(id) => Ok(*id),
                _ => Err(self.wrong(i, what, "a list of references")),
            })
            .collect()
    }

    pub fn reals(&self, i: usize, what: &str) -> Result<Vec<f64>, StepError> {
        self.list(i, what)?
            .iter()
            .map(|p| real_of(p).ok_or_else(|| self.wrong(i, what, "a list of numbers")))
            .collect()
    }

    pub fn counts(&self, i: usize, what: &str) -> Result<Vec<usize>, StepError> {
        self.list(i, what)?
            .iter()
            .map(|p| match p {
                Param::Integer(v) => usize::try_from(*v).ok(),
                _ => None,
            })
            .map(|v| v.ok_or_else(|| self.wrong(i, what, "a list of integers ≥ 0")))
            .collect()
    }
}

/// A number, also when written as an integer or wrapped in a measure type.
pub(crate) fn real_of(p: &Param) -> Option<f64> {
    match p {
        Param::Real(v) => Some(*v),
        Param::Integer(v) => Some(*v as f64),
        Param::Typed(_, inner) => real_of(inner),
        _ => None,
    }
}

/// Resolution of `#id`s against the exchange.
pub(crate) trait Resolve {
    /// The instance `target`, referenced from `from`; its first (simple: only) record.
    fn get<'a>(&'a self, target: u64, from: &Entity<'_>) -> Result<Entity<'a>, StepError>;
    /// Any instance by name, for walks that do not start from a reference.
    fn entity(&self, id: u64) -> Option<Entity<'_>>;
}

impl Resolve for Exchange {
    fn get<'a>(&'a self, target: u64, from: &Entity<'_>) -> Result<Entity<'a>, StepError> {
        self.entity(target).ok_or_else(|| StepError::Dangling {
            at: from.at(),
            target,
        })
    }

    fn entity(&self, id: u64) -> Option<Entity<'_>> {
        let instance = self.instances.get(&id)?;
        let record = instance.records.first()?;
        Some(Entity {
            id,
            instance,
            record,
        })
    }
}
