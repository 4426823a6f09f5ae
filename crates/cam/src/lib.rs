//! tezgah-cam: from STEP surfaces to 5-axis finishing tool paths and post-processed G-code.
//!
//! It sits beside the G-code interpreter as a second source of moves: surfaces come in
//! (`tezgah-geom`'s `NurbsSurface`), a strategy places the [`Cutter`] along them as a
//! [`ToolPath`], and the post-processor turns that into G-code for a table-tilting machine.

pub mod cutter;
pub mod step;
pub mod toolpath;

pub use cutter::{Cutter, CutterShape, CutterSpecError, Cylinder};
pub use toolpath::{CutterLocation, Pass, ToolPath};
