//! `tezgah run`'s replay on a second thread: the interpolator's samples, each with the path it
//! lies on, go over in batches to the [`Verifier`], which replays them in order there while
//! this thread plans and interpolates. The report is the same as an inline replay's (one
//! consumer, the same order); on two cores the replay's time leaves the run's critical path.
//! Where no thread can be started the replay runs inline.

use std::ops::Range;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Arc;
use std::thread::{Scope, ScopedJoinHandle};

use miette::{miette, Result};
use tezgah_motion::interpolate::Sample;
use tezgah_motion::verify::{Report, Verifier};
use tezgah_motion::Segment;

/// Samples per batch: a few milliseconds of replay, so that the hand-over costs nothing
/// beside it and the replay is never far behind.
const BATCH: usize = 2048;

/// Batches in flight: the interpolator runs at most this far ahead of the replay.
const IN_FLIGHT: usize = 4;

/// Samples and the segments their paths index. A segment that ends one sample's path and
/// starts the next one's (nearly always the same, the sample's own) is stored once.
#[derive(Default)]
struct Batch {
    samples: Vec<(Sample, Range<u32>)>,
    segments: Vec<Arc<Segment>>,
}

impl Batch {
    fn with_capacity() -> Batch {
        Batch {
            samples: Vec::with_capacity(BATCH),
            segments: Vec::with_capacity(BATCH / 4),
        }
    }

    fn push(&mut self, s: &Sample, path: &[Arc<Segment>]) {
        let mut start = self.segments.len();
        let mut rest = path;
        if let (Some((first, after)), Some(last)) = (path.split_first(), self.segments.last()) {
            if Arc::ptr_eq(first, last) {
                start -= 1;
                rest = after;
            }
        }
        self.segments.extend(rest.iter().cloned());
        self.samples
            .push((*s, start as u32..self.segments.len() as u32));
    }

    fn replay(&self, verifier: &mut Verifier) {
        for (s, path) in &self.samples {
            let path = &self.segments[path.start as usize..path.end as usize];
            verifier.push(s, path);
        }
    }
}

/// The replay of a run's samples.
pub struct Replay<'scope>(Where<'scope>);

/// Where the samples are replayed.
enum Where<'scope> {
    Thread {
        batch: Batch,
        to: SyncSender<Batch>,
        replay: ScopedJoinHandle<'scope, Report>,
    },
    Inline(Box<Verifier>),
}

impl<'scope> Replay<'scope> {
    /// The replay by the verifier `make` makes, on a thread of `scope` (which also makes it,
    /// alongside the caller's work); inline where no thread can be started.
    pub fn start<'env, F>(scope: &'scope Scope<'scope, 'env>, make: &'scope F) -> Replay<'scope>
    where
        F: Fn() -> Verifier + Sync,
    {
        let (to, from) = sync_channel::<Batch>(IN_FLIGHT);
        let spawned = std::thread::Builder::new()
            .name("verify".into())
            .spawn_scoped(scope, move || replay_all(make(), from));
        match spawned {
            Ok(replay) => Replay(Where::Thread {
                batch: Batch::with_capacity(),
                to,
                replay,
            }),
            Err(_) => Replay(Where::Inline(Box::new(make()))),
        }
    }

    /// Takes one sample and the path it lies on ([`Verifier::push`]).
    pub fn push(&mut self, s: &Sample, path: &[Arc<Segment>]) {
        match &mut self.0 {
            Where::Thread { batch, to, .. } => {
                batch.push(s, path);
                if batch.samples.len() >= BATCH {
                    // A replay that has stopped (it panicked) is reported by `finish`.
                    let _ = to.send(std::mem::replace(batch, Batch::with_capacity()));
                }
            }
            Where::Inline(v) => v.push(s, path),
        }
    }

    /// Ends the replay and returns its report.
    pub fn finish(self) -> Result<Report> {
        match self.0 {
            Where::Thread { batch, to, replay } => {
                let _ = to.send(batch);
                drop(to);
                replay
                    .join()
                    .map_err(|_| miette!("the verification thread failed"))
            }
            Where::Inline(v) => Ok(v.finish()),
        }
    }
}

/// The thread's work: every batch in order, then the report.
fn replay_all(mut verifier: Verifier, from: Receiver<Batch>) -> Report {
    for batch in from {
        batch.replay(&mut verifier);
    }
    verifier.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_geom::{Line, ToolControl, Vec3};
    use tezgah_kinematics::{Joints, Machine};
    use tezgah_motion::plan::PlanMachine;
    use tezgah_motion::{Junction, SegmentFeed};

    /// A line along x from `x0` to `x1` at F6000.
    fn segment(x0: f64, x1: f64, line: u32) -> Arc<Segment> {
        let (a, b) = (Vec3::new(x0, 0.0, 0.0), Vec3::new(x1, 0.0, 0.0));
        Arc::new(Segment {
            curve: Box::new(Line::new(a, b).unwrap()),
            length: x1 - x0,
            rotary: [[0.0; 3]; 2],
            line,
            feed: SegmentFeed::Feed(100.0),
            end: Junction::Stop,
            tolerance: 0.01,
            control: ToolControl::OFF,
            feed_override: true,
            tool_axis_travel: None,
            axis: None,
        })
    }

    /// Samples along three 1 mm lines at 100 mm/s with a pause on each line end, each with
    /// the path the interpolator would hand over: the segments passed since the last sample.
    fn samples() -> Vec<(Sample, Vec<Arc<Segment>>)> {
        let segs = [
            segment(0.0, 1.0, 1),
            segment(1.0, 2.0, 2),
            segment(2.0, 3.0, 3),
        ];
        let mut out = Vec::new();
        let mut last: Option<usize> = None;
        for k in 0..5000u32 {
            // 0.1 mm per period, standing still for 10 periods after every 40.
            let phase = k % 50;
            let moving = phase < 40;
            let x = (f64::from(k / 50) * 4.0 + f64::from(phase.min(40)) * 0.1) % 3.0;
            let i = (x.floor() as usize).min(2);
            let path = match (moving, last) {
                (false, _) => Vec::new(),
                (true, Some(j)) if j <= i => segs[j..=i].to_vec(),
                (true, _) => vec![segs[i].clone()],
            };
            last = moving.then_some(i);
            let mut joints = Joints::zeros(3);
            joints.as_mut_slice()[0] = x;
            let s = Sample {
                index: u64::from(k),
                t: f64::from(k) * 1e-3,
                line: i as u32 + 1,
                tip: Vec3::new(x, 0.0, 0.0),
                rotary: [0.0; 3],
                joints,
                feed: if moving { 100.0 } else { 0.0 },
            };
            out.push((s, path));
        }
        out
    }

    /// A batch hands every sample its own path back, segment for segment, with the shared
    /// segments stored once.
    #[test]
    fn a_batch_keeps_every_path() {
        let all = samples();
        let mut batch = Batch::default();
        for (s, path) in &all {
            batch.push(s, path);
        }
        assert!(batch.segments.len() < all.iter().map(|(_, p)| p.len()).sum::<usize>() / 2);
        for ((s, path), (kept, range)) in all.iter().zip(&batch.samples) {
            assert_eq!(s, kept);
            let got = &batch.segments[range.start as usize..range.end as usize];
            assert_eq!(got.len(), path.len());
            assert!(got.iter().zip(path).all(|(a, b)| Arc::ptr_eq(a, b)));
        }
    }

    /// The replay on its thread, over several batches, reports what the verifier reports
    /// inline.
    #[test]
    fn the_thread_reports_what_the_inline_replay_does() {
        let pm = PlanMachine::from_machine(&Machine::default_machine()).unwrap();
        let all = samples();
        let mut inline = Verifier::new(&pm, 1e-3);
        for (s, path) in &all {
            inline.push(s, path);
        }
        let inline = inline.finish();
        let make = || Verifier::new(&pm, 1e-3);
        let threaded = std::thread::scope(|scope| {
            let mut replay = Replay::start(scope, &make);
            assert!(matches!(replay.0, Where::Thread { .. }));
            for (s, path) in &all {
                replay.push(s, path);
            }
            replay.finish().unwrap()
        });
        assert_eq!(threaded.samples, 5000);
        // 0.1 mm a period along x.
        assert!(threaded.joints[0].velocity >= 100.0 * (1.0 - 1e-12));
        assert_eq!(threaded, inline);
    }
}
