//! Real-time scheduling for the real-time thread, best effort: SCHED_FIFO at a priority, the
//! process' memory locked (current and future pages, so no page fault stalls a period) and
//! optionally one CPU. Called once on that thread before its loop; what the system refuses
//! (no root, no CAP_SYS_NICE / CAP_IPC_LOCK, another OS) is reported, never fatal — the loop
//! then runs time-shared, as the soak figures in the notes show.

/// What to ask for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RealtimeSettings {
    /// SCHED_FIFO priority (1–99), `None` to stay time-shared.
    pub fifo_priority: Option<i32>,
    /// `mlockall(MCL_CURRENT | MCL_FUTURE)`.
    pub lock_memory: bool,
    /// Pin the thread to this CPU.
    pub cpu: Option<usize>,
}

impl RealtimeSettings {
    /// Nothing asked: the thread stays an ordinary one.
    pub const OFF: RealtimeSettings = RealtimeSettings {
        fifo_priority: None,
        lock_memory: false,
        cpu: None,
    };

    /// SCHED_FIFO at 80 (above the kernel's threaded interrupts at 50, below its watchdogs at
    /// 99, as LinuxCNC and the PREEMPT_RT guides place a control loop) and memory locked; no
    /// pinning (on a shared machine the scheduler places it better).
    pub const BEST_EFFORT: RealtimeSettings = RealtimeSettings {
        fifo_priority: Some(80),
        lock_memory: true,
        cpu: None,
    };
}

impl RealtimeSettings {
    /// What the planner thread asks for alongside: SCHED_FIFO ten below the real-time thread
    /// (so it preempts the machine's ordinary work but never the loop it feeds: under load a
    /// time-shared planner, not the loop, was what let the ring run dry), nothing else (the
    /// memory lock is the process', asked once).
    pub fn for_planner(&self) -> RealtimeSettings {
        RealtimeSettings {
            fifo_priority: self.fifo_priority.map(|p| (p - 10).max(1)),
            lock_memory: false,
            cpu: None,
        }
    }
}

/// How one request went.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    NotAsked,
    Done,
    /// Refused or unavailable, with the system's reason.
    Refused(String),
}

/// What was applied.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Applied {
    pub fifo: Outcome,
    pub memory_locked: Outcome,
    pub cpu: Outcome,
}

impl Applied {
    /// One line per refusal, for a warning (empty when all asked was granted).
    pub fn warnings(&self) -> Vec<String> {
        [
            ("SCHED_FIFO", &self.fifo),
            ("mlockall", &self.memory_locked),
            ("CPU affinity", &self.cpu),
        ]
        .into_iter()
        .filter_map(|(what, o)| match o {
            Outcome::Refused(why) => Some(format!(
                "real-time thread: {what} not applied ({why}); it runs time-shared, \
                 periods may be late and the ring may underrun on a busy machine"
            )),
            _ => None,
        })
        .collect()
    }
}

/// Runs `work` on the calling thread time-shared (SCHED_OTHER), then puts back `fifo` if it
/// was granted: long non-real-time work (building and checking a whole program's path) must
/// not hold a core at real-time priority. The machine is idle whenever the planner does such
/// work (load, cycle start, MDI and restart are accepted only then), so nothing waits on it.
pub fn time_shared<T>(fifo: &Outcome, priority: Option<i32>, work: impl FnOnce() -> T) -> T {
    let Some(p) = priority.filter(|_| *fifo == Outcome::Done) else {
        return work();
    };
    sys::other();
    let out = work();
    let _ = sys::fifo(p);
    out
}

/// The calling thread's scheduling policy is SCHED_FIFO.
pub fn is_fifo() -> bool {
    sys::is_fifo()
}

/// Applies `settings` to the calling thread (and, for the memory lock, the process).
pub fn apply(settings: &RealtimeSettings) -> Applied {
    Applied {
        fifo: settings.fifo_priority.map_or(Outcome::NotAsked, sys::fifo),
        memory_locked: if settings.lock_memory {
            sys::lock_memory()
        } else {
            Outcome::NotAsked
        },
        cpu: settings.cpu.map_or(Outcome::NotAsked, sys::pin),
    }
}

#[cfg(target_os = "linux")]
mod sys {
    use super::Outcome;

    fn errno(code: i32) -> String {
        std::io::Error::from_raw_os_error(code).to_string()
    }

    pub fn fifo(priority: i32) -> Outcome {
        if !(1..=99).contains(&priority) {
            return Outcome::Refused(format!("priority {priority} is outside 1–99"));
        }
        let param = libc::sched_param {
            sched_priority: priority,
        };
        // SAFETY: pthread_self() is the calling thread, alive during the call; param is a
        // valid sched_param for the duration of the call.
        let rc =
            unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
        if rc == 0 {
            Outcome::Done
        } else {
            Outcome::Refused(errno(rc))
        }
    }

    pub fn other() {
        let param = libc::sched_param { sched_priority: 0 };
        // SAFETY: as in `fifo`; SCHED_OTHER at priority 0 is always permitted.
        unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_OTHER, &param) };
    }

    pub fn is_fifo() -> bool {
        let mut policy = 0;
        let mut param = libc::sched_param { sched_priority: 0 };
        // SAFETY: both out-pointers are valid for the call.
        let rc =
            unsafe { libc::pthread_getschedparam(libc::pthread_self(), &mut policy, &mut param) };
        rc == 0 && policy == libc::SCHED_FIFO
    }

    pub fn lock_memory() -> Outcome {
        // With MCL_FUTURE under a finite RLIMIT_MEMLOCK, a later allocation past the limit
        // fails (and Rust aborts on it): lock only with the limit lifted or as root.
        let mut limit = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: limit is a valid rlimit to write into.
        let rc = unsafe { libc::getrlimit(libc::RLIMIT_MEMLOCK, &mut limit) };
        // SAFETY: geteuid has no preconditions.
        let root = unsafe { libc::geteuid() } == 0;
        if !root && (rc != 0 || limit.rlim_cur != libc::RLIM_INFINITY) {
            return Outcome::Refused(
                "RLIMIT_MEMLOCK is finite and not root: future allocations could fail".into(),
            );
        }
        // SAFETY: mlockall takes flags only.
        let rc = unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) };
        if rc == 0 {
            Outcome::Done
        } else {
            Outcome::Refused(std::io::Error::last_os_error().to_string())
        }
    }

    pub fn pin(cpu: usize) -> Outcome {
        if cpu >= libc::CPU_SETSIZE as usize {
            return Outcome::Refused(format!("no CPU {cpu}"));
        }
        // SAFETY: cpu_set_t is plain data, zeroed is the empty set; CPU_SET stays within it
        // (checked above); the call reads the set for the calling thread (pid 0).
        let rc = unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            libc::CPU_SET(cpu, &mut set);
            libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set)
        };
        if rc == 0 {
            Outcome::Done
        } else {
            Outcome::Refused(std::io::Error::last_os_error().to_string())
        }
    }
}

#[cfg(not(target_os = "linux"))]
mod sys {
    use super::Outcome;

    fn unsupported() -> Outcome {
        Outcome::Refused("only implemented on Linux".into())
    }

    pub fn fifo(_: i32) -> Outcome {
        unsupported()
    }

    pub fn lock_memory() -> Outcome {
        unsupported()
    }

    pub fn other() {}

    pub fn is_fifo() -> bool {
        false
    }

    pub fn pin(_: usize) -> Outcome {
        unsupported()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn off_asks_nothing() {
        let a = apply(&RealtimeSettings::OFF);
        assert_eq!(
            (a.fifo.clone(), a.memory_locked.clone(), a.cpu.clone()),
            (Outcome::NotAsked, Outcome::NotAsked, Outcome::NotAsked)
        );
        assert!(a.warnings().is_empty());
    }

    /// Work in `time_shared` runs under SCHED_OTHER and the granted FIFO comes back after;
    /// where FIFO is not granted here (no root, no CAP_SYS_NICE) only the pass-through is
    /// checked, and said.
    #[test]
    fn time_shared_work_drops_and_restores_fifo() {
        std::thread::spawn(|| {
            let asked = Some(10);
            let got = apply(&RealtimeSettings {
                fifo_priority: asked,
                lock_memory: false,
                cpu: None,
            });
            let inside = time_shared(&got.fifo, asked, is_fifo);
            if got.fifo == Outcome::Done {
                assert!(!inside, "still FIFO inside the work");
                assert!(is_fifo(), "FIFO not restored");
            } else {
                println!(
                    "SCHED_FIFO not granted here ({:?}): pass-through only",
                    got.fifo
                );
                assert!(!inside && !is_fifo());
            }
        })
        .join()
        .unwrap();
    }

    /// A request the system can never grant comes back refused with a reason, as a warning
    /// (checked on a thread of its own, which the refusal leaves as it was).
    #[test]
    fn impossible_requests_are_refused_with_a_reason() {
        let a = std::thread::spawn(|| {
            apply(&RealtimeSettings {
                fifo_priority: Some(1000),
                lock_memory: false,
                cpu: Some(1 << 20),
            })
        })
        .join()
        .unwrap();
        assert!(matches!(a.fifo, Outcome::Refused(_)), "{a:?}");
        assert!(matches!(a.cpu, Outcome::Refused(_)), "{a:?}");
        let w = a.warnings();
        assert_eq!(w.len(), 2);
        assert!(
            w[0].contains("SCHED_FIFO") && w[0].contains("1–99"),
            "{w:?}"
        );
    }
}
