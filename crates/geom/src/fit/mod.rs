//! Spline fitting: turns a run of points (the short G1 moves of CAM output, the thesis's
//! G05.1 groups) into one B-spline. [`interpolate`] passes through every point (Piegl &
//! Tiller A9.1); [`approximate`] is a least-squares fit that stays within a tolerance of every
//! point and segment, the one the path builder's compression uses.

mod approximate;
mod interpolate;
mod params;

pub use approximate::{approximate, Approximation};
pub use interpolate::interpolate;
pub use params::{averaged_knots, parameters, Parameterisation};
