//! tezgah-motion: path building, jerk-limited feed planning and interpolation.
//!
//! Consumes `tezgah_geom::Move`s (from G-code, CAM or MDI) and produces timed samples. It grows
//! with the path and feed-planning issues; for now it holds nothing.
