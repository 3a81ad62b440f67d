//! The flight controller's external compass: a standalone magnetometer of the scene's rig
//! (IST8310, QMC5883L or RM3100) on the board's I2C bus, read at 100 Hz with raw register transactions
//! the way ArduPilot's compass backends do, and turned into the IMU's axes.
//!
//! **Which compass.** A real flight controller is told where its compass sits by its
//! configuration (ArduPilot's `COMPASS_ORIENT`, PX4's `CAL_MAG0_ROT`); this one reads it off the
//! scene ([`CompassConfig::for_scene`]): the first device after the IMU whose model is a
//! magnetometer alone, its I2C address, the range the host computes its images with, and both
//! devices' mounting rotations. The compass's reading `v_c` (its own axes) is turned into the
//! IMU's axes, the flight controller's body frame, as `v_imu = R_imu · R_cᵀ · v_c` (each `R` is
//! a scene `rotation`, plate → chip axes;
//! [`axes_between`]).
//!
//! **The bus.** The chip belongs to the device's rig, as the IMU does (see [`super::board`]):
//! for each batch of transactions the chip answering the compass's address
//! ([`Rig::i2c_target`]) is moved into the slot behind margemu's I2C adapter ([`bus::I2c`]) and
//! back afterwards. An address nobody answers is an absent compass.
//!
//! **Set-up** ([`Compass::init`]), from ArduPilot's `libraries/AP_Compass/AP_Compass_IST8310.cpp`
//! and `AP_Compass_QMC5883L.cpp` (described, not copied):
//! - IST8310: WAI (0x00) must read 0x10; a soft reset (CNTL2 = SRST), then CNTL2 is read until
//!   SRST has cleared (up to 5 tries, 10 ms apart); AVGCNTL = 0x24 (16 times averaging on
//!   every axis), PDCNTL = 0xC0; then the first single measurement (CNTL1 = 1).
//! - QMC5883L: one read of 0x00 first (ArduPilot's note: other devices on the bus can upset the
//!   chip until it has been read once), then 0x0C must read 0x01 and 0x0D 0xFF; SET/RESET period
//!   0x0B = 0x01, the undocumented 0x20 = 0x40 and 0x21 = 0x01; CONF1 = continuous, 100 Hz,
//!   OSR 512, read back. ArduPilot sets the ±8 G range; this board sets the range the host
//!   computes its images with (the scene's `mag_range`, ±2 G at power-on), as a configuration
//!   would, since the data registers carry counts at the host's range.
//!
//! - RM3100 (`AP_Compass_RM3100.cpp`): the cycle counts of x, y, z written (200, 0x00C8) and read
//!   back as its identity check (the part has no WHO_AM_I; REVID is read for the record), TMRC =
//!   0x94, then continuous measurement of x, y, z (CMM = 0x71).
//!
//! A wrong identity, or nothing at the address, stops the flight controller with the reason.
//! The waits are counted, not slept, and do not move the chip's clock.
//!
//! **Reading** ([`Compass::poll`]) every 10 ms on the device clock, counted from the previous
//! reading (ArduPilot re-arms its periodic callback after each reading):
//! - IST8310: one burst of 7 bytes from STAT1 (0x02): DRDY, then the data registers 0x03–0x08,
//!   as PX4's driver reads them; ArduPilot reads the 6 data bytes from 0x03 without looking at
//!   DRDY, which at 10 ms after a 6.1 ms measurement gives the same data. Then the next single
//!   measurement. A poll that finds DRDY clear takes nothing and tries again at the next turn.
//! - QMC5883L: STATUS (0x06), and when DRDY (bit 0) is set, the 6 data bytes from 0x00.
//!   ArduPilot tests bit 2 instead, which the datasheet names DOR (a measurement was skipped):
//!   against the chip that driver reads every second measurement (the firmware's
//!   `tests/qmc5883l/fc_ardupilot.rs` shows it); this board reads every one.
//!
//! - RM3100: STATUS (0x34), and when DRDY (bit 7) is set, the 9 result bytes from 0x24.
//!
//! Counts become µT through the chip module (`margemu_protocol::regmap::{ist8310, qmc5883l}`
//! `field_ut`), never here. ArduPilot also flips the IST8310's z and the QMC5883L's x and z to
//! its own conventions; in margemu the chip's data axes are the ones the scene's `rotation` names,
//! so the rotation alone turns them.

use super::board::on_bus;
use crate::bus::{self, Shared};
use embedded_hal::i2c::I2c as _;
use margemu_firmware::chip::{Chip as _, EmulatedChip};
use margemu_firmware::fault::FaultSchedule;
use margemu_firmware::link::rig::Rig;
use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion};
use margemu_protocol::regmap::mag_image;
use margemu_protocol::regmap::{ist8310, qmc5883l, rm3100};
use margemu_sim::scene::chip::{axes_between, rotate, Rotation};
use margemu_sim::scene::Scene;

/// ArduPilot's compass period: 10 ms (100 Hz).
pub const PERIOD_NS: u64 = 10_000_000;

/// CONF1 mode and rate bits the board writes: continuous (01), 100 Hz (10 in bits 3:2), OSR 512
/// (00 in bits 7:6); the range bits are added.
const QMC_CONF1_CONTINUOUS_100HZ: u8 = 0x01 | 0x02 << 2;

/// What the flight controller is told about its external compass (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct CompassConfig {
    /// The device's name in the scene.
    pub name: String,
    /// The model the flight controller expects.
    pub model: ChipModel,
    /// Its 7-bit I2C address.
    pub address: u8,
    /// The conversion the host computes the compass's images with (the QMC5883L's range).
    pub settings: ChipSettings,
    /// Compass axes → IMU axes
    /// ([`axes_between`]).
    pub to_body: Rotation,
}

impl CompassConfig {
    /// The scene's external compass: its first device after the IMU whose model is a
    /// magnetometer alone (on I2C, the only bus those have), or `None`.
    pub fn for_scene(scene: &Scene) -> Option<Self> {
        let device = scene
            .other_devices
            .iter()
            .find(|d| d.chip.model.is_magnetometer_only())?;
        Some(Self {
            name: device.name.clone(),
            model: device.chip.model,
            address: device.chip.i2c_address,
            settings: device.chip.settings,
            to_body: axes_between(device.chip.rotation, scene.chip.rotation),
        })
    }
}

/// What the compass answered at set-up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompassSetup {
    /// Its model.
    pub model: ChipModel,
    /// Its I2C address.
    pub address: u8,
    /// The identity register the driver checks: the IST8310's WAI, the QMC5883L's 0x0D.
    pub identity: u8,
    /// Time the set-up asked to wait, ns (not slept).
    pub waited_ns: u64,
}

/// The flight controller's I2C bus, on the slot.
type Bus = bus::I2c<EmulatedChip>;

/// The compass on the flight controller's I2C bus.
pub struct Compass {
    config: CompassConfig,
    /// The rig's compass during a transaction batch; a spare part otherwise.
    slot: Shared<EmulatedChip>,
    i2c: Bus,
    /// The device-clock instant of the next poll.
    next_poll_ns: u64,
    /// Polls that found no new measurement.
    not_ready: u64,
    /// Polls whose transactions failed.
    failed: u64,
}

fn read(i2c: &mut Bus, address: u8, register: u8, buf: &mut [u8]) -> Result<(), String> {
    i2c.write_read(address, &[register], buf)
        .map_err(|e| format!("reading register {register:#04x}: {e}"))
}

fn read_byte(i2c: &mut Bus, address: u8, register: u8) -> Result<u8, String> {
    let mut value = [0u8; 1];
    read(i2c, address, register, &mut value)?;
    Ok(value[0])
}

fn write(i2c: &mut Bus, address: u8, register: u8, value: u8) -> Result<(), String> {
    i2c.write(address, &[register, value])
        .map_err(|e| format!("writing {value:#04x} to register {register:#04x}: {e}"))
}

/// `got` must be `want`, else the device is not the compass.
fn expect(what: &str, register: u8, got: u8, want: u8) -> Result<(), String> {
    match got == want {
        true => Ok(()),
        false => Err(format!(
            "register {register:#04x} reads {got:#04x}, not the {what}'s {want:#04x}"
        )),
    }
}

impl Compass {
    /// Finds the compass of `config` in `rig`, checks its identity and sets it up (see the
    /// module docs) at the device-clock instant `now_ns`; the first poll is one period later.
    pub fn init(
        rig: &mut Rig,
        config: &CompassConfig,
        now_ns: u64,
    ) -> Result<(Self, CompassSetup), String> {
        let slot = bus::shared(EmulatedChip::default());
        let mut compass = Self {
            config: config.clone(),
            i2c: bus::I2c::new(slot.clone()),
            slot,
            next_poll_ns: now_ns + PERIOD_NS,
            not_ready: 0,
            failed: 0,
        };
        let setup = compass
            .on_bus(rig, |i2c, c| match c.model {
                ChipModel::Ist8310 => ist8310_init(i2c, c.address),
                ChipModel::Qmc5883l => qmc5883l_init(i2c, c.address, &c.settings),
                ChipModel::Rm3100 => rm3100_init(i2c, c.address),
                other => Err(format!(
                    "the {} is no compass this flight controller drives (IST8310, QMC5883L, \
                     RM3100)",
                    other.part_name()
                )),
            })
            .map_err(|e| compass.fail(&e))?;
        Ok((compass, setup))
    }

    /// Polls the compass at the device-clock instant `now_ns` (see the module docs): its new
    /// measurement in µT in the IMU's axes when one is due and ready, else `None`.
    pub fn poll(&mut self, rig: &mut Rig, now_ns: u64) -> Result<Option<[f64; 3]>, String> {
        if now_ns < self.next_poll_ns {
            return Ok(None);
        }
        let address = self.config.address;
        if rig.i2c_target(address).is_none() {
            return Err(self.fail(&format!("no device answers I2C address {address:#04x}")));
        }
        let read = self.on_bus(rig, |i2c, c| match c.settings.conversion {
            Conversion::Qmc5883l(range) => {
                Ok(qmc5883l_read(i2c, c.address)?.map(|raw| qmc5883l::field_ut(raw, range)))
            }
            Conversion::Rm3100(cycle_counts) => {
                Ok(rm3100_read(i2c, c.address)?.map(|raw| rm3100::field_ut(raw, cycle_counts)))
            }
            _ => Ok(ist8310_read(i2c, c.address)?.map(ist8310::field_ut)),
        });
        // A failed transaction (a NACK, a corrupted status, a timeout: the bus faults) loses
        // this poll only; the next one is a period later, as ArduPilot's and PX4's compass
        // drivers retry at their next cycle.
        let Ok(field) = read else {
            self.failed += 1;
            self.next_poll_ns = now_ns + PERIOD_NS;
            return Ok(None);
        };
        let Some(ut) = field else {
            self.not_ready += 1;
            return Ok(None);
        };
        self.next_poll_ns = now_ns + PERIOD_NS;
        Ok(Some(rotate(&self.config.to_body, ut)))
    }

    /// Keeps the bus faults of its I2C bus those of the rig's device at its address in
    /// `schedule` (none while no device answers it).
    pub fn sync_faults(&self, rig: &Rig, schedule: &FaultSchedule) {
        let address = Some(self.config.address);
        let device = rig
            .chips()
            .position(|c| c.i2c_addresses_now().contains(&address));
        if let Some(device) = device.and_then(|d| u8::try_from(d).ok()) {
            self.i2c.faults().sync(schedule, device);
        }
    }

    /// Polls that found no new measurement so far.
    pub fn not_ready(&self) -> u64 {
        self.not_ready
    }

    /// Polls whose transactions failed so far (each retried a period later).
    pub fn failed(&self) -> u64 {
        self.failed
    }

    /// Runs `f` on the bus with the rig's chip at the compass's address in the slot.
    fn on_bus<R>(
        &mut self,
        rig: &mut Rig,
        f: impl FnOnce(&mut Bus, &CompassConfig) -> Result<R, String>,
    ) -> Result<R, String> {
        let address = self.config.address;
        let chip = rig
            .i2c_target(address)
            .ok_or_else(|| format!("no device answers I2C address {address:#04x}"))?;
        let Self {
            slot, i2c, config, ..
        } = self;
        on_bus(slot, chip, || f(i2c, config))
    }

    /// The reason the flight controller stops for a compass error.
    fn fail(&self, why: &str) -> String {
        let c = &self.config;
        format!(
            "the compass `{}` ({} at I2C {:#04x}): {why}",
            c.name,
            c.model.part_name(),
            c.address
        )
    }
}

fn ist8310_init(i2c: &mut Bus, address: u8) -> Result<CompassSetup, String> {
    use ist8310::{bits, reg, WAI_VALUE};
    let wai = read_byte(i2c, address, reg::WAI)?;
    expect("IST8310", reg::WAI, wai, WAI_VALUE)?;
    let mut waited_ns = 0;
    let mut reset = false;
    for _ in 0..5 {
        write(i2c, address, reg::CNTL2, bits::CNTL2_SRST)?;
        waited_ns += 10_000_000;
        if read_byte(i2c, address, reg::CNTL2)? & bits::CNTL2_SRST == 0 {
            reset = true;
            break;
        }
    }
    if !reset {
        return Err("CNTL2.SRST did not clear after 5 soft resets".into());
    }
    write(i2c, address, reg::AVGCNTL, 0x24)?;
    write(i2c, address, reg::PDCNTL, bits::PDCNTL_PD)?;
    write(i2c, address, reg::CNTL1, 0x01)?;
    Ok(CompassSetup {
        model: ChipModel::Ist8310,
        address,
        identity: wai,
        waited_ns,
    })
}

/// The data registers of a completed measurement, and the next one started; `None` (nothing
/// started) while DRDY is clear.
fn ist8310_read(i2c: &mut Bus, address: u8) -> Result<Option<[i16; 3]>, String> {
    use ist8310::{bits, reg};
    let mut burst = [0u8; 7];
    read(i2c, address, reg::STAT1, &mut burst)?;
    let [stat1, data @ ..] = burst;
    if stat1 & bits::STAT1_DRDY == 0 {
        return Ok(None);
    }
    write(i2c, address, reg::CNTL1, 0x01)?;
    Ok(Some(mag_image::parse(&data)))
}

fn qmc5883l_init(
    i2c: &mut Bus,
    address: u8,
    settings: &ChipSettings,
) -> Result<CompassSetup, String> {
    use qmc5883l::{reg, CHIP_ID_VALUE, REG_0C_VALUE};
    let Conversion::Qmc5883l(range) = settings.conversion else {
        return Err(format!(
            "the host computes its images as {:?}, not a QMC5883L's",
            settings.conversion
        ));
    };
    read_byte(i2c, address, reg::XOUT_L)?;
    let c = read_byte(i2c, address, reg::RESERVED_0C)?;
    expect("QMC5883L", reg::RESERVED_0C, c, REG_0C_VALUE)?;
    let id = read_byte(i2c, address, reg::CHIP_ID)?;
    expect("QMC5883L", reg::CHIP_ID, id, CHIP_ID_VALUE)?;
    let conf1 = QMC_CONF1_CONTINUOUS_100HZ | range.conf1_bits();
    for (register, value) in [
        (reg::PERIOD, 0x01),
        (reg::UNDOC_20, 0x40),
        (reg::UNDOC_21, 0x01),
        (reg::CONF1, conf1),
    ] {
        write(i2c, address, register, value)?;
    }
    let back = read_byte(i2c, address, reg::CONF1)?;
    if back != conf1 {
        return Err(format!(
            "CONF1 reads {back:#04x} after {conf1:#04x} was written"
        ));
    }
    Ok(CompassSetup {
        model: ChipModel::Qmc5883l,
        address,
        identity: id,
        waited_ns: 0,
    })
}

/// The data registers when STATUS.DRDY says a measurement is new; `None` otherwise.
fn qmc5883l_read(i2c: &mut Bus, address: u8) -> Result<Option<[i16; 3]>, String> {
    use qmc5883l::{bits, reg};
    if read_byte(i2c, address, reg::STATUS)? & bits::STATUS_DRDY == 0 {
        return Ok(None);
    }
    let mut data = [0u8; 6];
    read(i2c, address, reg::XOUT_L, &mut data)?;
    Ok(Some(mag_image::parse(&data)))
}

#[cfg(test)]
mod tests;

fn rm3100_init(i2c: &mut Bus, address: u8) -> Result<CompassSetup, String> {
    use rm3100::{reg, reset};
    let counts = reset::CYCLE_COUNT.to_be_bytes();
    let mut write_counts = [0u8; 7];
    write_counts[0] = reg::CCX;
    for pair in write_counts[1..].chunks_exact_mut(2) {
        pair.copy_from_slice(&counts);
    }
    i2c.write(address, &write_counts)
        .map_err(|e| format!("writing the cycle counts: {e}"))?;
    let mut back = [0u8; 6];
    read(i2c, address, reg::CCX, &mut back)?;
    if back.chunks_exact(2).any(|c| c != counts) {
        return Err(format!(
            "the cycle counts read {back:02x?}, not the {:#06x} written",
            reset::CYCLE_COUNT
        ));
    }
    let revid = read_byte(i2c, address, reg::REVID)?;
    write(i2c, address, reg::TMRC, 0x94)?;
    write(i2c, address, reg::CMM, 0x71)?;
    Ok(CompassSetup {
        model: ChipModel::Rm3100,
        address,
        identity: revid,
        waited_ns: 0,
    })
}

/// The results when STATUS.DRDY says a measurement is new; `None` otherwise.
fn rm3100_read(i2c: &mut Bus, address: u8) -> Result<Option<[i32; 3]>, String> {
    use rm3100::{bits, reg};
    if read_byte(i2c, address, reg::STATUS)? & bits::STATUS_DRDY == 0 {
        return Ok(None);
    }
    let mut data = [0u8; rm3100::IMAGE_LEN];
    read(i2c, address, reg::MX, &mut data)?;
    Ok(Some(rm3100::parse_image(&data)))
}
