//! [`SystemScheduler`]: the [`Scheduler`] calls made for real (POSIX threads, `mlockall`,
//! `getrlimit`, the effective capabilities in `/proc/self/status`): the crate's only calls
//! into the C library, each behind a checked return code.

#![allow(unsafe_code)]

use super::{Errno, Policy, Scheduler};

/// The operating system's scheduler and memory locking.
#[derive(Clone, Copy, Debug, Default)]
pub struct SystemScheduler;

/// `CAP_IPC_LOCK`'s bit in the capability sets (linux/capability.h).
const CAP_IPC_LOCK: u32 = 14;

/// The soft limit of `resource`, `None` if unlimited (or unreadable).
fn soft_limit(resource: libc::__rlimit_resource_t) -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: `limit` is a valid, writable rlimit.
    let rc = unsafe { libc::getrlimit(resource, &mut limit) };
    (rc == 0 && limit.rlim_cur != libc::RLIM_INFINITY).then_some(limit.rlim_cur)
}

/// Whether the process's effective capabilities include `cap`.
fn has_capability(cap: u32) -> bool {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else {
        return false;
    };
    status
        .lines()
        .find_map(|l| l.strip_prefix("CapEff:"))
        .and_then(|hex| u64::from_str_radix(hex.trim(), 16).ok())
        .is_some_and(|caps| caps >> cap & 1 == 1)
}

impl Scheduler for SystemScheduler {
    fn current(&self) -> Result<Policy, Errno> {
        let mut policy = 0;
        let mut param = libc::sched_param { sched_priority: 0 };
        // SAFETY: both out-pointers are valid; `pthread_self` is the calling thread.
        let rc =
            unsafe { libc::pthread_getschedparam(libc::pthread_self(), &mut policy, &mut param) };
        match rc {
            0 => Ok(Policy {
                policy,
                priority: param.sched_priority,
            }),
            e => Err(e),
        }
    }

    fn set(&self, p: Policy) -> Result<(), Errno> {
        let param = libc::sched_param {
            sched_priority: p.priority,
        };
        // SAFETY: `param` is a valid sched_param; `pthread_self` is the calling thread.
        match unsafe { libc::pthread_setschedparam(libc::pthread_self(), p.policy, &param) } {
            0 => Ok(()),
            e => Err(e),
        }
    }

    fn memory_lock_limit(&self) -> Option<String> {
        if has_capability(CAP_IPC_LOCK) {
            return None;
        }
        soft_limit(libc::RLIMIT_MEMLOCK).map(|bytes| {
            format!(
                "RLIMIT_MEMLOCK is {} KB and no CAP_IPC_LOCK (locking all \
                 memory could then make an allocation fail)",
                bytes / 1024
            )
        })
    }

    fn lock_memory(&self) -> Result<(), Errno> {
        // SAFETY: no pointers; affects only the process's paging.
        match unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } {
            0 => Ok(()),
            _ => Err(std::io::Error::last_os_error().raw_os_error().unwrap_or(0)),
        }
    }

    fn unlock_memory(&self) {
        // SAFETY: no pointers; affects only the process's paging.
        unsafe { libc::munlockall() };
    }

    fn rtprio_limit(&self) -> u64 {
        soft_limit(libc::RLIMIT_RTPRIO).unwrap_or(u64::MAX)
    }
}
