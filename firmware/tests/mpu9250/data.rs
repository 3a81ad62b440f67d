//! Data registers: full scales, big-endian two's complement with rounding and saturation,
//! TEMP_OUT, the output rate, atomic sample swaps, and register images (RM sections 4.3–4.8,
//! 4.22–4.24, 4.39).

use super::*;
use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};

const G: f32 = 9.80665;
const DPS: f32 = core::f32::consts::PI / 180.0;

fn sample(acc: [f32; 3], gyr: [f32; 3], temp_c: f32) -> PhysicalSample {
    PhysicalSample {
        acc,
        gyr,
        mag: [0.0; 3],
        temp_c,
    }
}

#[test]
fn accel_full_scales() {
    // ACCEL_CONFIG = FS << 3; +1 g on x, −1 g on y, +0.5 g on z.
    for (fs, one_g) in [(0u8, 0x4000u16), (1, 0x2000), (2, 0x1000), (3, 0x0800)] {
        let mut c = chip();
        spi_write(&mut c, 0x1C, &[fs << 3]);
        c.latch_at(&sample([G, -G, 0.5 * G], [0.0; 3], 21.0), MS);
        let [h, l] = one_g.to_be_bytes();
        let [nh, nl] = one_g.wrapping_neg().to_be_bytes();
        let [zh, zl] = (one_g / 2).to_be_bytes();
        assert_eq!(
            spi_read(&mut c, 0x3B, 6),
            [h, l, nh, nl, zh, zl],
            "ACCEL_FS_SEL {fs}"
        );
    }
}

#[test]
fn gyro_full_scales() {
    // 100 °/s on x, −100 °/s on z: 13100, 6550, 3280, 1640 LSB.
    for (fs, lsb) in [(0u8, 13100i16), (1, 6550), (2, 3280), (3, 1640)] {
        let mut c = chip();
        spi_write(&mut c, 0x1B, &[fs << 3]);
        c.latch_at(
            &sample([0.0; 3], [100.0 * DPS, 0.0, -100.0 * DPS], 21.0),
            MS,
        );
        let [h, l] = lsb.to_be_bytes();
        let [nh, nl] = (-lsb).to_be_bytes();
        assert_eq!(
            spi_read(&mut c, 0x43, 6),
            [h, l, 0, 0, nh, nl],
            "GYRO_FS_SEL {fs}"
        );
    }
}

#[test]
fn saturation_never_wraps() {
    let mut c = chip();
    c.latch_at(
        &sample(
            [1e30, -1e30, 2.0 * G],
            [f32::INFINITY, -300.0 * DPS, f32::NAN],
            1e9,
        ),
        MS,
    );
    assert_eq!(
        spi_read(&mut c, 0x3B, 14),
        [0x7F, 0xFF, 0x80, 0x00, 0x7F, 0xFF, 0x7F, 0xFF, 0x7F, 0xFF, 0x80, 0x00, 0x00, 0x00]
    );
}

#[test]
fn rounding_to_nearest() {
    let mut c = chip();
    // At ±2 g one LSB is 1/16384 g: 2.4 LSB → 2, 2.6 LSB → 3, −2.6 LSB → −3.
    let lsb = G / 16384.0;
    c.latch_at(
        &sample([2.4 * lsb, 2.6 * lsb, -2.6 * lsb], [0.0; 3], 21.0),
        MS,
    );
    assert_eq!(
        spi_read(&mut c, 0x3B, 6),
        [0x00, 0x02, 0x00, 0x03, 0xFF, 0xFD]
    );
}

#[test]
fn temp_out() {
    // (t − 21 °C) · 333.87 LSB/°C: 0, 3338.7 → 3339, −7011.27 → −7011, 21367.68 → 21368.
    let mut c = chip();
    for (t, bytes) in [
        (21.0, [0x00, 0x00]),
        (31.0, [0x0D, 0x0B]),
        (0.0, [0xE4, 0x9D]),
        (85.0, [0x53, 0x78]),
    ] {
        c.latch_at(&sample([0.0; 3], [0.0; 3], t), MS);
        assert_eq!(spi_read(&mut c, 0x41, 2), bytes, "{t} °C");
    }
}

#[test]
fn output_rate_follows_smplrt_div_and_the_dlpf() {
    let mut c = chip();
    assert_eq!(c.sample_period_ns(), 125_000, "reset: DLPF_CFG 0, 8 kHz");
    spi_write(&mut c, 0x1A, &[0x01]); // DLPF on
    assert_eq!(c.output_rate_hz(), 1000.0);
    spi_write(&mut c, 0x19, &[0x04]);
    assert_eq!(
        (c.sample_period_ns(), c.output_rate_hz()),
        (5_000_000, 200.0)
    );
    spi_write(&mut c, 0x1B, &[0x01]); // FCHOICE_B = 01: DLPF bypassed, 32 kHz
    assert_eq!(
        (c.sample_period_ns(), c.output_rate_hz()),
        (31_250, 32_000.0)
    );
    spi_write(&mut c, 0x1B, &[0x00]);
    spi_write(&mut c, 0x1A, &[0x07]);
    assert_eq!(
        c.sample_period_ns(),
        125_000,
        "DLPF_CFG 7: 8 kHz, no divider"
    );
}

#[test]
fn a_burst_in_progress_completes_with_the_old_sample() {
    let mut c = chip();
    c.latch_at(&sample([G, 0.0, 0.0], [0.0; 3], 21.0), MS);
    c.select();
    assert_eq!(c.exchange(0x80 | 0x3B), 0x40);
    assert_eq!(c.exchange(0x00), 0x00);
    c.latch_at(&sample([0.5 * G, 0.0, 0.0], [0.0; 3], 21.0), 2 * MS); // mid-burst
    assert_eq!(c.exchange(0x00), 0x00);
    assert_eq!(c.exchange(0x00), 0x00); // still the first sample's y, z...
    c.deselect();
    assert_eq!(
        spi_read(&mut c, 0x3B, 2),
        [0x20, 0x00],
        "the new sample after deselect"
    );
    // The same over I2C: the swap waits for STOP (not for a repeated START).
    c.start(0x68, false);
    c.write(0x3B);
    c.latch_at(&sample([G, 0.0, 0.0], [0.0; 3], 21.0), 3 * MS);
    c.start(0x68, true);
    assert_eq!([c.read(), c.read()], [0x20, 0x00]);
    c.stop();
    assert_eq!(i2c_read(&mut c, 0x68, 0x3B, 2), Some(vec![0x40, 0x00]));
}

#[test]
fn register_images_are_served_verbatim() {
    let mut c = chip();
    let repr = ImageRepr {
        accel: [1, -2, 3],
        temp: -4,
        gyro: [0x1234, -0x1234, 7],
        ..Default::default()
    };
    c.latch_image_at(&repr.emit(), MS);
    assert_eq!(
        spi_read(&mut c, 0x3B, 14),
        [0, 1, 0xFF, 0xFE, 0, 3, 0xFF, 0xFC, 0x12, 0x34, 0xED, 0xCC, 0, 7]
    );
    assert_eq!(spi_read(&mut c, 0x3A, 1), [0x01]);
}

#[test]
fn image_config_tracks_the_registers() {
    let mut c = chip();
    spi_write(&mut c, 0x1B, &[0x10]);
    spi_write(&mut c, 0x1C, &[0x18]);
    let cfg = c.image_config();
    assert_eq!(
        cfg.gyro_fs,
        margemu_protocol::regmap::mpu6xxx::GyroFs::Dps1000
    );
    assert_eq!(
        cfg.accel_fs,
        margemu_protocol::regmap::mpu6xxx::AccelFs::G16
    );
    assert_eq!(
        cfg,
        ImageConfig {
            gyro_fs: cfg.gyro_fs,
            accel_fs: cfg.accel_fs,
            ..ImageConfig::NOMINAL
        }
    );
}

#[test]
fn latch_without_a_time_steps_the_chip_sample_clock() {
    let mut c = chip();
    c.latch(&at_rest());
    assert_eq!(c.now_ns(), 125_000, "8 kHz after reset");
    spi_write(&mut c, 0x1A, &[0x01]);
    spi_write(&mut c, 0x19, &[9]);
    c.latch(&at_rest());
    c.latch_image(&[0; 22]);
    assert_eq!(c.now_ns(), 20_125_000);
    assert_eq!(c.next_sample_ns(), 30_125_000);
    c.latch_at(&at_rest(), 5); // time never runs backwards
    assert_eq!(c.now_ns(), 20_125_000);
}

#[test]
fn user_offset_registers_shift_the_output() {
    let mut c = Mpu6xxx::with_config(Config {
        accel_offset: [0x1000, 0x0000, 0xFFFE],
        ..Config::default()
    });
    spi_write(&mut c, 0x13, &[0x00, 0x02, 0xFF, 0xFF]); // XG_OFFS_USR = 2, YG = −1
    spi_write(&mut c, 0x77, &[0x10, 0x02]); // XA_OFFS: one 0.98 mg step above the trim
    spi_write(&mut c, 0x7D, &[0x00, 0x00]); // ZA_OFFS: one step above its trim (0xFFFE = −2)
    c.latch_at(&sample([0.0; 3], [0.0; 3], 21.0), MS);
    // ±2 g: one step = 16 LSB. ±250 °/s: one OFFS_USR unit = 4 LSB.
    assert_eq!(
        spi_read(&mut c, 0x3B, 6),
        [0x00, 0x10, 0x00, 0x00, 0x00, 0x10]
    );
    assert_eq!(spi_read(&mut c, 0x43, 4), [0x00, 0x08, 0xFF, 0xFC]);
    assert_eq!(c.image_config().gyro_offset, [2, -1, 0]);
    assert_eq!(c.image_config().accel_offset, [2, 0, 2]);
}
