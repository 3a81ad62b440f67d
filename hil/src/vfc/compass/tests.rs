use super::*;
use margemu_firmware::chip::Bus as WriteBus;
use margemu_protocol::chip::PhysicalSample;
use margemu_protocol::link::Rate;
use margemu_sim::scene::chip::ChipSetup;

/// The rig fixture's compass mounting: upside down, x kept.
const FLIPPED: Rotation = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
/// A quarter turn about z.
const QUARTER: Rotation = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
/// A plate-frame field, µT.
const FIELD: [f64; 3] = [21.0, -4.5, -40.2];

/// An ICM-42688-P on SPI with `compass` added on I2C, as a device builds it from Configure and
/// AddDevice.
fn rig(compass: Option<&ChipSetup>) -> Rig {
    let imu = EmulatedChip::new(ChipModel::Icm42688p, 0x47, 0x68).unwrap();
    let mut rig = Rig::new(imu);
    if let Some(c) = compass {
        rig.add(&c.add_device(Rate::new(200, 1).unwrap())).unwrap();
    }
    rig
}

/// The compass device of a model with `settings`, mounted by `rotation`.
fn setup(model: ChipModel, settings: ChipSettings, rotation: Option<Rotation>) -> ChipSetup {
    ChipSetup {
        settings,
        rotation,
        ..ChipSetup::power_on(model)
    }
}

fn config(chip: &ChipSetup, imu_rotation: Option<Rotation>) -> CompassConfig {
    CompassConfig {
        name: "compass".into(),
        model: chip.model,
        address: chip.i2c_address,
        settings: chip.settings,
        to_body: axes_between(chip.rotation, imu_rotation),
    }
}

/// Latches the plate field `FIELD` into the rig at every ms from `from_ms` to `to_ms`: the IMU
/// a zero image, the compass its image of the field in its own axes.
fn latch(rig: &mut Rig, chip: &ChipSetup, from_ms: u64, to_ms: u64) {
    let sample = PhysicalSample {
        mag: chip.to_chip(FIELD).map(|v| v as f32),
        ..PhysicalSample::default()
    };
    let mut image = vec![0u8; ChipModel::Icm42688p.image_len()];
    image.extend_from_slice(chip.settings.image(&sample).as_bytes());
    for ms in from_ms..=to_ms {
        rig.latch_image_at(&image, ms * 1_000_000);
    }
}

fn assert_near(got: [f64; 3], want: [f64; 3], tolerance: f64) {
    for i in 0..3 {
        assert!((got[i] - want[i]).abs() <= tolerance, "{got:?} vs {want:?}");
    }
}

#[test]
fn alignment_turns_the_compass_into_the_imus_axes() {
    let plate = [1.0, 2.0, 3.0];
    let cases = [
        (None, Some(FLIPPED)),
        (None, Some(QUARTER)),
        (Some(QUARTER), Some(FLIPPED)),
        (Some(QUARTER), None),
    ];
    for (imu, compass) in cases {
        let seen = rotate(&compass.unwrap_or(axes_between(None, None)), plate);
        let want = rotate(&imu.unwrap_or(axes_between(None, None)), plate);
        assert_near(rotate(&axes_between(compass, imu), seen), want, 1e-12);
    }
    assert_eq!(axes_between(Some(FLIPPED), None), FLIPPED);
}

#[test]
fn the_ist8310_is_set_up_like_ardupilot_does_and_read_every_10_ms() {
    let chip = setup(
        ChipModel::Ist8310,
        ChipSettings::power_on(ChipModel::Ist8310),
        Some(FLIPPED),
    );
    let mut rig = rig(Some(&chip));
    let (mut compass, init) = Compass::init(&mut rig, &config(&chip, Some(QUARTER)), 0).unwrap();
    assert_eq!(
        (init.model, init.address, init.identity),
        (ChipModel::Ist8310, 0x0E, 0x10)
    );
    assert_eq!(init.waited_ns, 10_000_000, "one soft reset, one 10 ms wait");
    let writes: Vec<(u8, u8)> = std::iter::from_fn(|| rig.pop_write())
        .map(|(w, _)| {
            assert_eq!((w.bus, w.device), (WriteBus::I2c, 0x0E));
            (w.register, w.value)
        })
        .collect();
    assert_eq!(
        writes,
        [(0x0B, 0x01), (0x41, 0x24), (0x42, 0xC0), (0x0A, 0x01)]
    );
    latch(&mut rig, &chip, 1, 9);
    assert_eq!(
        compass.poll(&mut rig, 9_000_000),
        Ok(None),
        "not due before 10 ms"
    );
    latch(&mut rig, &chip, 10, 10);
    // The field in the IMU's axes (a quarter turn from the plate's), within 0.3 µT/LSB.
    let want = rotate(&QUARTER, FIELD);
    assert_near(
        compass.poll(&mut rig, 10_000_000).unwrap().unwrap(),
        want,
        0.15,
    );
    // The next single measurement was started; due 10 ms after this reading.
    latch(&mut rig, &chip, 11, 19);
    assert_eq!(compass.poll(&mut rig, 19_000_000), Ok(None));
    latch(&mut rig, &chip, 20, 20);
    assert_near(
        compass.poll(&mut rig, 20_000_000).unwrap().unwrap(),
        want,
        0.15,
    );
    assert_eq!(compass.not_ready(), 0);
}

#[test]
fn a_nak_window_loses_the_polls_inside_it_and_reading_resumes_after() {
    use margemu_firmware::fault::FaultSchedule;
    use margemu_model::fault::{Fault, FaultKind, Window};
    let chip = setup(
        ChipModel::Ist8310,
        ChipSettings::power_on(ChipModel::Ist8310),
        None,
    );
    let mut rig = rig(Some(&chip));
    let (mut compass, _) = Compass::init(&mut rig, &config(&chip, None), 0).unwrap();
    // The compass is the rig's device 1; its polls at 20 and 30 ms fall in the window.
    let mut schedule = FaultSchedule::new();
    let window = Window::new(20_000_000, 40_000_000);
    schedule
        .push(Fault::new(1, window, FaultKind::Nak), 9)
        .unwrap();
    schedule
        .push(Fault::new(0, Window::new(0, 90_000_000), FaultKind::Nak), 9)
        .unwrap();
    compass.sync_faults(&rig, &schedule);
    let mut got = Vec::new();
    for ms in (10..=50).step_by(10) {
        latch(&mut rig, &chip, ms - 9, ms);
        got.push(compass.poll(&mut rig, ms * 1_000_000).unwrap().is_some());
    }
    assert_eq!(got, [true, false, false, true, true]);
    assert_eq!((compass.failed(), compass.not_ready()), (2, 0));
}

#[test]
fn a_poll_before_the_measurement_completes_waits_for_drdy() {
    let chip = setup(
        ChipModel::Ist8310,
        ChipSettings::power_on(ChipModel::Ist8310),
        None,
    );
    let mut rig = rig(Some(&chip));
    let (mut compass, _) = Compass::init(&mut rig, &config(&chip, None), 0).unwrap();
    // The chip's clock stays at 5 ms (under the 6.1 ms measurement) while the flight
    // controller's says 10 ms: DRDY is clear, nothing is taken.
    latch(&mut rig, &chip, 5, 5);
    assert_eq!(compass.poll(&mut rig, 10_000_000), Ok(None));
    assert_eq!(compass.not_ready(), 1);
    latch(&mut rig, &chip, 6, 7);
    assert_near(
        compass.poll(&mut rig, 10_000_000).unwrap().unwrap(),
        FIELD,
        0.15,
    );
}

#[test]
fn the_qmc5883l_runs_continuously_at_the_hosts_range() {
    for gauss in [2.0, 8.0] {
        let settings = ChipSettings::power_on(ChipModel::Qmc5883l)
            .with_mag_range(gauss)
            .unwrap();
        let chip = setup(ChipModel::Qmc5883l, settings, Some(FLIPPED));
        let mut rig = rig(Some(&chip));
        let (mut compass, init) = Compass::init(&mut rig, &config(&chip, None), 0).unwrap();
        assert_eq!((init.address, init.identity), (0x0D, 0xFF));
        let conf1 = std::iter::from_fn(|| rig.pop_write())
            .filter(|(w, _)| w.register == 0x09)
            .last()
            .unwrap()
            .0
            .value;
        assert_eq!(conf1, if gauss == 2.0 { 0x09 } else { 0x19 }, "{gauss} G");
        latch(&mut rig, &chip, 1, 10);
        // LSB: 1/120 µT at ±2 G, 1/30 µT at ±8 G.
        assert_near(
            compass.poll(&mut rig, 10_000_000).unwrap().unwrap(),
            FIELD,
            0.02,
        );
        // At 20 ms the chip has measured again.
        latch(&mut rig, &chip, 11, 20);
        assert!(compass.poll(&mut rig, 20_000_000).unwrap().is_some());
    }
}

#[test]
fn the_rm3100_is_set_up_like_ardupilot_does_and_read_when_ready() {
    let chip = setup(
        ChipModel::Rm3100,
        ChipSettings::power_on(ChipModel::Rm3100),
        Some(QUARTER),
    );
    // On I2C, as ArduPilot probes it: at 0x20 with SA0 and SA1 low.
    let chip = ChipSetup {
        bus: margemu_sim::scene::chip::BusKind::I2c,
        ..chip
    };
    let mut rig = rig(Some(&chip));
    let (mut compass, init) = Compass::init(&mut rig, &config(&chip, Some(QUARTER)), 0).unwrap();
    assert_eq!((init.address, init.identity), (0x20, 0x22));
    let writes: Vec<(u8, u8)> = std::iter::from_fn(|| rig.pop_write())
        .map(|(w, _)| (w.register, w.value))
        .collect();
    assert_eq!(
        writes,
        [
            (0x04, 0x00),
            (0x05, 0xC8),
            (0x06, 0x00),
            (0x07, 0xC8),
            (0x08, 0x00),
            (0x09, 0xC8),
            (0x0B, 0x94),
            (0x01, 0x71)
        ]
    );
    // A whole sequence of 3 axes at 200 counts takes 6.85 ms; TMRC 0x94 gives ~146 Hz.
    latch(&mut rig, &chip, 1, 10);
    // The same axes as the IMU's: the field in the IMU's axes, within the 1/75 µT LSB.
    let got = compass.poll(&mut rig, 10_000_000).unwrap().unwrap();
    assert_near(got, chip.to_chip(FIELD), 0.02);
    // The next poll is due 10 ms later, and finds the next measurement.
    assert_eq!(compass.poll(&mut rig, 15_000_000).unwrap(), None);
    latch(&mut rig, &chip, 11, 20);
    assert!(compass.poll(&mut rig, 20_000_000).unwrap().is_some());
}

#[test]
fn an_absent_compass_or_another_chip_at_its_address_is_refused() {
    let ist = setup(
        ChipModel::Ist8310,
        ChipSettings::power_on(ChipModel::Ist8310),
        None,
    );
    let why = Compass::init(&mut rig(None), &config(&ist, None), 0)
        .err()
        .unwrap();
    assert_eq!(
        why,
        "the compass `compass` (IST8310 at I2C 0x0e): no device answers I2C address 0x0e"
    );
    // A QMC5883L expected where an IST8310 answers.
    let qmc = CompassConfig {
        model: ChipModel::Qmc5883l,
        settings: ChipSettings::power_on(ChipModel::Qmc5883l),
        ..config(&ist, None)
    };
    let why = Compass::init(&mut rig(Some(&ist)), &qmc, 0).err().unwrap();
    assert!(
        why.ends_with("register 0x0c reads 0x00, not the QMC5883L's 0x01"),
        "{why}"
    );
}
