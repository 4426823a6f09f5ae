//! tezgah-motion: path building, jerk-limited feed planning and interpolation.
//!
//! Consumes `tezgah_geom::Move`s (from G-code, CAM or MDI) and produces timed samples. Stages:
//! [`path`] (moves → segments), [`takeup`] (the joint move at a tool-centre-point switch),
//! [`preflight`] (every segment's joints within reach and limits before anything moves),
//! [`prepare`] (a program's moves smoothed and pre-flighted for a machine, and its planned cycle time),
//! [`plan`] (speed limits, look-ahead, one [`profile`] per group of segments), [`interpolate`]
//! (samples at the period, joints by the kinematics under each segment's tool control;
//! [`cursor`] places the tool at any path coordinate of a piece, for the executor's re-timed
//! sampling) and
//! [`verify`] (the post-run replay) and [`tool_pose`] (each sample's tool tip and axis in the
//! workpiece frame, by forward kinematics).

pub mod cursor;
pub mod interpolate;
pub mod path;
pub mod plan;
pub mod preflight;
pub mod prepare;
pub mod profile;
pub mod takeup;
pub mod tool_pose;
pub mod verify;

pub use path::{Junction, PathItem, Segment, SegmentFeed};
pub use profile::{solve, Limits, Profile, ProfileError, State};
