//! Subroutine files for `o<name> call`: `<name>.ngc` looked up in the program's folder and in
//! the folders given with `--subroutine-path`, in that order (LinuxCNC's SUBROUTINE_PATH).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use tezgah_gcode::interp::SubroutineLibrary;

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

/// The library for `program` (if read from a file) and the extra folders.
pub fn folders(program: Option<&Path>, extra: &[PathBuf]) -> Option<Arc<dyn SubroutineLibrary>> {
    let own = program.and_then(Path::parent).map(|p| {
        if p.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            p.to_path_buf()
        }
    });
    let dirs: Vec<PathBuf> = own.into_iter().chain(extra.iter().cloned()).collect();
    (!dirs.is_empty()).then(|| Arc::new(Folders(dirs)) as Arc<dyn SubroutineLibrary>)
}
