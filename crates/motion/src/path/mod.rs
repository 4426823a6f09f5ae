//! The path stage: typed moves in, a sequence of timed-to-be [`Segment`]s out.
//!
//! The interpreter (or CAM, or MDI) gives `tezgah_geom::Move`s; the path stage turns them into
//! segments of the tool-tip path with their feed and junction kinds, smoothing where the
//! program allows. The feed planner reads only this module's types, never G-code.

pub mod direct;
pub mod orient;
pub mod segment;

pub use segment::{Junction, PathItem, Segment, SegmentFeed};
pub mod deviation;
pub mod smooth;

pub use deviation::deviation;
