//! Tool tables in LinuxCNC's format: one tool per line, `T<n> P<pocket> Z<offset> D<diam> ;text`.
//!
//! The interpreter takes tool length offsets (G43) and diameters (cutter compensation) from it.
//! Offsets are in the table's units, which the interpreter takes to be the program's units, as
//! LinuxCNC's standalone interpreter does.

use std::collections::BTreeMap;

use tezgah_geom::{Axis, Pose};

/// One tool.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Tool {
    pub number: i64,
    /// 1-based row of the tool in its table: LinuxCNC's pocket index in canonical calls.
    pub row: usize,
    pub pocket: i64,
    /// Offsets along X Y Z A B C (Z is the tool length).
    pub offset: Pose,
    pub diameter: f64,
    /// Lathe tool angles (degrees) and orientation (0–9), kept to be written back.
    pub front_angle: f64,
    pub back_angle: f64,
    pub orientation: i32,
    pub comment: String,
}

/// An error in a tool table: the 1-based line and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("tool table line {line}: {message}")]
pub struct ToolTableError {
    pub line: usize,
    pub message: String,
}

/// Tools by number.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ToolTable {
    tools: BTreeMap<i64, Tool>,
}

impl ToolTable {
    pub fn get(&self, number: i64) -> Option<&Tool> {
        self.tools.get(&number)
    }

    pub fn get_mut(&mut self, number: i64) -> Option<&mut Tool> {
        self.tools.get_mut(&number)
    }

    /// The tools in order of their numbers.
    pub fn iter(&self) -> impl Iterator<Item = &Tool> {
        self.tools.values()
    }

    pub fn insert(&mut self, tool: Tool) {
        self.tools.insert(tool.number, tool);
    }

    pub fn len(&self) -> usize {
        self.tools.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tools.is_empty()
    }

    /// Read a table. Every line names its tool with `T`; other fields are optional.
    pub fn parse(text: &str) -> Result<ToolTable, ToolTableError> {
        let mut table = ToolTable::default();
        for (i, raw) in text.lines().enumerate() {
            let err = |message: String| ToolTableError {
                line: i + 1,
                message,
            };
            let (fields, comment) = raw.split_once(';').unwrap_or((raw, ""));
            if fields.trim().is_empty() {
                continue;
            }
            let mut tool = Tool {
                comment: comment.trim().to_string(),
                number: -1,
                ..Tool::default()
            };
            for field in fields.split_whitespace() {
                let mut chars = field.chars();
                let letter = chars.next().unwrap_or(' ').to_ascii_uppercase();
                let value: f64 = chars
                    .as_str()
                    .parse()
                    .map_err(|_| err(format!("bad number in field '{field}'")))?;
                let axis = |a: Axis| a.index();
                match letter {
                    'T' | 'P' => {
                        if value.fract() != 0.0 || value < 0.0 {
                            return Err(err(format!("'{field}' is not a tool or pocket number")));
                        }
                        if letter == 'T' {
                            tool.number = value as i64;
                        } else {
                            tool.pocket = value as i64;
                        }
                    }
                    'X' => tool.offset.0[axis(Axis::X)] = value,
                    'Y' => tool.offset.0[axis(Axis::Y)] = value,
                    'Z' => tool.offset.0[axis(Axis::Z)] = value,
                    'A' => tool.offset.0[axis(Axis::A)] = value,
                    'B' => tool.offset.0[axis(Axis::B)] = value,
                    'C' => tool.offset.0[axis(Axis::C)] = value,
                    'D' => tool.diameter = value,
                    'I' => tool.front_angle = value,
                    'J' => tool.back_angle = value,
                    'Q' => tool.orientation = value as i32,
                    // U V W offsets are read and not used.
                    'U' | 'V' | 'W' => {}
                    _ => return Err(err(format!("unknown field '{field}'"))),
                }
            }
            if tool.number < 0 {
                return Err(err("no T word".to_string()));
            }
            tool.row = table.len() + 1;
            table.insert(tool);
        }
        Ok(table)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_linuxcnc_sample() {
        let t = ToolTable::parse(
            "T1 P1 D0.125000 Z+0.511000 ;1/8 end mill\n\nT99999 P123     Z+0.100000 ;big tool number\n",
        )
        .unwrap();
        assert_eq!(t.len(), 2);
        let t1 = t.get(1).unwrap();
        assert_eq!(t1.offset.z(), 0.511);
        assert_eq!(t1.diameter, 0.125);
        assert_eq!(t1.comment, "1/8 end mill");
        assert_eq!(t.get(99999).unwrap().pocket, 123);
        assert_eq!(t.get(99999).unwrap().row, 2);
    }

    #[test]
    fn errors_name_the_line() {
        let e = ToolTable::parse("T1 Z1\nT2 Zx\n").unwrap_err();
        assert_eq!(e.line, 2);
    }
}
