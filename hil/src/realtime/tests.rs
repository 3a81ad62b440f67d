//! The fallback paths, on a fake [`Scheduler`] that records what it was asked.

use super::*;

/// A scheduler whose calls fail as told, and that remembers the thread's policy.
struct Fake {
    set_fails: Option<Errno>,
    lock_limit: Option<String>,
    policy: Mutex<Policy>,
    locked: Mutex<bool>,
}

impl Fake {
    fn new(set_fails: Option<Errno>, lock_limit: Option<&str>) -> Arc<Self> {
        Arc::new(Self {
            set_fails,
            lock_limit: lock_limit.map(str::to_owned),
            policy: Mutex::new(Policy {
                policy: libc::SCHED_OTHER,
                priority: 0,
            }),
            locked: Mutex::new(false),
        })
    }

    fn policy(&self) -> Policy {
        *self.policy.lock().unwrap()
    }
}

impl Scheduler for Fake {
    fn current(&self) -> Result<Policy, Errno> {
        Ok(self.policy())
    }
    fn set(&self, policy: Policy) -> Result<(), Errno> {
        match self.set_fails {
            Some(e) if policy.policy == libc::SCHED_FIFO => Err(e),
            _ => {
                *self.policy.lock().unwrap() = policy;
                Ok(())
            }
        }
    }
    fn memory_lock_limit(&self) -> Option<String> {
        self.lock_limit.clone()
    }
    fn lock_memory(&self) -> Result<(), Errno> {
        *self.locked.lock().unwrap() = true;
        Ok(())
    }
    fn unlock_memory(&self) {
        *self.locked.lock().unwrap() = false;
    }
    fn rtprio_limit(&self) -> u64 {
        0
    }
}

/// Memory locking is one lock per process: the tests that take it run one at a time.
static SERIAL: Mutex<()> = Mutex::new(());

#[test]
fn options_parse_and_print_back() {
    for (text, r) in [
        ("off", Realtime::Off),
        ("auto", Realtime::Auto),
        ("10", Realtime::Priority(10)),
        ("99", Realtime::Priority(99)),
    ] {
        assert_eq!(text.parse::<Realtime>(), Ok(r));
        assert_eq!(r.to_string(), text);
    }
    for bad in ["0", "100", "on", "", "-1"] {
        let e = bad.parse::<Realtime>().unwrap_err();
        assert!(
            e.contains("off, auto or a SCHED_FIFO priority 1 to 99"),
            "{e}"
        );
    }
    assert_eq!(Realtime::default(), Realtime::Off);
    assert_eq!(Realtime::Auto.priority(), Some(DEFAULT_PRIORITY));
}

#[test]
fn off_changes_nothing() {
    let fake = Fake::new(None, None);
    let (guard, got) = enter(Realtime::Off, fake.clone());
    assert_eq!(fake.policy().policy, libc::SCHED_OTHER);
    assert_eq!(got.to_string(), "normal priority (realtime off)");
    assert_eq!(got.warning(), None);
    drop(guard);
}

#[test]
fn fifo_and_locked_memory_then_restored() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let fake = Fake::new(None, None);
    let (guard, got) = enter(Realtime::Priority(12), fake.clone());
    assert_eq!(
        fake.policy(),
        Policy {
            policy: libc::SCHED_FIFO,
            priority: 12
        }
    );
    assert!(*fake.locked.lock().unwrap());
    assert_eq!(got.to_string(), "SCHED_FIFO 12, memory locked");
    assert_eq!(got.warning(), None);
    drop(guard);
    assert_eq!(fake.policy().policy, libc::SCHED_OTHER);
    assert!(!*fake.locked.lock().unwrap());
}

#[test]
fn eperm_falls_back_to_normal_priority_with_one_warning() {
    let fake = Fake::new(Some(libc::EPERM), None);
    let (guard, got) = enter(Realtime::Auto, fake.clone());
    assert_eq!(fake.policy().policy, libc::SCHED_OTHER);
    assert!(!*fake.locked.lock().unwrap(), "nothing locked either");
    assert_eq!(
        got.to_string(),
        "normal priority: SCHED_FIFO 10 refused: EPERM (no CAP_SYS_NICE and RLIMIT_RTPRIO 0)"
    );
    let warning = got.warning().expect("a warning");
    assert!(!warning.contains('\n'), "one line: {warning}");
    for what in [
        "EPERM",
        "setcap cap_sys_nice",
        "ulimit -r 10",
        "/etc/security/limits.conf",
        "--realtime off",
    ] {
        assert!(warning.contains(what), "{what} missing from {warning}");
    }
    drop(guard);
    assert_eq!(fake.policy().policy, libc::SCHED_OTHER);
}

#[test]
fn memory_left_unlocked_beyond_the_rlimit() {
    let fake = Fake::new(None, Some("RLIMIT_MEMLOCK is 8192 KB and no CAP_IPC_LOCK"));
    let (guard, got) = enter(Realtime::Auto, fake.clone());
    assert!(!*fake.locked.lock().unwrap());
    assert_eq!(
        got.to_string(),
        "SCHED_FIFO 10, memory not locked: RLIMIT_MEMLOCK is 8192 KB and no CAP_IPC_LOCK"
    );
    assert!(got.warning().unwrap().contains("ulimit -l unlimited"));
    drop(guard);
}

#[test]
fn a_session_refused_realtime_records_it_and_goes_on() {
    use crate::stream::clock::VirtualClock;
    use crate::stream::{Session, StreamConfig, VirtualPort};
    let text = "duration = 0.05\nrate = 1000.0\nseed = 1\nmotion = \"kinematic\"\n";
    let scene = margemu_sim::scene::Scene::parse_str(text, "rt.toml".as_ref()).unwrap();
    let dir = std::env::temp_dir().join(format!("margemu-rt-refused-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let clock = VirtualClock::new();
    let device = VirtualPort::<256>::new(clock.clone(), 1_000_000);
    let config = StreamConfig {
        realtime: Realtime::Auto,
        ..StreamConfig::default()
    };
    let mut session = Session::new(&scene, config, &dir).unwrap();
    let fake = Fake::new(Some(libc::EPERM), None);
    session.set_scheduler(fake.clone());
    let summary = session.run_with(device, |_| {}).unwrap();
    assert_eq!(summary.served.byte_exact, 50, "the session went on");
    assert_eq!(fake.policy().policy, libc::SCHED_OTHER);
    let line =
        "normal priority: SCHED_FIFO 10 refused: EPERM (no CAP_SYS_NICE and RLIMIT_RTPRIO 0)";
    assert_eq!(summary.pacing.to_string(), line);
    let events = std::fs::read_to_string(dir.join("events.csv")).unwrap();
    let row = events
        .lines()
        .find(|l| l.contains(",pacing,"))
        .expect("a pacing row");
    assert_eq!(row, format!("0,pacing,{line}"));
    let _ = std::fs::remove_dir_all(&dir);
}
