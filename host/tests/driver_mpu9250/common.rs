// The body shared by both buses, included once per copy of the `mpu9250` crate: the including
// module names the copy `mpu9250` (see `driver_mpu9250.rs`).

use embedded_hal::delay::DelayNs;
use embedded_hal_compat::ReverseCompat;
use margemu::bus::{self, Clock, Shared};
use margemu::marg::MargSim;
use margemu::run::collect;
use margemu::scene::Scene;
use margemu_firmware::chip::{Mpu6xxx as Chip, PhysicalSample};
use margemu_protocol::regmap::ak8963::MagBits;
use margemu_protocol::regmap::mpu6xxx::convert::{
    asa_factor, mag_axes_from_mpu, temp_to_raw, STANDARD_GRAVITY, TEMP_LSB_PER_C, TEMP_OFFSET_C,
};
use margemu_protocol::regmap::mpu6xxx::{AccelFs, GyroFs};
use self::mpu9250::{
    AccelDataRate, AccelScale, Dlpf, GyroScale, GyroTempDataRate, MagScale, Marg, MpuConfig,
};
use std::path::Path;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

/// Temperature of the scene: °C at t = 0 and °C/s.
const TEMPERATURE: [f64; 2] = [30.0, 4.0];
/// Output rate the tests configure: DLPF_CFG = 1 (1 kHz internal) and SMPLRT_DIV = 9.
const RATE_HZ: f64 = 100.0;
const SMPLRT_DIV: u8 = 9;

const ACCEL_SCALES: [(AccelScale, f64); 4] = [
    (AccelScale::_2G, 2.0),
    (AccelScale::_4G, 4.0),
    (AccelScale::_8G, 8.0),
    (AccelScale::_16G, 16.0),
];
const GYRO_SCALES: [(GyroScale, f64); 4] = [
    (GyroScale::_250DPS, 250.0),
    (GyroScale::_500DPS, 500.0),
    (GyroScale::_1000DPS, 1000.0),
    (GyroScale::_2000DPS, 2000.0),
];
const MAG_SCALES: [(MagScale, MagBits); 2] = [
    (MagScale::_14BITS, MagBits::Bits14),
    (MagScale::_16BITS, MagBits::Bits16),
];

/// Roll, pitch, yaw and x/z translation, all moving: up to 2.4 g of specific force and 270 °/s
/// of body rate on one axis, so ±2 g and ±250 °/s saturate now and then (the chip clips, the
/// expectation below clips the same way). Field in µT (|B| = 49 µT); 30 → 38 °C; a little
/// sensor noise, so what is compared is the model's reading, not the bare truth.
fn scene_text(rate_hz: f64) -> String {
    format!(
        "duration = 2.0\nrate = {rate_hz}\nseed = 7\nmotion = \"kinematic\"\n\
         [field]\nreference = [20.0, 0.0, -45.0]\nunit = \"uT\"\n\
         [joints.x]\ntype = \"sine\"\namplitude = 0.06\nfrequency = 3.0\n\
         [joints.z]\ntype = \"sine\"\namplitude = 0.02\nfrequency = 2.5\n\
         [joints.roll]\ntype = \"sine\"\namplitude = 0.6\nfrequency = 0.7\n\
         [joints.pitch]\ntype = \"sine\"\namplitude = 0.4\nfrequency = 1.1\n\
         [joints.yaw]\ntype = \"sine\"\namplitude = 1.5\nfrequency = 0.5\n\
         [sensors]\ntemperature = [{}, {}]\n\
         [sensors.gyro]\nnoise_density = [0.002, 0.002, 0.002]\n\
         [sensors.accel]\nnoise_density = [0.005, 0.005, 0.005]\n\
         [sensors.mag]\nnoise_density = [0.05, 0.05, 0.05]\n",
        TEMPERATURE[0], TEMPERATURE[1]
    )
}

/// The scene's MARG samples as the chip's sensors see them, with their instants (ns).
fn scene_samples(rate_hz: f64) -> Vec<(u64, PhysicalSample)> {
    let text = scene_text(rate_hz);
    let scene = Scene::parse_str(&text, Path::new("driver.toml")).unwrap_or_else(|e| panic!("{e}"));
    let mut marg = MargSim::new(&scene).unwrap();
    collect(&scene)
        .unwrap()
        .iter()
        .map(|t| {
            let m = marg.sample(t).sample;
            let t_s = t.t_ns as f64 * 1e-9;
            let sample = PhysicalSample {
                acc: m.acc,
                gyr: m.gyr,
                mag: m.mag,
                temp_c: (TEMPERATURE[0] + TEMPERATURE[1] * t_s) as f32,
            };
            (t.t_ns, sample)
        })
        .collect()
}

/// A test body on its own thread with a deadline: the driver busy-waits on status bits with
/// no timeout, so a chip that never sets one would hang the test run instead of failing it.
fn guarded(body: fn()) {
    let (done, finished) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        body();
        let _ = done.send(());
    });
    match finished.recv_timeout(Duration::from_secs(120)) {
        Ok(()) => worker.join().unwrap(),
        Err(RecvTimeoutError::Disconnected) => {
            std::panic::resume_unwind(worker.join().unwrap_err())
        }
        Err(RecvTimeoutError::Timeout) => {
            panic!("the driver hung (busy-waiting on a status bit the chip never set?)")
        }
    }
}

/// The driver's 0.2 `DelayMs<u8>` (embedded-hal-compat reverses only `u16`/`u32` delays): a
/// margemu delay advancing an emulated clock, and the chip's clock with it, so the AK8963's
/// measurement schedule runs while the driver waits.
struct ChipDelay {
    delay: bus::Delay,
    clock: Clock,
    chip: Shared<Chip>,
}

impl ChipDelay {
    fn new(chip: &Shared<Chip>) -> Self {
        let clock = Clock::new();
        Self {
            delay: bus::Delay::with_clock(clock.clone()),
            clock,
            chip: chip.clone(),
        }
    }
}

impl embedded_hal_02::blocking::delay::DelayMs<u8> for ChipDelay {
    fn delay_ms(&mut self, ms: u8) {
        self.delay.delay_ms(u32::from(ms));
        self.chip.borrow_mut().advance(self.clock.now_ns());
    }
}

/// A chip as it leaves the factory (its fuse ROM ASA values are not 128, so the driver's
/// sensitivity adjustment is exercised).
fn new_chip() -> Shared<Chip> {
    let chip = Chip::new();
    assert!(chip.config().asa.iter().all(|&asa| asa > 128));
    bus::shared(chip)
}

/// What one read-out of the driver gave.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Reading {
    accel: [f32; 3],
    gyro: [f32; 3],
    mag: [f32; 3],
    temp: f32,
}

/// The driver calls the tests need, over either bus (the crate's device traits are private,
/// so the two concrete driver types implement this through one macro).
trait Driver {
    /// `all()` (one burst), checked equal to `accel()`, `gyro()`, `temp()` and `mag()`.
    fn read(&mut self) -> Reading;
    fn who_am_i(&mut self) -> (u8, u8);
    fn mag_adjustments(&self) -> [f32; 3];
    fn set_scales(&mut self, accel: AccelScale, gyro: GyroScale);
}

macro_rules! impl_driver {
    ($ty:ty) => {
        impl Driver for $ty {
            fn read(&mut self) -> Reading {
                let all = self.all::<[f32; 3]>().unwrap();
                let reading = Reading {
                    accel: all.accel,
                    gyro: all.gyro,
                    mag: all.mag,
                    temp: all.temp,
                };
                let single = Reading {
                    accel: self.accel().unwrap(),
                    gyro: self.gyro().unwrap(),
                    mag: self.mag().unwrap(),
                    temp: self.temp().unwrap(),
                };
                assert_eq!(single, reading, "single reads disagree with the burst");
                reading
            }

            fn who_am_i(&mut self) -> (u8, u8) {
                (
                    mpu9250::Mpu9250::who_am_i(self).unwrap(),
                    self.ak8963_who_am_i().unwrap(),
                )
            }

            fn mag_adjustments(&self) -> [f32; 3] {
                self.mag_sensitivity_adjustments()
            }

            fn set_scales(&mut self, accel: AccelScale, gyro: GyroScale) {
                self.accel_scale(accel).unwrap();
                self.gyro_scale(gyro).unwrap();
            }
        }
    };
}

/// Raw register reads beside the driver, over the same bus, to read back what it configured
/// (the AK8963's registers are read with the chip's own `peek`, free of side effects).
trait Raw {
    fn mpu(&mut self, reg: u8) -> u8;
}

fn ak8963_peek(chip: &Shared<Chip>, reg: u8) -> u8 {
    chip.borrow()
        .ak8963()
        .expect("an MPU-9250 has an AK8963")
        .peek(reg)
}

/// The full scales of one run: the chip's setting and the driver's range number.
#[derive(Clone, Copy, Debug)]
struct Scales {
    accel: AccelFs,
    accel_g: f64,
    gyro: GyroFs,
    gyro_dps: f64,
    mag: MagBits,
}

impl Scales {
    fn new(accel: usize, gyro: usize, mag: MagBits) -> Self {
        Self {
            accel: AccelFs::ALL[accel],
            accel_g: ACCEL_SCALES[accel].1,
            gyro: GyroFs::ALL[gyro],
            gyro_dps: GYRO_SCALES[gyro].1,
            mag,
        }
    }
}

/// One axis of one reading, in the unit the driver actually returns.
struct Axis {
    /// What the driver returned.
    got: f64,
    /// One register LSB as the driver scales it.
    driver_lsb: f64,
    /// The sample latched into the chip, in the driver's unit.
    sample: f64,
    /// One register LSB as the chip scales it (datasheet sensitivity), in the driver's unit.
    chip_lsb: f64,
    /// The register's range.
    range: (f64, f64),
}

impl Axis {
    /// The sample in register counts, clipped as the chip clips (never wraps).
    fn ideal(&self) -> f64 {
        (self.sample / self.chip_lsb).clamp(self.range.0, self.range.1)
    }

    /// The check, in LSB: the sample converted to the driver's units (the chip's count, scaled
    /// the driver's way) against what the driver returned.
    fn deviation(&self) -> f64 {
        (self.got / self.driver_lsb - self.ideal()).abs()
    }

    /// For the report only, in LSB: what the driver returned against the clipped sample taken
    /// at face value, so the driver's own scale constants show.
    fn face_value(&self) -> f64 {
        (self.got - self.ideal() * self.chip_lsb).abs() / self.chip_lsb
    }

    fn saturated(&self) -> bool {
        let ideal = self.ideal();
        ideal <= self.range.0 || ideal >= self.range.1
    }
}

/// Worst deviations per sensor (accel, gyro, mag, temp), in LSB of the current full scale.
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    /// [`Axis::deviation`]: the check.
    check: [f64; 4],
    /// [`Axis::face_value`]: for the report.
    face_value: [f64; 4],
    /// Samples where some accel / gyro axis saturated.
    saturated: [usize; 2],
}

impl Worst {
    fn add(&mut self, sensor: usize, axis: &Axis) {
        self.check[sensor] = self.check[sensor].max(axis.deviation());
        self.face_value[sensor] = self.face_value[sensor].max(axis.face_value());
    }

    fn max(self, o: Self) -> Self {
        Self {
            check: [0, 1, 2, 3].map(|i| self.check[i].max(o.check[i])),
            face_value: [0, 1, 2, 3].map(|i| self.face_value[i].max(o.face_value[i])),
            saturated: [0, 1].map(|i| self.saturated[i] + o.saturated[i]),
        }
    }

    fn assert_within_one_lsb(&self, what: &str) {
        assert!(self.check.iter().all(|d| *d <= 1.0), "{what}: {self}");
    }
}

impl std::fmt::Display for Worst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [a, g, m, t] = self.check;
        let [fa, fg, fm, ft] = self.face_value;
        write!(
            f,
            "accel {a:.3} ({fa:.3}) gyro {g:.3} ({fg:.3}) mag {m:.3} ({fm:.3}) temp {t:.3} \
             ({ft:.3}) LSB; saturated samples accel {} gyro {}",
            self.saturated[0], self.saturated[1]
        )
    }
}

/// Deviation of one reading from the sample latched before it.
fn deviation(r: &Reading, s: &PhysicalSample, scales: Scales, adj: [f32; 3]) -> Worst {
    const I16: (f64, f64) = (-32768.0, 32767.0);
    let mut w = Worst::default();
    let mut saturated = [false; 2];
    let rad_per_deg = std::f64::consts::PI / 180.0;
    for i in 0..3 {
        // Accel in the driver's m/s² (its G = 9.807 per g).
        let accel = Axis {
            got: f64::from(r.accel[i]),
            driver_lsb: f64::from(mpu9250::G) * scales.accel_g / 32768.0,
            sample: f64::from(s.acc[i]),
            chip_lsb: f64::from(STANDARD_GRAVITY) / f64::from(scales.accel.lsb_per_g()),
            range: I16,
        };
        // Gyro in rad/s (the driver's 32768/FS LSB per °/s, the chip's 131, 65.5, 32.8, 16.4).
        let gyro = Axis {
            got: f64::from(r.gyro[i]),
            driver_lsb: scales.gyro_dps / 32768.0 * rad_per_deg,
            sample: f64::from(s.gyr[i]),
            chip_lsb: rad_per_deg / f64::from(scales.gyro.lsb_per_dps()),
            range: I16,
        };
        w.add(0, &accel);
        w.add(1, &gyro);
        saturated[0] |= accel.saturated();
        saturated[1] |= gyro.saturated();
    }
    // Magnetometer in the driver's mG, in the AK8963's axes, ASA-adjusted on both sides.
    let ak = mag_axes_from_mpu(s.mag);
    let max = f64::from(scales.mag.max_raw());
    let driver_res = 10.0 * 4912.0
        / if scales.mag == MagBits::Bits16 {
            32768.0
        } else {
            8192.0
        };
    for i in 0..3 {
        let mag = Axis {
            got: f64::from(r.mag[i]),
            driver_lsb: driver_res * f64::from(adj[i]),
            sample: 10.0 * f64::from(ak[i]),
            chip_lsb: 10.0 * f64::from(scales.mag.ut_per_lsb()) * f64::from(adj[i]),
            range: (-max, max),
        };
        w.add(2, &mag);
    }
    let temp = Axis {
        got: f64::from(r.temp) - f64::from(TEMP_OFFSET_C),
        driver_lsb: 1.0 / f64::from(TEMP_LSB_PER_C),
        sample: f64::from(s.temp_c) - f64::from(TEMP_OFFSET_C),
        chip_lsb: 1.0 / f64::from(TEMP_LSB_PER_C),
        range: I16,
    };
    w.add(3, &temp);
    w.saturated = saturated.map(usize::from);
    w
}

/// What `init_mpu` and the AK8963 set-up leave in the registers, on either bus.
fn assert_common_config(raw: &mut impl Raw, chip: &Shared<Chip>, accel: u8, gyro: u8, cntl1: u8) {
    let expected = [
        (0x75, 0x71, "WHO_AM_I"),
        (0x6B, 0x01, "PWR_MGMT_1: awake, auto clock"),
        (0x6C, 0x00, "PWR_MGMT_2: all sensors on"),
        (0x19, SMPLRT_DIV, "SMPLRT_DIV"),
        (0x1A, 0x01, "CONFIG: DLPF_CFG = 1"),
        (0x1B, gyro << 3, "GYRO_CONFIG: GYRO_FS_SEL, FCHOICE_B = 00"),
        (0x1C, accel << 3, "ACCEL_CONFIG: ACCEL_FS_SEL"),
        (
            0x1D,
            0x41,
            "ACCEL_CONFIG2: bit 6 (1 kB FIFO), A_DLPF_CFG = 1",
        ),
        (0x38, 0x00, "INT_ENABLE"),
    ];
    for (reg, value, what) in expected {
        assert_eq!(raw.mpu(reg), value, "{what}");
    }
    assert_eq!(ak8963_peek(chip, 0x00), 0x48, "AK8963 WIA");
    assert_eq!(
        ak8963_peek(chip, 0x0A),
        cntl1,
        "AK8963 CNTL1: continuous mode 2"
    );
}

/// The driver config of one run: the given full scales, DLPF 1 and a 100 Hz output rate.
fn config(accel: AccelScale, gyro: GyroScale, mag: MagScale) -> MpuConfig<Marg> {
    let mut config = MpuConfig::marg();
    config
        .accel_scale(accel)
        .gyro_scale(gyro)
        .mag_scale(mag)
        .accel_data_rate(AccelDataRate::DlpfConf(Dlpf::_1))
        .gyro_temp_data_rate(GyroTempDataRate::DlpfConf(Dlpf::_1))
        .sample_rate_divisor(SMPLRT_DIV);
    config
}

/// Latches every sample into the chip at its instant (from one period after the chip's clock),
/// reads it back through the driver, and returns the worst deviation. The scene runs at the
/// AK8963's continuous-mode-2 rate, so each period holds exactly one magnetometer measurement,
/// of the field latched at its end.
fn replay(
    chip: &Shared<Chip>,
    driver: &mut impl Driver,
    samples: &[(u64, PhysicalSample)],
    scales: Scales,
) -> Worst {
    let adj = driver.mag_adjustments();
    let asa = chip.borrow().config().asa;
    assert_eq!(adj, asa.map(asa_factor), "the driver's ASA adjustment");
    let base = chip.borrow().now_ns() + chip.borrow().sample_period_ns();
    let t0 = samples[0].0;
    let mut worst = Worst::default();
    for (t_ns, s) in samples {
        chip.borrow_mut().latch_at(s, base + t_ns - t0);
        worst = worst.max(deviation(&driver.read(), s, scales, adj));
    }
    worst
}

/// Every accel × gyro full scale, magnetometer resolution alternating: a fresh chip each time,
/// set up by the driver's constructor.
fn every_full_scale<D: Driver, R: Raw>(
    bus_name: &str,
    init: impl Fn(&Shared<Chip>, &mut MpuConfig<Marg>) -> (D, R),
) {
    let samples = scene_samples(RATE_HZ);
    let mut lines = Vec::new();
    let mut total = Worst::default();
    for (a, &(accel, accel_g)) in ACCEL_SCALES.iter().enumerate() {
        for (g, &(gyro, gyro_dps)) in GYRO_SCALES.iter().enumerate() {
            let (mag, mag_bits) = MAG_SCALES[(a + g) % 2];
            let chip = new_chip();
            let (mut driver, mut raw) = init(&chip, &mut config(accel, gyro, mag));
            assert_eq!(driver.who_am_i(), (0x71, 0x48));
            let cntl1 = if mag_bits == MagBits::Bits16 {
                0x16
            } else {
                0x06
            };
            assert_common_config(&mut raw, &chip, a as u8, g as u8, cntl1);
            assert_eq!(chip.borrow().output_rate_hz(), RATE_HZ);
            let scales = Scales::new(a, g, mag_bits);
            let worst = replay(&chip, &mut driver, &samples, scales);
            let what = format!("{bus_name} ±{accel_g} g ±{gyro_dps} °/s {mag_bits:?}");
            lines.push(format!("{what}: {worst}"));
            worst.assert_within_one_lsb(&what);
            total = total.max(worst);
        }
    }
    println!("{}\n{bus_name} worst: {total}", lines.join("\n"));
}

/// Full scales changed at run time through the driver's setters on one chip.
fn scales_changed_at_run_time<D: Driver, R: Raw>(
    init: impl Fn(&Shared<Chip>, &mut MpuConfig<Marg>) -> (D, R),
) {
    let samples = scene_samples(RATE_HZ);
    let chip = new_chip();
    let mut config = config(AccelScale::_2G, GyroScale::_250DPS, MagScale::_16BITS);
    let (mut driver, mut raw) = init(&chip, &mut config);
    for (i, chunk) in samples.chunks(samples.len() / 4).take(4).enumerate() {
        let (a, g) = (3 - i, i);
        driver.set_scales(ACCEL_SCALES[a].0, GYRO_SCALES[g].0);
        assert_eq!(raw.mpu(0x1C), (a as u8) << 3, "ACCEL_CONFIG");
        assert_eq!(raw.mpu(0x1B), (g as u8) << 3, "GYRO_CONFIG");
        let scales = Scales::new(a, g, MagBits::Bits16);
        let worst = replay(&chip, &mut driver, chunk, scales);
        worst.assert_within_one_lsb(&format!("{scales:?}"));
    }
}

/// The driver reads TEMP_OUT as unsigned: below 21 °C it reports `u16 / 333.87 + 21`.
fn temperature_below_21_c_reads_as_unsigned<D: Driver, R: Raw>(
    init: impl Fn(&Shared<Chip>, &mut MpuConfig<Marg>) -> (D, R),
) {
    let chip = new_chip();
    let mut config = config(AccelScale::_2G, GyroScale::_250DPS, MagScale::_16BITS);
    let (mut driver, _) = init(&chip, &mut config);
    let cold = PhysicalSample {
        temp_c: 11.0,
        ..PhysicalSample::default()
    };
    let now = chip.borrow().now_ns();
    chip.borrow_mut().latch_at(&cold, now + 10_000_000);
    let raw = temp_to_raw(cold.temp_c);
    assert_eq!(raw, -3339);
    let unsigned = f32::from(raw as u16) / TEMP_LSB_PER_C + TEMP_OFFSET_C;
    let got = driver.read().temp;
    assert!((got - unsigned).abs() < 0.01, "{got} °C");
}
