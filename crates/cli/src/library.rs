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

impl Folders {
    /// The file that defines subroutine `name`: `<name>.ngc` in the first folder that has it.
    pub fn locate(&self, name: &str) -> Option<PathBuf> {
        self.0
            .iter()
            .map(|dir| dir.join(format!("{name}.ngc")))
            .find(|path| path.is_file())
    }
}

impl SubroutineLibrary for Folders {
    fn source(&self, name: &str) -> Option<String> {
        let bytes = std::fs::read(self.locate(name)?).ok()?;
        Some(String::from_utf8_lossy(&bytes).into_owned())
    }

    fn path(&self, name: &str) -> Option<PathBuf> {
        self.locate(name)
    }
}

/// The subroutine library, INI file and parameter file of a program.
pub struct ProgramInputs {
    pub subroutines: Option<Arc<dyn SubroutineLibrary>>,
    /// The same folders, to name the file a subroutine was read from.
    pub folders: Option<Arc<Folders>>,
    pub ini: Option<Arc<IniFile>>,
    pub parameters: Option<Arc<ParameterFile>>,
}

/// The text of a file; bytes that are not UTF-8 become U+FFFD (G-code is ASCII; a stray byte
/// in a comment should not refuse the file).
pub fn read_text(path: &Path) -> Result<String> {
    std::fs::read(path)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot read {}", path.display()))
        .map(|bytes| {
            // Valid UTF-8 (nearly every program) is taken as it is: the lossy conversion's
            // chunked scan costs ten times the validation on a multi-megabyte program.
            String::from_utf8(bytes)
                .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned())
        })
}

/// Writes a report as pretty JSON with a final newline.
pub fn write_json(path: &Path, json: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(json).into_diagnostic()? + "\n";
    std::fs::write(path, text)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", path.display()))
}

/// The tool table at `path` (LinuxCNC's format), or an empty one without a path.
pub fn load_tool_table(path: Option<&Path>) -> Result<tezgah_gcode::ToolTable> {
    let Some(path) = path else {
        return Ok(tezgah_gcode::ToolTable::default());
    };
    tezgah_gcode::ToolTable::parse(&read_text(path)?)
        .into_diagnostic()
        .wrap_err_with(|| format!("in {}", path.display()))
}

/// Read a LinuxCNC parameter file (`.var`).
pub fn load_parameters(path: Option<&Path>) -> Result<Option<Arc<ParameterFile>>> {
    let Some(path) = path else { return Ok(None) };
    let file = ParameterFile::parse(&read_text(path)?)
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
            let file = IniFile::parse(&read_text(path)?)
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
    let folders = (!dirs.is_empty()).then(|| Arc::new(Folders(dirs)));
    Ok(ProgramInputs {
        subroutines: folders.clone().map(|f| f as Arc<dyn SubroutineLibrary>),
        folders,
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

/// What a program may read besides its own text.
#[derive(clap::Args)]
pub struct Inputs {
    /// A tool table in LinuxCNC's format.
    #[arg(long)]
    pub tool_table: Option<PathBuf>,
    /// A folder of subroutine files `<name>.ngc` (repeatable; the program's folder first).
    #[arg(long = "subroutine-path")]
    pub subroutine_path: Vec<PathBuf>,
    /// A LinuxCNC INI file: its `[RS274NGC] SUBROUTINE_PATH` and `#<_ini[section]name>` values.
    #[arg(long)]
    pub ini: Option<PathBuf>,
    /// A LinuxCNC parameter file (`.var`): the work offsets, G92 offsets and other numbered
    /// parameters the program starts with.
    #[arg(long)]
    pub params: Option<PathBuf>,
}

impl ProgramInputs {
    /// Where subroutine `name` was read from, for reports.
    pub fn locate(&self, name: &str) -> Option<PathBuf> {
        self.folders.as_ref()?.locate(name)
    }
}

impl Inputs {
    pub fn program_inputs(&self, program: Option<&Path>) -> Result<ProgramInputs> {
        program_inputs(
            program,
            self.ini.as_deref(),
            self.params.as_deref(),
            &self.subroutine_path,
        )
    }
}
