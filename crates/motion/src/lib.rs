//! tezgah-motion: path building, jerk-limited feed planning and interpolation.
//!
//! Consumes `tezgah_geom::Move`s (from G-code, CAM or MDI) and produces timed samples. So far it
//! holds the time-optimal jerk-limited 1-D [`profile`] along a path; look-ahead, interpolation
//! and the run loop build on it.

pub mod path;
pub mod profile;

pub use path::{Junction, PathItem, Segment, SegmentFeed};
pub use profile::{solve, Limits, Profile, ProfileError, State};
