//! tezgah-kinematics: machine models that map program poses to joint positions and back.
//!
//! Sits between path planning and the joint set-points. This crate grows with the kinematics
//! issue (Cartesian, Y-Z-C-A, table-tilting 5-axis, linear delta); for now it holds nothing.
