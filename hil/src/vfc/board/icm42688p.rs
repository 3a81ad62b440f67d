//! The ICM-42688-P board: the emulated ICM-42688-P on SPI, driven by the unmodified `icm426xx`
//! crate (0.4, embedded-hal 1.0, its blocking API) through margemu's [`bus::SpiDevice`].
//!
//! **Set-up** is the driver's own `initialize`: soft reset (DEVICE_CONFIG), WHO_AM_I (it refuses
//! anything but 0x47), INT1 latched, active high, push-pull; the FIFO in stop-on-full mode with
//! 20-bit ("high resolution", packet 4) accel + gyro + temperature + timestamp packets,
//! big-endian; GYRO_CONFIG0/ACCEL_CONFIG0 at FS_SEL 0 (±2000 °/s, ±16 g) and the ODR asked for
//! ([`output_data_rate`]: the scene's rate); UI filters and the anti-alias filters of banks 1
//! and 2 for that ODR; a FIFO watermark of one packet routed to INT1 (cleared by the first FIFO
//! byte read); then gyro and accel in low-noise mode (PWR_MGMT0). The driver's delays do not
//! sleep and do not move the chip's clock (the device's scene clock); the time asked for is
//! reported.
//!
//! **Reading.** [`Board::data_ready`] is INT1's level. [`Board::read`] drains the FIFO with the
//! driver's `read_sample` (one SPI burst: INT_STATUS, FIFO_COUNT, one 20-byte packet) until it
//! says no packet is left, so a flight controller that was late for a data-ready loses nothing:
//! the FIFO kept the samples, and the flight controller stamps each from its index in the
//! stream ([`crate::vfc::fc`]). The driver scales the 20-bit values itself, as fixed ±16 g and
//! ±2000 °/s over 2^19 codes: exact for the accelerometer (32768 LSB/g, the emulated chip's
//! 8192 LSB/g on bits 19:2), 550 ppm low for the gyroscope (262.144 codes per °/s where the chip
//! has 262, its 131 LSB/(°/s) on bits 19:1). A flight controller built on this crate sees
//! exactly these values; they stay as they are. The 16-bit data registers (and so the full
//! scales of the host's images) are not read by this driver, but the host must still predict
//! them: [`chip_settings`].
//!
//! **FIFO overflow.** In stop-on-full mode the FIFO keeps its oldest 102 packets and drops new
//! ones once full (the device thread starved for 102 sample periods: 0.1 s at 1 kHz). The driver
//! then reports `FifoOverflow` (having consumed one packet); the board flushes the FIFO through
//! the driver's `reset_fifo`, as its docs advise, returns no samples, and counts the overflow:
//! the flight controller counts the gap as missed samples. (ArduPilot's v3 driver,
//! `libraries/AP_InertialSensor/AP_InertialSensor_Invensensev3.cpp`, reads this chip's FIFO the
//! same way: FIFO_COUNT, a burst of packets, a FIFO reset on overflow.)
//!
//! **Axes.** The body frame is the chip's accel/gyro frame (the chip is mounted with the
//! plate's axes, as the MPU-9250 is); there is no magnetometer ([`to_body`]).

use super::{on_bus, Reading};
use crate::bus::{self, Shared};
use crate::vfc::axes::BodySample;
use icm426xx::{Config, InterruptMode, InterruptPolarity, OutputDataRate, Ready, ICM42688};
use margemu_firmware::chip::Icm42688p as Chip;
use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion};
use margemu_protocol::regmap::icm42688p::image::ImageConfig;
use margemu_protocol::regmap::icm42688p::{AccelFs, GyroFs};

/// The bus, as named in reports (the driver is SPI only).
pub const BUS: &str = "SPI";

/// The accelerometer full scale the driver sets (ACCEL_FS_SEL 0).
pub const ACCEL_FS: AccelFs = AccelFs::G16;
/// The gyroscope full scale the driver sets (GYRO_FS_SEL 0).
pub const GYRO_FS: GyroFs = GyroFs::Dps2000;

/// What the host must assume when it computes register images for a chip this board set up:
/// the full scales above (the 20-bit FIFO values the driver reads have fixed scales anyway).
pub fn image_config() -> ImageConfig {
    ImageConfig {
        accel_fs: ACCEL_FS,
        gyro_fs: GYRO_FS,
    }
}

/// [`image_config`] as the chip boundary's settings of an ICM-42688-P.
pub fn chip_settings() -> ChipSettings {
    ChipSettings {
        model: ChipModel::Icm42688p,
        conversion: Conversion::Icm42688p(image_config()),
    }
}

/// The driver's ODR for `rate_hz`, if it has that one (12.5 Hz to 32 kHz; the chip's
/// accelerometer-only low-power rates below 12.5 Hz are not in the driver).
pub fn output_data_rate(rate_hz: f64) -> Option<OutputDataRate> {
    use OutputDataRate as O;
    let table = [
        (32000.0, O::Hz32000),
        (16000.0, O::Hz16000),
        (8000.0, O::Hz8000),
        (4000.0, O::Hz4000),
        (2000.0, O::Hz2000),
        (1000.0, O::Hz1000),
        (500.0, O::Hz500),
        (200.0, O::Hz200),
        (100.0, O::Hz100),
        (50.0, O::Hz50),
        (25.0, O::Hz25),
        (12.5, O::Hz12_5),
    ];
    table
        .into_iter()
        .find(|(hz, _)| *hz == rate_hz)
        .map(|(_, odr)| odr)
}

/// The driver on SPI.
pub type Driver = ICM42688<bus::SpiDevice<Chip>, Ready>;

/// What the driver did while setting the chip up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitReport {
    /// WHO_AM_I, read back through the driver's register access after set-up.
    pub who_am_i: u8,
    /// Time the driver asked to wait, ns (not slept).
    pub waited_ns: u64,
    /// The conversion the chip applies now (full scales).
    pub image: ImageConfig,
}

/// The ICM-42688-P on the flight controller's SPI bus.
pub struct Board {
    /// The device's chip during a transaction batch; a spare part otherwise.
    slot: Shared<Chip>,
    driver: Driver,
    /// The bus faults of the driver's SPI device.
    faults: bus::BusFaultsHandle<Chip>,
    overflows: u64,
}

/// The driver's sample in the chip's axes; `None` for a packet without accelerometer or
/// gyroscope data (the driver's set-up puts both in every packet).
fn reading(sample: &icm426xx::Sample) -> Option<Reading> {
    let v = |(x, y, z): (f32, f32, f32)| [x, y, z].map(f64::from);
    Some(Reading {
        acc: v(sample.accel?),
        gyro: v(sample.gyro?),
        mag_ut: None,
    })
}

/// A [`Reading`] of this board in body axes: the chip's own axes, no magnetic field (a zero
/// vector, which the filters skip and count in `skipped_mag`).
pub fn to_body(r: &Reading) -> BodySample {
    BodySample {
        gyro: r.gyro,
        acc: r.acc,
        mag_ut: [0.0; 3],
    }
}

impl Board {
    /// Sets the device's `chip` up through the driver (see the module docs) at the ODR of
    /// `rate_hz`, which must be one of the driver's.
    pub fn init(chip: &mut Chip, rate_hz: f64) -> Result<(Self, InitReport), String> {
        let odr = output_data_rate(rate_hz).ok_or_else(|| {
            format!("the driver has no output data rate of {rate_hz} Hz (12.5 Hz to 32 kHz)")
        })?;
        let slot = bus::shared(Chip::new());
        on_bus(&slot, chip, || {
            let clock = bus::Clock::new();
            let config = Config {
                int1_mode: InterruptMode::Latched,
                int1_polarity: InterruptPolarity::ActiveHigh,
                rate: odr,
                timestamps_are_absolute: false,
            };
            let spi = bus::SpiDevice::new(slot.clone());
            let faults = spi.faults();
            let mut driver = ICM42688::new(spi)
                .initialize(bus::Delay::with_clock(clock.clone()), config)
                .map_err(|e| format!("{e:?}"))?;
            let who_am_i = driver
                .ll()
                .bank::<{ icm426xx::register_bank::BANK0 }>()
                .who_am_i()
                .read()
                .map_err(|e| format!("{e:?}"))?
                .value();
            let report = InitReport {
                who_am_i,
                waited_ns: clock.now_ns(),
                image: slot.borrow().image_config(),
            };
            let board = Self {
                slot: slot.clone(),
                driver,
                faults,
                overflows: 0,
            };
            Ok((board, report))
        })
    }

    /// Whether INT1 says the FIFO holds a packet (its level, read like a GPIO; the driver set
    /// it active high).
    pub fn data_ready(&self, chip: &Chip) -> bool {
        chip.int_pin()
    }

    /// Reads every packet in the FIFO, oldest first (see the module docs); empty after an
    /// overflow, which flushes the FIFO.
    pub fn read(&mut self, chip: &mut Chip) -> Result<Vec<Reading>, String> {
        let Self {
            slot,
            driver,
            overflows,
            ..
        } = self;
        on_bus(slot, chip, || {
            let mut out = Vec::new();
            loop {
                match driver.read_sample() {
                    Ok(Some((sample, more))) => {
                        out.push(reading(&sample).ok_or_else(|| {
                            format!("a FIFO packet without accelerometer or gyroscope: {sample:?}")
                        })?);
                        if !more {
                            return Ok(out);
                        }
                    }
                    // FIFO empty (the packet read was the empty marker).
                    Ok(None) => return Ok(out),
                    Err(icm426xx::Error::FifoOverflow) => {
                        *overflows += 1;
                        driver
                            .reset_fifo()
                            .map_err(|e| format!("flushing the FIFO: {e:?}"))?;
                        return Ok(Vec::new());
                    }
                    Err(e) => return Err(format!("{e:?}")),
                }
            }
        })
    }

    /// The bus faults of its SPI device.
    pub fn faults(&self) -> &bus::BusFaultsHandle<Chip> {
        &self.faults
    }

    /// FIFO overflows so far.
    pub fn overflows(&self) -> u64 {
        self.overflows
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_firmware::chip::PhysicalSample;

    #[test]
    fn output_data_rates_of_the_driver() {
        assert!(output_data_rate(200.0).is_some());
        assert!(output_data_rate(1000.0).is_some());
        assert!(output_data_rate(12.5).is_some());
        assert!(output_data_rate(6.25).is_none());
        assert!(output_data_rate(300.0).is_none());
    }

    #[test]
    fn the_driver_sets_the_chip_up_and_drains_the_fifo() {
        let mut chip = Chip::new();
        let (mut board, init) = Board::init(&mut chip, 200.0).unwrap();
        assert_eq!(init.who_am_i, 0x47);
        assert_eq!(init.image, image_config());
        assert!(init.waited_ns >= 1_000_000, "{init:?}");
        assert_eq!(chip.output_rate_hz(), 200.0);
        // The soft reset's RESET_DONE_INT is routed to INT1 at power-on and the driver leaves
        // it so: INT1 is up until the first read of INT_STATUS, which finds the FIFO empty.
        assert!(board.data_ready(&chip));
        assert!(board.read(&mut chip).unwrap().is_empty());
        assert!(!board.data_ready(&chip));
        let sample = |k: u32| PhysicalSample {
            acc: [1.0, -2.0, 9.80665 + f32::from(k as u16)],
            gyr: [0.5, -1.0, 30.0],
            mag: [20.0, -5.0, -40.0],
            temp_c: 30.0,
        };
        // Three samples latched before the board looks: the FIFO keeps them all.
        for k in 1..=3u32 {
            chip.latch_at(&sample(k), u64::from(k) * 5_000_000);
        }
        assert!(board.data_ready(&chip));
        let got = board.read(&mut chip).unwrap();
        assert!(!board.data_ready(&chip), "the read clears INT1");
        assert_eq!(got.len(), 3);
        for (k, r) in (1..=3u32).zip(&got) {
            let s = sample(k);
            let body = to_body(r);
            assert_eq!(body.mag_ut, [0.0; 3]);
            for i in 0..3 {
                // Accelerometer: 18 bits at 8192 LSB/g, exact scale.
                assert!((body.acc[i] - f64::from(s.acc[i])).abs() < 2e-3, "{body:?}");
                // Gyroscope: the driver's scale is 550 ppm low.
                let w = f64::from(s.gyr[i]);
                assert!(
                    (body.gyro[i] - w * 262.0 / 262.144).abs() < 1e-4,
                    "{body:?}"
                );
            }
        }
        assert!(board.read(&mut chip).unwrap().is_empty());
        assert_eq!(board.overflows(), 0);
    }

    #[test]
    fn a_dead_chip_in_a_nak_window_and_reading_after_it() {
        use margemu_firmware::fault::FaultSchedule;
        use margemu_model::fault::{Fault, FaultKind, Window};
        let mut chip = Chip::new();
        let (mut board, _) = Board::init(&mut chip, 200.0).unwrap();
        assert!(board.read(&mut chip).unwrap().is_empty());
        let mut schedule = FaultSchedule::new();
        let window = Window::new(10_000_000, 20_000_000);
        schedule
            .push(Fault::new(0, window, FaultKind::Nak), 1)
            .unwrap();
        board.faults().sync(&schedule, 0);
        let sample = PhysicalSample {
            acc: [1.0, -2.0, 9.8],
            ..PhysicalSample::default()
        };
        // Inside the window the driver reads INT_STATUS as 0xFF, FIFO_FULL set: it takes it
        // for an overflow and flushes the FIFO, a write the dead chip never sees.
        chip.latch_at(&sample, 10_000_000);
        assert!(board.read(&mut chip).unwrap().is_empty());
        assert_eq!(board.overflows(), 1);
        // After the window both samples are read: the flush was lost.
        chip.latch_at(&sample, 20_000_000);
        assert_eq!(board.read(&mut chip).unwrap().len(), 2);
        assert_eq!(board.overflows(), 1);
    }

    #[test]
    fn an_overflow_flushes_the_fifo_and_reading_resumes() {
        let mut chip = Chip::new();
        let (mut board, _) = Board::init(&mut chip, 1000.0).unwrap();
        let at_rest = PhysicalSample {
            acc: [0.0, 0.0, 9.80665],
            temp_c: 25.0,
            ..Default::default()
        };
        // 150 periods unread: the FIFO (102 packets) overflows.
        for k in 1..=150u64 {
            chip.latch_at(&at_rest, k * 1_000_000);
        }
        assert!(board.read(&mut chip).unwrap().is_empty());
        assert_eq!(board.overflows(), 1);
        chip.latch_at(&at_rest, 151_000_000);
        let got = board.read(&mut chip).unwrap();
        assert_eq!(got.len(), 1);
        assert!((got[0].acc[2] - 9.80665).abs() < 1e-3, "{got:?}");
    }
}
