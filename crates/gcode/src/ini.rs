//! LinuxCNC INI files, as far as the interpreter reads them: `#<_ini[section]name>` parameters
//! (`[RS274NGC] INI_VARS`, on unless set to 0) and `[RS274NGC] SUBROUTINE_PATH`.
//!
//! The format is LinuxCNC's: `[SECTION]` headers, `NAME = VALUE` lines, `#` and `;` comment
//! lines. Names are looked up as LinuxCNC looks them up: the program's lower-cased
//! `#<_ini[vars]toolchange_x>` asks for `TOOLCHANGE_X` in `[VARS]`, upper case.

use std::collections::HashMap;

/// An INI file's `(SECTION, NAME) → value` entries.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IniFile {
    entries: HashMap<(String, String), String>,
}

/// A line of an INI file that is neither a section, an entry nor a comment.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: expected [SECTION] or NAME = VALUE, found {text:?}")]
pub struct IniError {
    /// 1-based line number.
    pub line: usize,
    pub text: String,
}

impl IniFile {
    pub fn parse(text: &str) -> Result<IniFile, IniError> {
        let mut entries = HashMap::new();
        let mut section = String::new();
        for (k, raw) in text.lines().enumerate() {
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with(';') {
                continue;
            }
            if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                section = name.trim().to_string();
                continue;
            }
            let Some((name, value)) = line.split_once('=') else {
                return Err(IniError {
                    line: k + 1,
                    text: raw.to_string(),
                });
            };
            // The first entry of a name counts, as LinuxCNC's `IniFile::Find` returns it.
            entries
                .entry((section.clone(), name.trim().to_string()))
                .or_insert_with(|| value.trim().to_string());
        }
        Ok(IniFile { entries })
    }

    /// The text of `name` in `[section]`, exactly as written there.
    pub fn get(&self, section: &str, name: &str) -> Option<&str> {
        self.entries
            .get(&(section.to_string(), name.to_string()))
            .map(String::as_str)
    }

    /// A yes/no entry, read as LinuxCNC's `IniFile::Find(bool*)` reads it (`0`, `false`,
    /// `no` and `off` are false; any other value is true).
    pub fn flag(&self, section: &str, name: &str) -> Option<bool> {
        let v = self.get(section, name)?.to_ascii_lowercase();
        Some(!matches!(v.as_str(), "0" | "false" | "no" | "off"))
    }

    /// Whether `#<_ini[…]…>` parameters are on (`[RS274NGC] INI_VARS`, default on).
    pub fn ini_vars(&self) -> bool {
        self.flag("RS274NGC", "INI_VARS").unwrap_or(true)
    }

    /// Whether Fanuc-style subprograms (bare `O<n>`, M98, M99) are refused
    /// (`[RS274NGC] DISABLE_FANUC_STYLE_SUB`, default off).
    pub fn fanuc_subs_disabled(&self) -> bool {
        self.flag("RS274NGC", "DISABLE_FANUC_STYLE_SUB")
            .unwrap_or(false)
    }

    /// The folders of `[RS274NGC] SUBROUTINE_PATH` (colon-separated), as written.
    pub fn subroutine_path(&self) -> Vec<&str> {
        self.get("RS274NGC", "SUBROUTINE_PATH")
            .map(|p| p.split(':').filter(|d| !d.is_empty()).collect())
            .unwrap_or_default()
    }

    /// The value of the parameter `_ini[section]name` (lower case, as the reader gives
    /// names), if the file has that entry and it is a number.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        let rest = name.strip_prefix("_ini[")?;
        let (section, key) = rest.split_once(']')?;
        if section.is_empty() || key.is_empty() {
            return None;
        }
        self.get(&section.to_ascii_uppercase(), &key.to_ascii_uppercase())?
            .parse()
            .ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str =
        "[EMC]\nDEBUG=0\n\n[RS274NGC]\nINI_VARS = 1\nSUBROUTINE_PATH = subs:../lib\n\
        # a comment\n; another\n[VARS]\nTOOLCHANGE_X = 10\nTOOLCHANGE_Y=-2.5\nNAME = text\n";

    #[test]
    fn parameters_are_looked_up_in_upper_case() {
        let ini = IniFile::parse(TEXT).unwrap();
        assert_eq!(ini.parameter("_ini[vars]toolchange_x"), Some(10.0));
        assert_eq!(ini.parameter("_ini[vars]toolchange_y"), Some(-2.5));
        assert_eq!(ini.parameter("_ini[vars]name"), None, "not a number");
        assert_eq!(ini.parameter("_ini[nosuch]toolchange_x"), None);
        assert_eq!(ini.parameter("_ini[vars]"), None);
        assert_eq!(ini.parameter("_x"), None);
        assert!(ini.ini_vars());
        assert_eq!(ini.subroutine_path(), ["subs", "../lib"]);
    }

    #[test]
    fn ini_vars_can_be_turned_off_and_bad_lines_are_named() {
        let ini = IniFile::parse("[RS274NGC]\nINI_VARS = 0\n").unwrap();
        assert!(!ini.ini_vars());
        let err = IniFile::parse("[A]\nX = 1\nnot an entry\n").unwrap_err();
        assert_eq!(err.line, 3);
    }
}
