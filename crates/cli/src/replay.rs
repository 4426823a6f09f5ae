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
