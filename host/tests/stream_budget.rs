//! Source mode (b)'s budget at the session: a real board is refused a scene beyond its budget
//! before Configure, with a message that names the board, the rate, the cost and the fastest
//! rate that fits, unless the override is set; QEMU and host-run devices are not budgeted. Run
//! on a virtual clock against the real firmware link handler (`VirtualPort`), which reports
//! the all-zero device ID of a host-run device.

mod common;

use common::{config, scratch};
use margemu::scene::Scene;
use margemu::stream::budget::{BoardKind, BudgetPolicy};
use margemu::stream::clock::VirtualClock;
use margemu::stream::{Session, SourceMode, StreamConfig, StreamError, VirtualPort};
use std::path::Path;

/// 20 ms of an ICM-42688-P at 8 kHz with white noise: ≈ 6 400 instructions per output sample
/// on the device, beyond the Black Pill's budget at 8 kHz (it fits up to ≈ 6 kHz).
fn scene() -> Scene {
    let text = "duration = 0.02\nrate = 8000.0\nseed = 3\nmotion = \"static\"\n\
                [chip]\nmodel = \"icm42688p\"\n\
                [sensors.gyro]\nnoise_density = [1e-4, 1e-4, 1e-4]\n";
    Scene::parse_str(text, Path::new("budget.toml")).unwrap()
}

fn stream(name: &str, budget: BudgetPolicy) -> Result<(), StreamError> {
    let clock = VirtualClock::new();
    let device = VirtualPort::<4096>::new(clock.clone(), 1_000_000);
    let config = StreamConfig {
        port: "virtual".into(),
        source: SourceMode::Model {
            kinematics_hz: None,
        },
        budget,
        ..config()
    };
    let session = Session::new(&scene(), config, &scratch(&format!("budget-{name}"))).unwrap();
    session.run_with(device, |_| {}).map(|_| ())
}

#[test]
fn a_real_board_is_refused_a_scene_beyond_its_budget() {
    let board = BudgetPolicy {
        board: BoardKind::BlackpillF411,
        over_budget: false,
    };
    let err = stream("refused", board).unwrap_err();
    let StreamError::Unsupported { reason } = &err else {
        panic!("{err}");
    };
    for part in [
        "source mode (b) is beyond the blackpill-f411",
        "at 8000 Hz",
        "instructions per output sample",
        "fits up to",
        "Lower the rate",
        "--source images",
        "--over-budget",
    ] {
        assert!(reason.contains(part), "{part:?} missing from: {reason}");
    }
}

#[test]
fn the_override_streams_it_anyway() {
    let board = BudgetPolicy {
        board: BoardKind::BlackpillF411,
        over_budget: true,
    };
    stream("override", board).unwrap();
}

#[test]
fn host_run_and_qemu_devices_are_not_budgeted() {
    // Auto: the virtual device reports the all-zero device ID of a host-run device.
    stream("auto", BudgetPolicy::default()).unwrap();
    let qemu = BudgetPolicy {
        board: BoardKind::Qemu,
        over_budget: false,
    };
    stream("qemu", qemu).unwrap();
}
