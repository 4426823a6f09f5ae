//! tezgah-cam: from STEP surfaces to 5-axis finishing tool paths and post-processed G-code.
//!
//! It sits beside the G-code interpreter as a second source of moves: surfaces come in
//! (`tezgah-geom`'s `NurbsSurface`), a strategy places the [`Cutter`] along them as a
//! [`ToolPath`] ([`strategy::plan`] is the entry point), the post-processor ([`post`]) turns
//! that into G-code for a table-tilting machine, and the dexel simulation ([`verify`])
//! measures scallop and gouge independently.

pub mod arc_grid;
pub mod cutter;
pub mod effective_radius;
pub mod error;
pub mod forward_step;
pub mod gouge;
pub mod orientation;
pub mod post;
pub mod region;
pub mod scallop;
pub mod select;
pub mod silhouette;
pub mod step;
pub mod strategy;
#[doc(hidden)]
pub mod testing;
pub mod toolpath;
pub mod verify;

pub use cutter::{Cutter, CutterShape, CutterSpecError, Cylinder};
pub use effective_radius::LeadTilt;
pub use error::CamError;
pub use gouge::CheckFace;
pub use strategy::{
    plan, Band, FeedDirection, Plan, Settings, StrategyKind, ToleranceShares, ToolAxis,
};
pub use toolpath::{CutterLocation, Pass, ToolPath};
