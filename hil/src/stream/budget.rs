//! The device's budget in source mode (b): a real board runs the sensor model and the chain per
//! output sample, and a scene that needs more than its budget would fall behind. Before
//! Configure, the session estimates the scene's cost with the firmware's cost model
//! ([`margemu_firmware::budget`], measured on the Cortex-M4F) and refuses a real board's
//! session beyond it, saying what the device, the rate, the cost and the fastest rate that fits
//! are, and how to proceed ([`budget_refusal`]).
//!
//! **Which device is a real board** ([`BoardKind`], `--board`): by default
//! ([`BoardKind::Auto`]) the HelloAck's device ID says: the QEMU board reports
//! `qemu-mps2-an386`, host-run devices (the in-process loopback, the PTY devices of the tests)
//! report all zeros, and a board reports its MCU's unique ID: any other ID is taken for the
//! Black Pill (STM32F411 at 96 MHz, the one real board). QEMU and host-run devices are not
//! budgeted (they are not real time on a fixed clock).
//!
//! ```
//! use margemu_hil::stream::budget::{board_of, BoardKind};
//! let mut id = [0u8; 16];
//! assert_eq!(board_of(BoardKind::Auto, &id), None); // a host-run device
//! id[..15].copy_from_slice(b"qemu-mps2-an386");
//! assert_eq!(board_of(BoardKind::Auto, &id), None);
//! id = [0x37; 16]; // an MCU's unique ID
//! assert_eq!(board_of(BoardKind::Auto, &id).unwrap().name, "blackpill-f411");
//! assert_eq!(board_of(BoardKind::Loopback, &id), None);
//! ```

use margemu_firmware::budget::{Board, Load, BLACKPILL_F411, BUDGET_SHARE, CYCLES_PER_INSTRUCTION};
use margemu_firmware::chip::Chip;
use margemu_firmware::link::setup;
use margemu_protocol::link::Rate;
use margemu_sim::scene::Scene;

use super::model::{device_chip, model_chain_setup};
use super::StreamError;

pub use margemu_firmware::budget::QEMU_DEVICE_ID;

/// What the device is, for the budget (`--board`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoardKind {
    /// From the HelloAck's device ID (see the module docs).
    #[default]
    Auto,
    /// The Black Pill (STM32F411 at 96 MHz): budgeted.
    BlackpillF411,
    /// The QEMU board: not budgeted.
    Qemu,
    /// A host-run device (the loopback): not budgeted.
    Loopback,
}

/// How a session treats the budget.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BudgetPolicy {
    /// What the device is.
    pub board: BoardKind,
    /// Stream a scene beyond a real board's budget anyway (`--over-budget`).
    pub over_budget: bool,
}

impl BudgetPolicy {
    /// For a device the host runs itself: [`BoardKind::Auto`] becomes
    /// [`BoardKind::Loopback`] (an explicit board is kept, to try a board's budget).
    pub fn in_process(self) -> Self {
        let board = match self.board {
            BoardKind::Auto => BoardKind::Loopback,
            b => b,
        };
        Self { board, ..self }
    }
}

/// The real board behind `kind` and the HelloAck's `device_id`; `None` for QEMU and host-run
/// devices.
pub fn board_of(kind: BoardKind, device_id: &[u8]) -> Option<Board> {
    match kind {
        BoardKind::BlackpillF411 => Some(BLACKPILL_F411),
        BoardKind::Qemu | BoardKind::Loopback => None,
        BoardKind::Auto => {
            let host_run = device_id.iter().all(|&b| b == 0);
            let qemu = device_id.starts_with(QEMU_DEVICE_ID)
                && device_id[QEMU_DEVICE_ID.len()..].iter().all(|&b| b == 0);
            (!host_run && !qemu).then_some(BLACKPILL_F411)
        }
    }
}

/// What the device runs per output sample for `scene` in source mode (b) at `rate`: the chip,
/// the model's terms and the chain its AddVibration messages build.
pub fn scene_load(scene: &Scene, rate: Rate) -> Result<Load, StreamError> {
    let model = |reason| StreamError::Model { reason };
    let setup = model_chain_setup(scene, rate).map_err(model)?;
    let chip = device_chip(&scene.chip, rate)?;
    let front = setup::model_chain(&chip.settings(), rate, scene.spec.seed, &setup)
        .transpose()
        .map_err(|e| model(format!("the device's model refuses the chain: {e}")))?;
    let marg = scene.spec.sensors.config();
    let load = Load::output_path(scene.chip.model, &marg, scene.spec.perturbation.is_some());
    Ok(load.with_chain(&setup, front.as_ref()))
}

/// Why `board` (device ID `device_id`) should not run `load` at `rate_hz`, unless the policy
/// says to stream anyway; `None` if it fits (or `policy.over_budget`).
pub fn budget_refusal(
    policy: &BudgetPolicy,
    board: &Board,
    device_id: &[u8],
    load: &Load,
    rate_hz: f64,
) -> Option<String> {
    if policy.over_budget || board.fits(load, rate_hz) {
        return None;
    }
    let per_sample = margemu_firmware::budget::instructions_per_sample(load, rate_hz);
    let max = board.max_rate_hz(load);
    let id: String = device_id.iter().map(|b| format!("{b:02x}")).collect();
    Some(format!(
        "source mode (b) is beyond the {} (device ID {id}, {:.0} MHz): at {rate_hz} Hz its model \
         and chain need ≈ {per_sample:.0} instructions per output sample, {:.1} M instructions/s \
         ({:.0} % of the core at {CYCLES_PER_INSTRUCTION} cycles per instruction), above its \
         budget of {:.1} M/s ({:.0} % of the core; docs/figures.md, \"Source mode (b) on the \
         Cortex-M4F\"); this scene fits up to {:.0} Hz. Lower the rate, drop model terms or \
         chain features (vibration, the internal path), stream register images (--source \
         images), or pass --over-budget to stream anyway",
        board.name,
        board.core_hz / 1e6,
        per_sample * rate_hz / 1e6,
        board.core_share(load, rate_hz) * 100.0,
        board.budget_instructions_per_s() / 1e6,
        BUDGET_SHARE * 100.0,
        max.floor(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_firmware::budget::instructions_per_sample;
    use margemu_protocol::chip::ChipModel;

    fn scene(rate: f64, terms: &str) -> Scene {
        let text = format!(
            "duration = 0.01\nrate = {rate}\nseed = 1\nmotion = \"static\"\n\
             [chip]\nmodel = \"icm42688p\"\n{terms}"
        );
        Scene::parse_str(&text, std::path::Path::new("inline.toml")).unwrap()
    }

    fn load_of(s: &Scene) -> Load {
        scene_load(s, super::super::rate_of(s).unwrap()).unwrap()
    }

    #[test]
    fn the_scene_load_reads_the_chip_and_terms() {
        let ideal = load_of(&scene(1000.0, ""));
        assert_eq!(ideal.chip, ChipModel::Icm42688p);
        assert!(!ideal.eq18 && !ideal.other_terms && !ideal.perturbation);
        let noisy = load_of(&scene(
            1000.0,
            "[sensors.gyro]\nnoise_density = [1e-4, 1e-4, 1e-4]\n",
        ));
        assert!(noisy.eq18);
        assert!(instructions_per_sample(&noisy, 1e3) > instructions_per_sample(&ideal, 1e3));
    }

    #[test]
    fn a_blackpill_refuses_a_scene_beyond_its_budget_and_says_how_to_proceed() {
        let load = load_of(&scene(8000.0, ""));
        let policy = BudgetPolicy::default();
        let id = [0x31u8; 16];
        let refusal = budget_refusal(&policy, &BLACKPILL_F411, &id, &load, 8000.0).unwrap();
        for part in [
            "blackpill-f411",
            "3131313131",
            "96 MHz",
            "at 8000 Hz",
            "≈ 5380 instructions per output sample",
            "budget of 38.4 M/s",
            "fits up to 7137 Hz",
            "--source images",
            "--over-budget",
        ] {
            assert!(refusal.contains(part), "{part:?} missing from: {refusal}");
        }
        // Within the budget, or with the override: streamed.
        assert_eq!(
            budget_refusal(&policy, &BLACKPILL_F411, &id, &load, 7000.0),
            None
        );
        let over = BudgetPolicy {
            over_budget: true,
            ..policy
        };
        assert_eq!(
            budget_refusal(&over, &BLACKPILL_F411, &id, &load, 8000.0),
            None
        );
    }

    #[test]
    fn qemu_and_host_run_devices_are_not_budgeted() {
        let mut qemu = [0u8; 16];
        qemu[..QEMU_DEVICE_ID.len()].copy_from_slice(QEMU_DEVICE_ID);
        assert_eq!(board_of(BoardKind::Auto, &qemu), None);
        assert_eq!(board_of(BoardKind::Auto, &[0; 16]), None);
        assert_eq!(board_of(BoardKind::Qemu, &[7; 16]), None);
        assert_eq!(board_of(BoardKind::Loopback, &[7; 16]), None);
        assert_eq!(
            board_of(BoardKind::BlackpillF411, &qemu),
            Some(BLACKPILL_F411)
        );
        // A longer name that begins like the QEMU board's is a board.
        qemu[QEMU_DEVICE_ID.len()] = b'x';
        assert_eq!(board_of(BoardKind::Auto, &qemu), Some(BLACKPILL_F411));
    }
}
