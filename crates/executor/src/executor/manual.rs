//! JOG, INC and HOME in the executor: the commands that start them (only while idle), their
//! stop, and the period step that polls the generator in hand ([`ManualMotion`]) instead of a
//! job. Set-points leave through the job's `emit`, so the stream's contract is one; HOME runs
//! in the drives' frame and its offsets take effect when it ends (no jump in the stream).

use tezgah_kinematics::Joints;

use super::{add, sub, Executor, Produced};
use crate::command::{Direction, Mode, RunState};
use crate::error::ExecError;
use crate::manual::active::ManualMotion;
use crate::manual::{default_jog_speed, Home, Inc, IncStep, Jog, ManualError};
use crate::setpoint::SetPoint;
use crate::speed_override::Override;
use crate::stop::{PlayedStop, StopLimits};

impl Executor {
    pub(super) fn jog(
        &mut self,
        joint: usize,
        direction: Direction,
        speed: Option<f64>,
    ) -> Result<(), ExecError> {
        if self.state != RunState::Idle {
            return Err(self.busy("jog"));
        }
        let speed = match speed {
            Some(v) => v,
            None => default_jog_speed(self.joint_kind(joint)?),
        };
        let mut jog = Jog::new(
            &self.machine_file,
            joint,
            &self.pose.joints,
            direction,
            speed,
            self.k,
        )?;
        jog.set_override(self.jog_override);
        self.start_manual(ManualMotion::Jog(jog), Mode::Jog);
        Ok(())
    }

    pub(super) fn jog_stop(&mut self) -> Result<(), ExecError> {
        match &mut self.manual {
            Some(ManualMotion::Jog(jog)) => {
                jog.stop();
                Ok(())
            }
            // Released after the jog ended (at a soft limit): nothing to do.
            None if self.state == RunState::Idle => Ok(()),
            _ => Err(ExecError::NotJogging),
        }
    }

    pub(super) fn jog_override(&mut self, percent: f64) -> Result<(), ExecError> {
        let o = Override::new(percent)?;
        if let Some(ManualMotion::Jog(jog)) = &mut self.manual {
            jog.set_override(o);
        }
        self.jog_override = o;
        Ok(())
    }

    pub(super) fn increment(
        &mut self,
        joint: usize,
        direction: Direction,
        step: f64,
    ) -> Result<(), ExecError> {
        if self.state != RunState::Idle {
            return Err(self.busy("increment"));
        }
        let step = IncStep::new(step)?;
        let speed = default_jog_speed(self.joint_kind(joint)?);
        let inc = Inc::new(
            &self.machine_file,
            joint,
            &self.pose.joints,
            direction,
            step,
            speed,
            self.k,
        )?;
        self.start_manual(ManualMotion::Inc(inc), Mode::Inc);
        Ok(())
    }

    pub(super) fn home(&mut self) -> Result<(), ExecError> {
        if self.state != RunState::Idle {
            return Err(self.busy("home"));
        }
        // Homing runs in the drives' frame; its offsets replace the old ones at the end.
        let home = Home::new(&self.machine_file, &self.drive_joints(), self.k)?;
        self.start_manual(ManualMotion::Home(Box::new(home)), Mode::Home);
        Ok(())
    }

    fn joint_kind(&self, joint: usize) -> Result<tezgah_kinematics::JointKind, ExecError> {
        self.machine_file
            .joints
            .get(joint)
            .map(|j| j.kind)
            .ok_or_else(|| {
                ManualError::NoSuchJoint {
                    joint,
                    count: self.machine_file.joints.len(),
                }
                .into()
            })
    }

    fn start_manual(&mut self, motion: ManualMotion, mode: Mode) {
        self.manual = Some(motion);
        self.last_manual = None;
        self.mode = mode;
        self.state = RunState::Running;
        self.error = None;
    }

    /// Ends the manual motion in hand jerk-limited: a jog by its own stop (the minimum
    /// distance), INC and HOME by stopping every joint from its exact state (homing is then
    /// not complete; the offsets in force stay).
    pub(super) fn stop_manual(&mut self) {
        match &mut self.manual {
            Some(ManualMotion::Jog(jog)) => jog.stop(),
            Some(ManualMotion::Stop(_)) | None => {}
            Some(_) => {
                let last = self
                    .last_manual
                    .unwrap_or_else(|| SetPoint::at_rest(0, 0, self.pose.joints));
                let limits = StopLimits::of(&self.machine);
                self.manual = Some(ManualMotion::Stop(Box::new(PlayedStop::new(
                    &last,
                    &limits,
                    self.options.period,
                ))));
            }
        }
    }

    /// One period of the manual motion in hand.
    pub(super) fn step_manual(&mut self) -> Result<Option<Produced>, ExecError> {
        let Some(manual) = self.manual.as_mut() else {
            return Ok(None);
        };
        match manual.next(&*self.switches) {
            Ok(Some(sp)) => {
                let drive_frame = manual.in_drive_frame();
                let position = if drive_frame {
                    sub(&sp.position, &self.offset, 1.0)
                } else {
                    sp.position
                };
                self.last_manual = Some(SetPoint { position, ..sp });
                let before = self.pose.tip;
                self.set_joints(position);
                let feed = (self.pose.tip - before).norm() / self.options.period;
                let drive = if drive_frame {
                    sp.position
                } else {
                    add(&position, &self.offset)
                };
                // The ramps' velocity and acceleration are exact (the same in both frames).
                let setpoint = self.history.exact(SetPoint {
                    index: self.k,
                    line: self.pose.line,
                    position: drive,
                    ..sp
                });
                Ok(Some(self.produced(setpoint, feed)))
            }
            Ok(None) => {
                if let Some(ManualMotion::Home(home)) = &self.manual {
                    if let Some(offset) = home.offsets() {
                        // The drives stay where they are (no jump); the machine frame moves.
                        self.offset = offset;
                        self.homed = true;
                        self.set_joints(sub(&self.history.last(), &offset, 1.0));
                    }
                }
                self.manual = None;
                self.last_manual = None;
                self.state = RunState::Idle;
                let at = self.history.last();
                Ok(Some(self.emit_at(at, true, 0.0)))
            }
            Err(e) => {
                // A homing that cannot go on (no switch found) stops where it is; the error
                // stays in the status (a stop's periods never fail or clear it).
                self.error = Some(e.to_string());
                self.stop_manual();
                self.step_manual()
            }
        }
    }

    /// The pose at machine-frame joints `q` (outside a program: line 0).
    fn set_joints(&mut self, q: Joints) {
        if let Ok((tip, rotary)) = self.machine.joint_mode_point(&q) {
            self.pose.tip = tip;
            self.pose.rotary = rotary;
        }
        self.pose.joints = q;
        self.pose.line = 0;
    }
}
