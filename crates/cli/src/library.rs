//! What a program reads besides its own text: subroutine files for `o<name> call`
//! (`<name>.ngc` looked up in the program's folder, then in the INI file's `SUBROUTINE_PATH`,
//! then in the folders given with `--subroutine-path`, as LinuxCNC's SUBROUTINE_PATH) and the
//! INI file's `#<_ini[section]name>` values.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use miette::{IntoDiagnostic, Result, WrapErr};
use tezgah_gcode::interp::SubroutineLibrary;
use tezgah_gcode::params::ParameterFile;
use tezgah_gcode::IniFile;

#[derive(Debug)]
pub struct Folders(Vec<PathBuf>);

impl SubroutineLibrary for Folders {
    fn source(&self, name: &str) -> Option<String> {
        self.0
            .iter()
            .find_map(|dir| std::fs::read(dir.join(format!("{name}.ngc"))).ok())
            .map(|bytes| String::from_utf8_lossy(&bytes).into_owned())
    }
}

/// The subroutine library, INI file and parameter file of a program.
pub struct ProgramInputs {
    pub subroutines: Option<Arc<dyn SubroutineLibrary>>,
    pub ini: Option<Arc<IniFile>>,
    pub parameters: Option<Arc<ParameterFile>>,
}

/// Read a LinuxCNC parameter file (`.var`).
/// The tool table at `path` (LinuxCNC's format), or an empty one without a path.
pub fn load_tool_table(path: Option<&Path>) -> Result<tezgah_gcode::ToolTable> {
    let Some(path) = path else {
        return Ok(tezgah_gcode::ToolTable::default());
    };
    let bytes = std::fs::read(path)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot read {}", path.display()))?;
    tezgah_gcode::ToolTable::parse(&String::from_utf8_lossy(&bytes))
        .into_diagnostic()
        .wrap_err_with(|| format!("in {}", path.display()))
}

pub fn load_parameters(path: Option<&Path>) -> Result<Option<Arc<ParameterFile>>> {
    let Some(path) = path else { return Ok(None) };
    let text = std::fs::read_to_string(path)
        .into_diagnostic()
        .wrap_err_with(|| format!("reading {}", path.display()))?;
    let file = ParameterFile::parse(&text)
        .into_diagnostic()
        .wrap_err_with(|| format!("in {}", path.display()))?;
    Ok(Some(Arc::new(file)))
}

/// The inputs of `program` (if read from a file), with the INI file and extra folders given.
pub fn program_inputs(
    program: Option<&Path>,
    ini: Option<&Path>,
    parameters: Option<&Path>,
    extra: &[PathBuf],
) -> Result<ProgramInputs> {
    let ini = match ini {
        None => None,
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .into_diagnostic()
                .wrap_err_with(|| format!("reading {}", path.display()))?;
            let file = IniFile::parse(&text)
                .into_diagnostic()
                .wrap_err_with(|| format!("in {}", path.display()))?;
            Some((folder_of(path), Arc::new(file)))
        }
    };
    let own = program.map(folder_of);
    let from_ini = ini.iter().flat_map(|(dir, file)| {
        file.subroutine_path()
            .into_iter()
            .map(|d| dir.join(d))
            .collect::<Vec<_>>()
    });
    let dirs: Vec<PathBuf> = own
        .into_iter()
        .chain(from_ini)
        .chain(extra.iter().cloned())
        .collect();
    Ok(ProgramInputs {
        subroutines: (!dirs.is_empty())
            .then(|| Arc::new(Folders(dirs)) as Arc<dyn SubroutineLibrary>),
        ini: ini.map(|(_, file)| file),
        parameters: load_parameters(parameters)?,
    })
}

/// The folder a file is in (`.` for a bare file name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}
