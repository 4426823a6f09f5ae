//! tezgah-geom: the geometric vocabulary shared by every stage of tezgah.
//!
//! It sits at the bottom of the crate stack: the G-code interpreter emits [`Move`]s built from
//! these types, and the planner, kinematics and CAM consume them without knowing about G-code.

pub mod moves;
pub mod pose;

pub use moves::{ArcMove, FeedMode, Move, MoveKind, PathMode, Plane, StopKind, Turn};
pub use pose::{Axis, Pose};
