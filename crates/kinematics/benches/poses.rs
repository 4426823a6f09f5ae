//! Poses along a smooth 5-axis-ish path that every built-in machine can reach, shared by the
//! inverse benchmark (`benches/inverse.rs`, wall time) and `examples/inverse_cpu.rs` (CPU time
//! of the thread, steadier on a shared machine).

use nalgebra::Vector3;
use tezgah_kinematics::{Kinematics, Machine, Tool, ToolPose};

pub const BATCH: usize = 1024;

/// Poses along a smooth 5-axis-ish path that every built-in machine can reach.
pub fn poses(machine: &Machine, tool: &Tool) -> Vec<ToolPose> {
    let k = &machine.kinematics;
    let mut q = machine.home();
    (0..BATCH)
        .map(|i| {
            let t = i as f64 / BATCH as f64 * std::f64::consts::TAU;
            let mut v = machine.to_file_units(&q);
            match machine.name.as_str() {
                "linear-delta" => {
                    // a 60 mm circle at z = −20 via the inverse itself
                    let p = ToolPose::vertical(Vector3::new(60.0 * t.cos(), 60.0 * t.sin(), -20.0));
                    q = k.inverse(&p, tool, &q).unwrap();
                    return p;
                }
                "yzca" => v.copy_from_slice(&[
                    40.0 + 10.0 * t.sin(),
                    5.0 * t.cos(),
                    360.0 * t / 3.0,
                    30.0 * t.sin(),
                ]),
                "mill3" => v.copy_from_slice(&[50.0 * t.cos(), 50.0 * t.sin(), -5.0]),
                _ => v.copy_from_slice(&[
                    30.0 * t.cos(),
                    20.0 * t.sin(),
                    -10.0,
                    10.0 + 40.0 * (1.0 + t.sin()),
                    2.0 * t.to_degrees(),
                ]),
            }
            q = machine.from_file_units(&v).unwrap();
            k.forward(&q, tool).unwrap()
        })
        .collect()
}
