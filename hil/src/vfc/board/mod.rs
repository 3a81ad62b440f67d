//! The flight controller's board: the emulated chip on its bus, driven by a third-party driver
//! crate through margemu's embedded-hal adapters ([`crate::bus`]). One board per chip, chosen
//! by the model of the chip the device was configured with:
//!
//! | model       | board            | driver            | bus            | magnetometer      |
//! |-------------|------------------|-------------------|----------------|-------------------|
//! | MPU-9250    | [`mpu9250`]      | `mpu9250` 0.25    | SPI (or I2C)   | AK8963, in the FIFO |
//! | ICM-42688-P | [`icm42688p`]    | `icm426xx` 0.4    | SPI            | none              |
//!
//! A rig's external compass (IST8310, QMC5883L, RM3100) is not the board's: the flight controller
//! reads it on its own I2C bus ([`super::compass`]) and, when there is one, uses it instead of
//! the board's magnetometer.
//!
//! [`Board`] is the chip-generic face the flight controller ([`super::fc`]) sees:
//! [`Board::init`] sets the device's chip up through the driver and says how the chip now
//! converts samples ([`Setup::configured`], checked against the host's images);
//! [`Board::data_ready`] reads the INT pin like a GPIO; [`Board::read`] returns every sample
//! waiting in the chip's FIFO, oldest first, in the chip's axes ([`Reading`], converted by the
//! chip module or the driver, never by the board); [`Board::to_body`] maps them to the body
//! frame. [`chip_settings`] is what the host must compute its
//! images with for a model (the full scales the model's driver sets).
//!
//! **The chip belongs to the device.** The firmware's link handler owns the chip and latches
//! samples into it; the bus adapters share their target through `Rc<RefCell<_>>`. So each board
//! holds a slot, and for each batch of bus transactions the device's chip is moved into the slot
//! and back afterwards ([`std::mem::swap`]): every byte a driver reads comes from the emulated
//! chip's registers through its bus target, as on a real board, and nothing else touches the
//! device's chip meanwhile.

pub mod icm42688p;
pub mod mpu9250;

pub use mpu9250::{InitReport, BUS};

use super::axes::{BodySample, MagAlignment};
use margemu_firmware::chip::EmulatedChip;
use margemu_firmware::fault::FaultSchedule;
use margemu_protocol::chip::{ChipModel, ChipSettings};

/// A chip the flight controller has no board (no driver) for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the virtual flight controller has no driver for the {}: it runs on the MPU-9250 (`mpu9250` crate) and the ICM-42688-P (`icm426xx` crate)",
    .0.part_name()
)]
pub struct NoBoard(pub ChipModel);

/// The conversion the board of `model` sets its chip to, hence the one the host must compute
/// its register images with.
pub fn chip_settings(model: ChipModel) -> Result<ChipSettings, NoBoard> {
    match model {
        ChipModel::Mpu9250 => Ok(mpu9250::chip_settings()),
        ChipModel::Icm42688p => Ok(icm42688p::chip_settings()),
        other => Err(NoBoard(other)),
    }
}

/// The bus the board of `model` reads its chip on, as named in reports.
pub fn bus(model: ChipModel) -> Option<&'static str> {
    match model {
        ChipModel::Mpu9250 => Some(mpu9250::BUS),
        ChipModel::Icm42688p => Some(icm42688p::BUS),
        _ => None,
    }
}

/// One sample as a board's driver returns it, in SI units and the chip's axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Specific force, m/s², accelerometer axes.
    pub acc: [f64; 3],
    /// Angular rate, rad/s, gyroscope axes.
    pub gyro: [f64; 3],
    /// Magnetic field, µT, in the magnetometer's own axes; `None` on a chip without one.
    pub mag_ut: Option<[f64; 3]>,
}

/// What a board's driver did while setting its chip up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// The chip's model.
    pub model: ChipModel,
    /// WHO_AM_I as the driver read it.
    pub who_am_i: u8,
    /// How the chip converts samples now (read back from the chip after set-up).
    pub configured: ChipSettings,
    /// The chip's output rate under the rate registers the driver wrote, Hz.
    pub rate_hz: f64,
    /// Time the driver asked to wait, ns (not slept).
    pub waited_ns: u64,
    /// The `mpu9250` driver's findings (AK8963, fuse ROM), on an MPU-9250.
    pub mpu9250: Option<InitReport>,
}

/// A board: one chip on its bus with its driver (see the module docs).
#[allow(clippy::large_enum_variant)] // one per flight controller
pub enum Board {
    /// The MPU-9250 through the `mpu9250` crate.
    Mpu9250(mpu9250::Board),
    /// The ICM-42688-P through the `icm426xx` crate.
    Icm42688p(icm42688p::Board),
}

/// The error of a board given a chip of another model than its own.
fn not_mine(board: &Board, chip: &EmulatedChip) -> String {
    use margemu_firmware::chip::Chip as _;
    format!(
        "the board drives a {:?}, but the device's chip is now a {:?}",
        board.model(),
        chip.model()
    )
}

impl Board {
    /// Sets the device's `chip` up through the driver of its model, asking for samples at
    /// `rate_hz`; the board and what it configured. An error names the driver and the cause.
    pub fn init(chip: &mut EmulatedChip, rate_hz: f64) -> Result<(Self, Setup), String> {
        use margemu_firmware::chip::Chip as _;
        let model = chip.model();
        match chip {
            EmulatedChip::Mpu6xxx(c) if model == ChipModel::Mpu9250 => {
                let (board, init) = mpu9250::Board::init(c, rate_hz)
                    .map_err(|e| format!("setting the chip up through the mpu9250 driver: {e}"))?;
                let setup = Setup {
                    model,
                    who_am_i: init.who_am_i,
                    configured: c.settings(),
                    rate_hz: c.output_rate_hz(),
                    waited_ns: u64::from(init.waited_ms) * 1_000_000,
                    mpu9250: Some(init),
                };
                Ok((Self::Mpu9250(board), setup))
            }
            EmulatedChip::Icm42688p(c) => {
                let (board, init) = icm42688p::Board::init(c, rate_hz)
                    .map_err(|e| format!("setting the chip up through the icm426xx driver: {e}"))?;
                let setup = Setup {
                    model,
                    who_am_i: init.who_am_i,
                    configured: c.settings(),
                    rate_hz: c.output_rate_hz(),
                    waited_ns: init.waited_ns,
                    mpu9250: None,
                };
                Ok((Self::Icm42688p(board), setup))
            }
            _ => Err(NoBoard(model).to_string()),
        }
    }

    /// The model this board drives.
    pub fn model(&self) -> ChipModel {
        match self {
            Self::Mpu9250(_) => ChipModel::Mpu9250,
            Self::Icm42688p(_) => ChipModel::Icm42688p,
        }
    }

    /// Whether the chip has a magnetometer (the filter then waits for its first measurement).
    pub fn has_magnetometer(&self) -> bool {
        self.model().has_magnetometer()
    }

    /// Whether the INT pin says samples are waiting (its level, read like a GPIO).
    pub fn data_ready(&self, chip: &EmulatedChip) -> Result<bool, String> {
        match (self, chip) {
            (Self::Mpu9250(b), EmulatedChip::Mpu6xxx(c)) => Ok(b.data_ready(c)),
            (Self::Icm42688p(b), EmulatedChip::Icm42688p(c)) => Ok(b.data_ready(c)),
            _ => Err(not_mine(self, chip)),
        }
    }

    /// Reads the samples waiting in the chip's FIFO, oldest first (the read clears INT): raw
    /// FIFO bursts on the MPU-9250 ([`mpu9250::Board::read`]), the driver's on the ICM-42688-P
    /// ([`icm42688p::Board::read`]); empty after a FIFO overflow, which is counted.
    pub fn read(&mut self, chip: &mut EmulatedChip) -> Result<Vec<Reading>, String> {
        match (&mut *self, &mut *chip) {
            (Self::Mpu9250(b), EmulatedChip::Mpu6xxx(c)) => b.read(c),
            (Self::Icm42688p(b), EmulatedChip::Icm42688p(c)) => b.read(c),
            _ => Err(not_mine(self, chip)),
        }
    }

    /// Keeps the bus faults of the board's bus those of the rig's device 0 (its chip) in
    /// `schedule`.
    pub fn sync_faults(&self, schedule: &FaultSchedule) {
        match self {
            Self::Mpu9250(b) => b.faults().sync(schedule, 0),
            Self::Icm42688p(b) => b.faults().sync(schedule, 0),
        }
    }

    /// FIFO overflows so far (each one flushed the FIFO).
    pub fn overflows(&self) -> u64 {
        match self {
            Self::Mpu9250(b) => b.overflows(),
            Self::Icm42688p(b) => b.overflows(),
        }
    }

    /// A reading of this board in body axes: the board's own axis mapping (`alignment` turns
    /// the MPU-9250's AK8963; a chip without a magnetometer gives a zero field, which the
    /// filters skip and count).
    pub fn to_body(&self, r: &Reading, alignment: &MagAlignment) -> BodySample {
        match self {
            Self::Mpu9250(_) => mpu9250::to_body(r, alignment),
            Self::Icm42688p(_) => icm42688p::to_body(r),
        }
    }
}

/// Runs `f` with the device's `chip` in `slot` (the bus adapters' target), then puts it back:
/// how a board's transactions reach the chip the firmware's device owns.
pub(super) fn on_bus<C, R>(slot: &crate::bus::Shared<C>, chip: &mut C, f: impl FnOnce() -> R) -> R {
    std::mem::swap(chip, &mut *slot.borrow_mut());
    let result = f();
    std::mem::swap(chip, &mut *slot.borrow_mut());
    result
}
