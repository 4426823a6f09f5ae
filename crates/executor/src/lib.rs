//! tezgah-executor: the real-time loop, operating modes and drives.
//!
//! Takes timed samples from tezgah-motion and hands one set-point per period to a drive. It
//! grows with the executor issue; for now it holds nothing.
