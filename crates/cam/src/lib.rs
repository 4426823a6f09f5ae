//! tezgah-cam: from STEP surfaces to 5-axis finishing tool paths and post-processed G-code.
//!
//! It sits beside the G-code interpreter as a second source of moves: surfaces come in
//! (`tezgah-geom`'s `NurbsSurface`), a strategy places the [`Cutter`] along them as a
//! [`ToolPath`], the post-processor ([`post`]) turns that into G-code for a table-tilting
//! machine, and the dexel simulation ([`verify`]) measures scallop and gouge independently.

pub mod cutter;
pub mod post;
pub mod toolpath;
pub mod verify;

pub use cutter::{Cutter, CutterShape, CutterSpecError, Cylinder};
pub use toolpath::{CutterLocation, Pass, ToolPath};
