//! Real-time pacing: the thread that paces a stream (or a HITL session) asks the operating
//! system for `SCHED_FIFO` at a modest priority and locks the process's memory, so that
//! other work on the machine (CPU hogs at normal priority, page faults) cannot hold a send
//! instant up by milliseconds.
//!
//! [`enter`] applies a [`Realtime`] request to the calling thread through a [`Scheduler`] (the
//! operating system's calls: [`SystemScheduler`]; a test fakes them) and returns a
//! [`RealtimeGuard`], which puts the thread back at its previous policy (and unlocks memory,
//! when it was the last to lock it) when dropped, and what was [`Obtained`]:
//!
//! - `SCHED_FIFO` at the priority asked ([`DEFAULT_PRIORITY`] for [`Realtime::Auto`]) for the
//!   calling thread only: threads it starts afterwards inherit it, so the session starts its
//!   receive, prediction and log threads before (they stay at normal priority);
//! - `mlockall(MCL_CURRENT | MCL_FUTURE)` only where it cannot make a later allocation fail:
//!   the process holds `CAP_IPC_LOCK` or `RLIMIT_MEMLOCK` is unlimited; otherwise nothing is
//!   locked and [`Obtained`] says why;
//! - where `SCHED_FIFO` is refused (`EPERM`: no `CAP_SYS_NICE` and `RLIMIT_RTPRIO` below the
//!   priority), nothing is changed: the session goes on at normal priority and
//!   [`Obtained::warning`] is one line saying what failed, why, and how to allow it.
//!
//! A `SCHED_FIFO` thread that never sleeps starves the threads at normal priority on its core:
//! the paced run only busy-waits the last [`MAX_SPIN`] before a send instant and sleeps
//! otherwise (see [`crate::stream::Port::spin_until`]).
//!
//! ```
//! use margemu_hil::realtime::{enter, Realtime, SystemScheduler};
//! use std::sync::Arc;
//! let (guard, obtained) = enter(Realtime::Off, Arc::new(SystemScheduler));
//! assert_eq!(obtained.to_string(), "normal priority (realtime off)");
//! assert!(obtained.warning().is_none());
//! drop(guard);
//! ```

mod system;

pub use system::SystemScheduler;

use std::fmt;
use std::marker::PhantomData;
use std::str::FromStr;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The `SCHED_FIFO` priority [`Realtime::Auto`] asks for: above every normal thread, below the
/// kernel's own real-time threads (50 and up).
pub const DEFAULT_PRIORITY: u8 = 10;

/// The longest busy-wait before a send instant that a `SCHED_FIFO` pacing thread is allowed.
pub const MAX_SPIN: Duration = Duration::from_micros(200);

/// What the pacing thread asks of the operating system (`--realtime off|auto|PRIO`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Realtime {
    /// Normal priority, memory not locked (the library's default, so that tests running many
    /// sessions at once never compete at real-time priority).
    #[default]
    Off,
    /// `SCHED_FIFO` at [`DEFAULT_PRIORITY`] and memory locked where permitted; otherwise one
    /// warning and normal priority (the command line's default).
    Auto,
    /// As [`Realtime::Auto`], at this `SCHED_FIFO` priority (1 to 99).
    Priority(u8),
}

impl Realtime {
    /// The `SCHED_FIFO` priority asked for (`None`: off).
    pub fn priority(self) -> Option<u8> {
        match self {
            Self::Off => None,
            Self::Auto => Some(DEFAULT_PRIORITY),
            Self::Priority(p) => Some(p),
        }
    }
}

impl fmt::Display for Realtime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Off => f.write_str("off"),
            Self::Auto => f.write_str("auto"),
            Self::Priority(p) => write!(f, "{p}"),
        }
    }
}

impl FromStr for Realtime {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "off" => Ok(Self::Off),
            "auto" => Ok(Self::Auto),
            _ => match s.parse::<u8>() {
                Ok(p @ 1..=99) => Ok(Self::Priority(p)),
                _ => Err(format!(
                    "{s:?} is not a realtime setting: off, auto or a SCHED_FIFO priority 1 to 99"
                )),
            },
        }
    }
}

/// An operating-system error number (`EPERM`, ...).
pub type Errno = i32;

/// A thread's scheduling policy and priority, as `pthread_getschedparam` gives them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Policy {
    /// `SCHED_OTHER`, `SCHED_FIFO`, ...
    pub policy: i32,
    /// The static priority (0 for `SCHED_OTHER`).
    pub priority: i32,
}

/// The operating system's calls that [`enter`] makes, behind a narrow trait so a test can make
/// them fail ([`SystemScheduler`] makes them for real).
pub trait Scheduler: Send + Sync {
    /// The calling thread's policy.
    fn current(&self) -> Result<Policy, Errno>;
    /// Sets the calling thread's policy.
    fn set(&self, policy: Policy) -> Result<(), Errno>;
    /// Why locking all of the process's memory could make an allocation fail (`None`: it
    /// cannot: `CAP_IPC_LOCK`, or `RLIMIT_MEMLOCK` unlimited).
    fn memory_lock_limit(&self) -> Option<String>;
    /// `mlockall(MCL_CURRENT | MCL_FUTURE)`.
    fn lock_memory(&self) -> Result<(), Errno>;
    /// `munlockall()`.
    fn unlock_memory(&self);
    /// The soft `RLIMIT_RTPRIO` (the highest priority allowed without `CAP_SYS_NICE`).
    fn rtprio_limit(&self) -> u64;
}

/// What [`enter`] obtained; its `Display` is the line a session records (`events.csv`'s
/// `pacing` row, the summaries): `SCHED_FIFO 10, memory locked`, `normal priority: EPERM ...`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Obtained {
    /// What was asked.
    pub requested: Realtime,
    /// The `SCHED_FIFO` priority the thread runs at (`None`: normal priority).
    pub fifo_priority: Option<u8>,
    /// Whether the process's memory is locked.
    pub memory_locked: bool,
    /// Why what was asked was not (all) obtained.
    pub shortfall: Option<String>,
}

impl Obtained {
    /// One line for the operator when real-time pacing was asked for and refused: what failed,
    /// why, and how to allow it or silence the warning (`None`: nothing to say).
    pub fn warning(&self) -> Option<String> {
        self.shortfall.as_ref()?;
        let prio = self.requested.priority().unwrap_or(DEFAULT_PRIORITY);
        let how = if self.fifo_priority.is_none() {
            format!(
                "allow it with `sudo setcap cap_sys_nice,cap_ipc_lock+ep $(which margemu)`, or \
                 `ulimit -r {prio}` (hard limit: `USER - rtprio {prio}` in \
                 /etc/security/limits.conf)"
            )
        } else {
            "allow it with `ulimit -l unlimited` (hard limit: `USER - memlock unlimited` in \
             /etc/security/limits.conf) or `setcap cap_ipc_lock+ep`"
                .to_owned()
        };
        Some(format!(
            "warning: real-time pacing: {self}; {how}; `--realtime off` silences this"
        ))
    }
}

impl fmt::Display for Obtained {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.requested, self.fifo_priority) {
            (Realtime::Off, _) => f.write_str("normal priority (realtime off)"),
            (_, None) => write!(
                f,
                "normal priority: {}",
                self.shortfall.as_deref().unwrap_or("not obtained")
            ),
            (_, Some(p)) if self.memory_locked => write!(f, "SCHED_FIFO {p}, memory locked"),
            (_, Some(p)) => write!(
                f,
                "SCHED_FIFO {p}, memory not locked: {}",
                self.shortfall.as_deref().unwrap_or("not asked")
            ),
        }
    }
}

/// How many guards hold the process's memory locked (it is one lock for the whole process).
static MEMORY_LOCKS: Mutex<usize> = Mutex::new(0);

/// Puts the thread that called [`enter`] back as it was when dropped, on that thread (it is
/// not `Send`).
pub struct RealtimeGuard {
    scheduler: Arc<dyn Scheduler>,
    /// The policy to restore.
    saved: Option<Policy>,
    locked: bool,
    _thread: PhantomData<*const ()>,
}

impl fmt::Debug for RealtimeGuard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RealtimeGuard")
            .field("saved", &self.saved)
            .field("locked", &self.locked)
            .finish()
    }
}

impl Drop for RealtimeGuard {
    fn drop(&mut self) {
        if let Some(saved) = self.saved {
            let _ = self.scheduler.set(saved);
        }
        if self.locked {
            let mut locks = MEMORY_LOCKS.lock().unwrap_or_else(|e| e.into_inner());
            *locks -= 1;
            if *locks == 0 {
                self.scheduler.unlock_memory();
            }
        }
    }
}

/// The name of an error number, as the warning writes it.
fn errno_name(errno: Errno) -> String {
    match errno {
        libc::EPERM => "EPERM".to_owned(),
        libc::EINVAL => "EINVAL".to_owned(),
        libc::ENOMEM => "ENOMEM".to_owned(),
        libc::EAGAIN => "EAGAIN".to_owned(),
        n => format!("errno {n}"),
    }
}

/// Applies `request` to the calling thread (see the module docs).
pub fn enter(request: Realtime, scheduler: Arc<dyn Scheduler>) -> (RealtimeGuard, Obtained) {
    let mut guard = RealtimeGuard {
        scheduler: scheduler.clone(),
        saved: None,
        locked: false,
        _thread: PhantomData,
    };
    let mut obtained = Obtained {
        requested: request,
        ..Obtained::default()
    };
    let Some(priority) = request.priority() else {
        return (guard, obtained);
    };
    let fifo = Policy {
        policy: libc::SCHED_FIFO,
        priority: i32::from(priority),
    };
    match scheduler.current().and_then(|saved| {
        scheduler.set(fifo)?;
        Ok(saved)
    }) {
        Ok(saved) => {
            guard.saved = Some(saved);
            obtained.fifo_priority = Some(priority);
        }
        Err(errno) => {
            let why = match errno {
                libc::EPERM => format!(
                    "no CAP_SYS_NICE and RLIMIT_RTPRIO {}",
                    scheduler.rtprio_limit()
                ),
                _ => "refused".to_owned(),
            };
            obtained.shortfall = Some(format!(
                "SCHED_FIFO {priority} refused: {} ({why})",
                errno_name(errno)
            ));
            return (guard, obtained);
        }
    }
    if let Some(why) = scheduler.memory_lock_limit() {
        obtained.shortfall = Some(why);
        return (guard, obtained);
    }
    let mut locks = MEMORY_LOCKS.lock().unwrap_or_else(|e| e.into_inner());
    let locked = if *locks > 0 {
        Ok(())
    } else {
        scheduler.lock_memory()
    };
    match locked {
        Ok(()) => {
            *locks += 1;
            guard.locked = true;
            obtained.memory_locked = true;
        }
        Err(errno) => {
            obtained.shortfall = Some(format!("mlockall failed: {}", errno_name(errno)));
        }
    }
    (guard, obtained)
}

/// Prints `obtained`'s warning on standard error, the first time one is due in this process
/// (a benchmark runs many sessions: one line is enough).
pub fn warn_once(obtained: &Obtained) {
    static WARNED: std::sync::Once = std::sync::Once::new();
    if let Some(line) = obtained.warning() {
        WARNED.call_once(|| eprintln!("{line}"));
    }
}

#[cfg(test)]
mod tests;
