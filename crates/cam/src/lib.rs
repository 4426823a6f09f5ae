//! tezgah-cam: from STEP surfaces to 5-axis finishing tool paths and post-processed G-code.
//!
//! It sits beside the G-code interpreter as a second source of moves. It grows with the CAM
//! issue; for now it holds nothing.
