//! The two lock-free single-producer/single-consumer rings (`rtrb`) between the planner
//! thread and the real-time thread: set-points in, one report per period out. Both are
//! bounded and pre-allocated, so neither side allocates or locks when it pushes or pops.

use serde::Serialize;
use tezgah_kinematics::Joints;

use crate::drive::DriveFault;
use crate::setpoint::SetPoint;

/// What the planner thread sends the real-time thread.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Slot {
    /// The next period's set-point.
    Point(SetPoint),
    /// After an underrun or a fault the real-time thread discards set-points until this: the
    /// planner has seen the halt and starts again from the halted position.
    Rearm,
}

/// The real-time thread's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RtState {
    /// Taking set-points (or holding the last one at rest while none come).
    Running,
    /// Playing the jerk-limited stop after an underrun.
    Stopping,
    /// Stopped after an underrun or a drive fault; set-points are discarded until a
    /// [`Slot::Rearm`].
    Halted,
}

/// What the real-time thread reports every period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RtReport {
    /// Periods run since the loop started.
    pub period: u64,
    /// Index of the set-point applied this period (the producer's counter; idle periods and
    /// an extrapolated stop repeat the last one).
    pub index: u64,
    /// Source line of the set-point applied.
    pub line: u32,
    pub state: RtState,
    /// Commanded joints this period.
    pub commanded: Joints,
    /// Commanded velocity this period.
    pub velocity: Joints,
    /// Measured joints (the drive's answer).
    pub measured: Joints,
    pub underruns: u64,
    pub fault: Option<DriveFault>,
    /// The worst wake-up lateness of the real-time thread so far, s.
    pub late_worst: f64,
    /// Periods it woke more than half a period late.
    pub late_over_half: u64,
}

/// The producer ends (planner thread) and consumer ends (real-time thread) of both rings.
pub struct Rings {
    pub setpoints: rtrb::Producer<Slot>,
    pub reports: rtrb::Consumer<RtReport>,
}

/// The real-time thread's ends.
pub struct RtEnds {
    pub setpoints: rtrb::Consumer<Slot>,
    pub reports: rtrb::Producer<RtReport>,
}

/// Both rings: `capacity` set-points ahead (keep it short — a few tens of periods — so that
/// feed hold and override act within a few periods), `report_capacity` reports behind.
pub fn rings(capacity: usize, report_capacity: usize) -> (Rings, RtEnds) {
    let (sp, sc) = rtrb::RingBuffer::new(capacity.max(1));
    let (rp, rc) = rtrb::RingBuffer::new(report_capacity.max(1));
    (
        Rings {
            setpoints: sp,
            reports: rc,
        },
        RtEnds {
            setpoints: sc,
            reports: rp,
        },
    )
}
