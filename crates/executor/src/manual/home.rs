//! HOME: the homing sequence of the machine file (`[joint.home]`), joints in `sequence` order
//! (Z first by default, as Kelekçi, 2021, §4.1), joints of equal sequence together. Per joint:
//! search toward the switch at `search_velocity`, stop; back off at `latch_velocity` until the
//! switch releases, stop; approach again at `latch_velocity` and latch the position where it
//! trips, stop; then a rest-to-rest move to the home `position`. Every piece is jerk-limited (the
//! one profile solver: its velocity interface as JOG, its position interface for the last move) and starts at the exact instant
//! the previous one ended, so the set-points are one continuous jerk-limited motion.
//!
//! Before homing the controller does not know where the machine is: its positions are machine
//! positions plus an unknown offset (the power-on frame). Homing finds that offset: the latched
//! position minus the switch's machine position. Set-points stay in the power-on frame
//! throughout (the drive sees no jump); [`Home::offsets`] gives the offsets, and the last move
//! ends at `position + offset`, i.e. on the home position in machine coordinates. The switch is
//! read once per period, so the latch is late by at most `latch_velocity`·Ts — the reason the
//! latch is slow.

use tezgah_kinematics::pose::MAX_JOINTS;
use tezgah_kinematics::{Joints, Machine};
use tezgah_motion::profile::{solve, Limits, Profile, State};

use super::{check_start, JointAxis, ManualError};
use crate::setpoint::SetPoint;
use crate::stop::velocity_profile;

/// The home switches as the controller reads them, once per period.
pub trait HomeSwitches {
    /// Whether joint `joint`'s home switch is pressed with the joint commanded at `position`
    /// (a real input ignores the position; the simulation needs it).
    fn tripped(&self, joint: usize, position: f64) -> bool;
}

/// The machine file's switches on a simulated machine: joint `i`'s switch is pressed when the
/// joint is at or beyond its edge in the search direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulatedSwitches {
    /// Edge in the power-on frame (internal units).
    edge: [f64; MAX_JOINTS],
    /// Search direction (±1).
    dir: [f64; MAX_JOINTS],
    joints: usize,
}

impl SimulatedSwitches {
    /// The switches of `machine` seen in a power-on frame where positions read machine positions
    /// plus `offset` (internal units).
    pub fn new(machine: &Machine, offset: &Joints) -> Result<SimulatedSwitches, ManualError> {
        if offset.len() != machine.joints.len() {
            return Err(ManualError::JointCount {
                given: offset.len(),
                expected: machine.joints.len(),
            });
        }
        let mut s = SimulatedSwitches {
            edge: [0.0; MAX_JOINTS],
            dir: [1.0; MAX_JOINTS],
            joints: machine.joints.len(),
        };
        for (i, j) in machine.joints.iter().enumerate() {
            s.edge[i] = j.home.switch * j.to_internal() + offset[i];
            s.dir[i] = j.home.search_velocity.signum();
        }
        Ok(s)
    }
}

impl HomeSwitches for SimulatedSwitches {
    fn tripped(&self, joint: usize, position: f64) -> bool {
        joint < self.joints && self.dir[joint] * (position - self.edge[joint]) >= 0.0
    }
}

/// Where one joint is in its homing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HomePhase {
    /// Its sequence has not come yet.
    Waiting,
    Search,
    SearchStop,
    BackOff,
    BackOffStop,
    Latch,
    LatchStop,
    /// The move to the home position.
    Final,
    Done,
}

/// The last piece of a joint's homing: rest to rest from `start` to `target`.
#[derive(Debug, Clone, Copy)]
struct FinalMove {
    start: f64,
    /// ±1: the direction of the move (the profile runs forward).
    sign: f64,
    target: f64,
    profile: Profile,
}

#[derive(Debug, Clone)]
struct JointHoming {
    axis: JointAxis,
    /// The joint's limits (the search and latch speeds are within their speed).
    limits: Limits,
    sequence: u32,
    /// Switch and home positions in machine coordinates (internal units).
    switch: f64,
    home: f64,
    /// Search direction (±1) and speeds (internal units, > 0).
    dir: f64,
    search_speed: f64,
    latch_speed: f64,
    phase: HomePhase,
    /// The current piece: a velocity profile from t0 (search, back-off, latch, their stops),
    /// or the final move's profile from t0.
    t0: f64,
    ramp: Profile,
    last: Option<FinalMove>,
    search_from: f64,
    max_travel: f64,
    offset: Option<f64>,
}

impl JointHoming {
    fn state(&self, t: f64) -> State {
        match &self.last {
            Some(m) if matches!(self.phase, HomePhase::Final | HomePhase::Done) => {
                if t - self.t0 >= m.profile.duration() {
                    State {
                        s: m.target,
                        ..State::default()
                    }
                } else {
                    let st = m.profile.state_at(t - self.t0);
                    State {
                        s: m.start + m.sign * st.s,
                        v: m.sign * st.v,
                        a: m.sign * st.a,
                        j: m.sign * st.j,
                    }
                }
            }
            _ => self.ramp.state_at(t - self.t0),
        }
    }

    fn begin(&mut self, t: f64, target: f64, phase: HomePhase) {
        let st = self.ramp.state_at(t - self.t0);
        self.ramp = velocity_profile(st, target, &self.limits);
        self.t0 = t;
        self.phase = phase;
    }

    fn piece_end(&self) -> f64 {
        match (&self.last, self.phase) {
            (Some(m), HomePhase::Final) => self.t0 + m.profile.duration(),
            _ => self.t0 + self.ramp.duration(),
        }
    }

    /// Advances the phase machine to time `t` (one period after the last set-point).
    fn advance(
        &mut self,
        t: f64,
        switches: &impl HomeSwitches,
        joint: usize,
    ) -> Result<(), ManualError> {
        use HomePhase::*;
        // Pieces that end before t hand over at their exact end; at most a few per period.
        for _ in 0..8 {
            let end = self.piece_end();
            match self.phase {
                SearchStop if t >= end => self.begin(end, -self.dir * self.latch_speed, BackOff),
                BackOffStop if t >= end => self.begin(end, self.dir * self.latch_speed, Latch),
                LatchStop if t >= end => self.start_final(end)?,
                Final if t >= end => {
                    self.phase = Done;
                    return Ok(());
                }
                _ => break,
            }
        }
        let x = self.state(t).s;
        match self.phase {
            Search => {
                if switches.tripped(joint, x) {
                    self.begin(t, 0.0, SearchStop);
                } else if (x - self.search_from).abs() > self.max_travel {
                    return Err(ManualError::SwitchNotFound {
                        name: self.axis.name.clone(),
                        travel: self.max_travel * self.axis.to_file,
                    });
                }
            }
            BackOff if !switches.tripped(joint, x) => self.begin(t, 0.0, BackOffStop),
            Latch if switches.tripped(joint, x) => {
                self.offset = Some(x - self.switch);
                self.begin(t, 0.0, LatchStop);
            }
            _ => {}
        }
        Ok(())
    }

    fn start_final(&mut self, t: f64) -> Result<(), ManualError> {
        let x0 = self.ramp.end().s;
        let target = self.home + self.offset.unwrap_or(0.0);
        let d = target - x0;
        let motion = |reason: String| ManualError::Motion {
            name: self.axis.name.clone(),
            reason,
        };
        let limits = Limits::new(
            self.search_speed,
            self.axis.max_acceleration,
            self.axis.max_jerk,
        )
        .map_err(|e| motion(format!("{e:?}")))?;
        let p = solve(d.abs(), 0.0, 0.0, &limits).map_err(|e| motion(e.to_string()))?;
        self.last = Some(FinalMove {
            start: x0,
            sign: d.signum(),
            target,
            profile: p,
        });
        self.t0 = t;
        self.phase = HomePhase::Final;
        Ok(())
    }
}

/// The homing of a whole machine; poll [`Home::next_setpoint`] once per period.
#[derive(Debug, Clone)]
pub struct Home {
    joints: Vec<JointHoming>,
    /// The sequence numbers in order, and which one runs.
    order: Vec<u32>,
    group: usize,
    held: Joints,
    period: f64,
    start_index: u64,
    emitted: u64,
    done: bool,
}

impl Home {
    /// Homes every joint of `machine` from `start` (power-on frame, at rest; the set-point at
    /// `index`). Allocates here, never per period.
    pub fn new(machine: &Machine, start: &Joints, index: u64) -> Result<Home, ManualError> {
        check_start(machine, start)?;
        let mut joints = Vec::with_capacity(machine.joints.len());
        for (i, j) in machine.joints.iter().enumerate() {
            let axis = JointAxis::from_machine(machine, i)?;
            let limits = axis.limits()?;
            let s = j.to_internal();
            let range = if (axis.max - axis.min).is_finite() {
                axis.max - axis.min
            } else {
                2.0 * std::f64::consts::PI
            };
            let rest = State {
                s: start[i],
                ..State::default()
            };
            joints.push(JointHoming {
                ramp: velocity_profile(rest, 0.0, &limits),
                limits,
                sequence: j.home.sequence,
                switch: j.home.switch * s,
                home: j.home.position * s,
                dir: j.home.search_velocity.signum(),
                search_speed: (j.home.search_velocity.abs() * s).min(axis.max_velocity),
                latch_speed: (j.home.latch_velocity * s).min(axis.max_velocity),
                axis,
                phase: HomePhase::Waiting,
                t0: 0.0,
                last: None,
                search_from: start[i],
                // the whole travel and a tenth more: a switch not met by then is not there
                max_travel: 1.1 * range,
                offset: None,
            });
        }
        let mut order: Vec<u32> = joints.iter().map(|j| j.sequence).collect();
        order.sort_unstable();
        order.dedup();
        Ok(Home {
            joints,
            order,
            group: 0,
            held: *start,
            period: machine.motion.period_s,
            start_index: index,
            emitted: 0,
            done: false,
        })
    }

    /// The next period's set-point, `Ok(None)` once homing is over. An error (a switch not
    /// found) ends homing; the caller stops the machine.
    pub fn next_setpoint(
        &mut self,
        switches: &impl HomeSwitches,
    ) -> Result<Option<SetPoint>, ManualError> {
        if self.done {
            return Ok(None);
        }
        let now = self.emitted as f64 * self.period;
        let t = now + self.period;
        // start the group whose turn it is (at the last set-point's instant)
        if let Some(&seq) = self.order.get(self.group) {
            for (i, j) in self.joints.iter_mut().enumerate() {
                if j.sequence == seq && j.phase == HomePhase::Waiting {
                    j.t0 = now;
                    j.search_from = j.ramp.end().s;
                    if switches.tripped(i, j.search_from) {
                        // already on the switch: back off first
                        j.begin(now, -j.dir * j.latch_speed, HomePhase::BackOff);
                    } else {
                        j.begin(now, j.dir * j.search_speed, HomePhase::Search);
                    }
                }
            }
        }
        let mut sp = SetPoint::at_rest(self.start_index + self.emitted + 1, 0, self.held);
        for (i, j) in self.joints.iter_mut().enumerate() {
            if j.phase == HomePhase::Waiting || j.phase == HomePhase::Done {
                continue;
            }
            j.advance(t, switches, i)?;
            let st = j.state(t);
            sp.position[i] = st.s;
            sp.velocity[i] = st.v;
            sp.acceleration[i] = st.a;
        }
        self.emitted += 1;
        self.held = sp.position;
        let seq = self.order.get(self.group).copied();
        if self
            .joints
            .iter()
            .filter(|j| Some(j.sequence) == seq)
            .all(|j| j.phase == HomePhase::Done)
        {
            self.group += 1;
            self.done = self.group >= self.order.len();
        }
        Ok(Some(sp))
    }

    /// Each joint's phase.
    pub fn phase(&self, joint: usize) -> Option<HomePhase> {
        self.joints.get(joint).map(|j| j.phase)
    }

    /// True once every joint is homed.
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Power-on frame minus machine frame per joint (internal units), once every joint has
    /// latched.
    pub fn offsets(&self) -> Option<Joints> {
        let mut q = Joints::zeros(self.joints.len());
        for (i, j) in self.joints.iter().enumerate() {
            q[i] = j.offset?;
        }
        Some(q)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{check_limits, positions};
    use super::*;

    /// Runs a homing to its end; returns the set-points and the period each joint first moved.
    fn run(
        m: &Machine,
        start: &Joints,
        offset: &Joints,
    ) -> (Home, Vec<SetPoint>, Result<(), ManualError>) {
        let sw = SimulatedSwitches::new(m, offset).unwrap();
        let mut home = Home::new(m, start, 0).unwrap();
        let mut sps = Vec::new();
        for _ in 0..2_000_000 {
            match home.next_setpoint(&sw) {
                Ok(Some(sp)) => sps.push(sp),
                Ok(None) => return (home, sps, Ok(())),
                Err(e) => return (home, sps, Err(e)),
            }
        }
        panic!("homing did not end");
    }

    fn first_move(sps: &[SetPoint], start: &Joints, joint: usize) -> usize {
        sps.iter()
            .position(|s| s.position[joint] != start[joint])
            .unwrap()
    }

    fn last_move(sps: &[SetPoint], joint: usize) -> usize {
        let end = sps.last().unwrap().position[joint];
        sps.iter()
            .rposition(|s| s.position[joint] != end)
            .unwrap_or(0)
    }

    #[test]
    fn mill3_homes_z_then_x_then_y_and_finds_the_offsets() {
        let m = Machine::builtin("mill3").unwrap();
        // the machine powered up somewhere, its frame 12.3/−4.5/7.0 mm off
        let offset = Joints::new([12.3, -4.5, 7.0]);
        let start = Joints::new([40.0, -20.0, 30.0]);
        let (home, sps, r) = run(&m, &start, &offset);
        r.unwrap();
        assert!(home.is_done());
        eprintln!(
            "mill3 homing from (40, -20, 30): {} periods, offsets found {:?}",
            sps.len(),
            home.offsets().unwrap()
        );
        // order: z moves and finishes before x starts, x before y
        let (z0, z1) = (first_move(&sps, &start, 2), last_move(&sps, 2));
        let (x0, x1) = (first_move(&sps, &start, 0), last_move(&sps, 0));
        let (y0, _) = (first_move(&sps, &start, 1), last_move(&sps, 1));
        assert!(
            z0 < z1 && z1 < x0 && x0 < x1 && x1 < y0,
            "{z0} {z1} {x0} {x1} {y0}"
        );
        // offsets within one latch period: latch 2 mm/s (z 1 mm/s) × 1 ms, late in the search
        // direction (+ on every joint here)
        let found = home.offsets().unwrap();
        for (i, latch) in [(0, 2.0), (1, 2.0), (2, 1.0)] {
            let late = found[i] - offset[i];
            assert!(
                (0.0..=latch * 1e-3 + 1e-12).contains(&late),
                "joint {i}: {late}"
            );
        }
        // it ends at home (0, 0, 0 machine) in the power-on frame, exactly, at rest
        let last = sps.last().unwrap();
        for i in 0..3 {
            assert_eq!(last.position[i], found[i]);
            assert_eq!((last.velocity[i], last.acceleration[i]), (0.0, 0.0));
        }
        for (i, (v, a, j)) in [
            (200.0, 2000.0, 50000.0),
            (200.0, 2000.0, 50000.0),
            (100.0, 1000.0, 25000.0),
        ]
        .into_iter()
        .enumerate()
        {
            check_limits(&positions(&start, &sps, i), 1e-3, v, a, j)
                .unwrap_or_else(|e| panic!("joint {i}: {e}"));
        }
        // search speeds held while searching: 20, 20, 10 mm/s at most
        assert!(sps.iter().all(|s| s.velocity[2].abs() <= 10.0 + 1e-9));
    }

    #[test]
    fn starting_on_the_switch_backs_off_first() {
        let m = Machine::builtin("mill3").unwrap();
        let zero = Joints::zeros(3);
        // z at 97 is past its switch edge at 95 (search +)
        let start = Joints::new([0.0, 0.0, 97.0]);
        let (home, sps, r) = run(&m, &start, &zero);
        r.unwrap();
        let z: Vec<f64> = sps.iter().map(|s| s.position[2]).collect();
        // z never goes above where it started: it backs off, then latches from below
        assert!(z.iter().all(|&p| p <= 97.0));
        let late = home.offsets().unwrap()[2];
        assert!((0.0..=1e-3 + 1e-12).contains(&late), "{late}");
    }

    #[test]
    fn a_missing_switch_is_an_error() {
        let m = Machine::builtin("mill3").unwrap();
        // switches 1000 mm away: never met within the travel
        let offset = Joints::new([0.0, 0.0, 1000.0]);
        let (_, sps, r) = run(&m, &Joints::zeros(3), &offset);
        assert!(matches!(r, Err(ManualError::SwitchNotFound { ref name, .. }) if name == "z"));
        assert!(!sps.is_empty());
    }

    #[test]
    fn equal_sequences_home_together() {
        let text = Machine::builtin_text("mill3")
            .unwrap()
            .replace("sequence = 2", "sequence = 1");
        let m = Machine::from_toml_str(&text).unwrap();
        let start = Joints::new([10.0, 10.0, 10.0]);
        let (_, sps, r) = run(&m, &start, &Joints::zeros(3));
        r.unwrap();
        assert_eq!(first_move(&sps, &start, 0), first_move(&sps, &start, 1));
        assert!(last_move(&sps, 2) < first_move(&sps, &start, 0));
    }

    #[test]
    fn negative_search_on_a_rotary_joint() {
        // yzca defaults: c endless (switch 0, search +36 °/s), a: switch at max 120°, search
        // +9 °/s; give A a negative search toward −100°.
        let text = Machine::builtin_text("yzca").unwrap().replace(
            "max_jerk = 50000.0",
            "max_jerk = 50000.0\n[joint.home]\nswitch = -100.0\nsearch_velocity = -30.0\nlatch_velocity = 3.0\nposition = 10.0",
        );
        let m = Machine::from_toml_str(&text).unwrap();
        let off = 5f64.to_radians();
        let offset = Joints::new([0.0, 0.0, 0.0, off]);
        let start = Joints::new([0.0, 0.0, 0.0, 0.5]);
        let (home, sps, r) = run(&m, &start, &offset);
        r.unwrap();
        let late = home.offsets().unwrap()[3] - off;
        // latched late in the search direction (−) by at most 3 °/s × 1 ms
        assert!(
            late <= 0.0 && late >= -(3e-3f64).to_radians() - 1e-12,
            "{late}"
        );
        let end = sps.last().unwrap().position[3];
        assert!((end - (10f64.to_radians() + home.offsets().unwrap()[3])).abs() < 1e-12);
        check_limits(
            &positions(&start, &sps, 3),
            1e-3,
            90f64.to_radians(),
            900f64.to_radians(),
            50000f64.to_radians(),
        )
        .unwrap();
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
        #[test]
        fn random_power_on_frames_home_exactly(
            start in proptest::array::uniform3(-90.0..90.0f64),
            offset in proptest::array::uniform3(-20.0..20.0f64),
        ) {
            let m = Machine::builtin("mill3").unwrap();
            let (start, offset) = (Joints::new(start), Joints::new(offset));
            let (home, sps, r) = run(&m, &start, &offset);
            proptest::prop_assert!(r.is_ok(), "{:?}", r);
            let found = home.offsets().unwrap();
            let last = sps.last().unwrap();
            for (i, (latch, v, a, j)) in [
                (2.0, 200.0, 2000.0, 50000.0),
                (2.0, 200.0, 2000.0, 50000.0),
                (1.0, 100.0, 1000.0, 25000.0),
            ]
            .into_iter()
            .enumerate()
            {
                let late = found[i] - offset[i];
                proptest::prop_assert!((0.0..=latch * 1e-3 + 1e-9).contains(&late), "{i}: {late}");
                // home position 0 in machine coordinates
                proptest::prop_assert_eq!(last.position[i], found[i]);
                let c = check_limits(&positions(&start, &sps, i), 1e-3, v, a, j);
                proptest::prop_assert!(c.is_ok(), "{i}: {:?}", c);
            }
            // Z moved and came to rest before X or Y moved
            let z_end = last_move(&sps, 2);
            proptest::prop_assert!(z_end < first_move(&sps, &start, 0));
            proptest::prop_assert!(z_end < first_move(&sps, &start, 1));
        }
    }
}
