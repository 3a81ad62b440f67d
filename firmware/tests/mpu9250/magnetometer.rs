//! The AK8963 through bypass mode: WIA, fuse ROM, modes and timing, 14/16-bit output, ST1,
//! little-endian data, ST2 overflow and the read-releases-latch rule, its axes, soft reset and
//! self-test (AK8963 datasheet sections 6 and 8; RM section 5).

use super::*;

const AK: u8 = 0x0C;

fn bypass(asa: [u8; 3]) -> Mpu6xxx {
    let mut c = Mpu6xxx::with_config(Config {
        asa,
        ..Config::default()
    });
    assert_eq!(i2c_write(&mut c, 0x68, &[0x37, 0x02]), [true; 3]);
    c
}

fn field(mag: [f32; 3]) -> PhysicalSample {
    PhysicalSample { mag, ..at_rest() }
}

/// ST1, HXL..HZH, ST2 in one read, as drivers do.
fn read_st1_to_st2(c: &mut Mpu6xxx) -> Vec<u8> {
    i2c_read(c, AK, 0x02, 8).expect("AK8963 acknowledges")
}

#[test]
fn wia_info_and_fuse_rom() {
    let mut c = bypass([0xB0, 0xA8, 0xC1]);
    assert_eq!(i2c_read(&mut c, AK, 0x00, 1), Some(vec![0x48]));
    assert_eq!(
        i2c_read(&mut c, AK, 0x10, 3),
        Some(vec![0, 0, 0]),
        "readable in fuse mode only"
    );
    i2c_write(&mut c, AK, &[0x0A, 0x1F]);
    assert_eq!(i2c_read(&mut c, AK, 0x10, 3), Some(vec![0xB0, 0xA8, 0xC1]));
    i2c_write(&mut c, AK, &[0x0A, 0x00]);
    assert_eq!(i2c_read(&mut c, AK, 0x10, 1), Some(vec![0]));
}

#[test]
fn power_down_measures_nothing() {
    let mut c = bypass([128; 3]);
    for ms in 1..50 {
        c.latch_at(&field([10.0, 10.0, 10.0]), ms * MS);
    }
    assert_eq!(read_st1_to_st2(&mut c), [0; 8]);
}

#[test]
fn continuous_mode_2_at_100_hz_16_bit() {
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x16]);
    let s = field([30.0, 15.0, -45.0]); // MPU axes → AK axes (15, 30, 45) µT
    c.latch_at(&s, 7 * MS);
    assert_eq!(read_st1_to_st2(&mut c)[0], 0x00);
    c.latch_at(&s, 8 * MS);
    assert_eq!(
        read_st1_to_st2(&mut c),
        [0x01, 100, 0, 200, 0, 0x2C, 0x01, 0x10]
    );
    c.latch_at(&s, 9 * MS);
    assert_eq!(
        read_st1_to_st2(&mut c)[0],
        0x00,
        "DRDY cleared by the read, next at 17.2 ms"
    );
    c.latch_at(&s, 18 * MS);
    assert_eq!(read_st1_to_st2(&mut c)[0], 0x01);
}

#[test]
fn continuous_mode_1_at_8_hz_14_bit() {
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x02]);
    let s = field([0.0, -6.0, 0.0]); // AK x = −6 µT = −10 LSB at 0.6 µT/LSB
    let mut ready_at = Vec::new();
    for ms in 1..=300 {
        c.latch_at(&s, ms * MS);
        if read_st1_to_st2(&mut c)[0] & 1 != 0 {
            ready_at.push(ms);
        }
    }
    assert_eq!(ready_at, [8, 133, 258]);
    c.latch_at(&s, 400 * MS);
    assert_eq!(
        read_st1_to_st2(&mut c),
        [0x01, 0xF6, 0xFF, 0, 0, 0, 0, 0x00]
    );
}

#[test]
fn single_measurement_then_power_down() {
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x11]);
    c.latch_at(&field([0.0, 0.0, 1.5]), 8 * MS);
    assert_eq!(
        i2c_read(&mut c, AK, 0x0A, 1),
        Some(vec![0x10]),
        "back to power-down"
    );
    assert_eq!(
        read_st1_to_st2(&mut c),
        [0x01, 0, 0, 0, 0, 0xF6, 0xFF, 0x10]
    ); // z_ak = −z_mpu
    c.latch_at(&field([0.0, 0.0, 1.5]), 100 * MS);
    assert_eq!(read_st1_to_st2(&mut c)[0], 0x00);
}

#[test]
fn unread_data_reports_dor() {
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x16]);
    c.latch_at(&field([0.0; 3]), 8 * MS);
    c.latch_at(&field([0.0; 3]), 18 * MS);
    assert_eq!(read_st1_to_st2(&mut c)[0], 0x03, "DRDY | DOR");
    c.latch_at(&field([0.0; 3]), 28 * MS);
    assert_eq!(read_st1_to_st2(&mut c)[0], 0x01);
}

#[test]
fn data_stays_latched_until_st2_is_read() {
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x16]);
    c.latch_at(&field([0.0, 0.15, 0.0]), 8 * MS);
    assert_eq!(i2c_read(&mut c, AK, 0x03, 2), Some(vec![1, 0])); // HXL, HXH: read started
    c.latch_at(&field([0.0, 0.3, 0.0]), 18 * MS); // discarded: the read has not ended
    assert_eq!(
        i2c_read(&mut c, AK, 0x03, 7),
        Some(vec![1, 0, 0, 0, 0, 0, 0x10])
    );
    c.latch_at(&field([0.0, 0.45, 0.0]), 28 * MS);
    assert_eq!(
        read_st1_to_st2(&mut c)[..3],
        [0x03, 3, 0],
        "new data, DOR reports the skip"
    );
}

#[test]
fn overflow_sets_hofl() {
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x16]);
    c.latch_at(&field([2000.0, 2000.0, 1000.0]), 8 * MS); // |x|+|y|+|z| = 5000 µT ≥ 4912
    assert_eq!(read_st1_to_st2(&mut c)[7], 0x18, "HOFL | BITM");
    c.latch_at(&field([5000.0, 0.0, 0.0]), 18 * MS);
    let d = read_st1_to_st2(&mut c);
    assert_eq!((d[3], d[4], d[7]), (0xF8, 0x7F, 0x18), "clipped at +32760");
}

#[test]
fn asa_adjustment_recovers_the_field() {
    let asa = [0xB0, 0x80, 0x60]; // factors 1.1875, 1.0, 0.875
    let mut c = bypass(asa);
    i2c_write(&mut c, AK, &[0x0A, 0x16]);
    let mpu = [-21.3, 42.7, -33.3];
    c.latch_at(&field(mpu), 8 * MS);
    let d = read_st1_to_st2(&mut c);
    let raw: Vec<f32> = (0..3)
        .map(|i| f32::from(i16::from_le_bytes([d[1 + 2 * i], d[2 + 2 * i]])))
        .collect();
    let ak = [mpu[1], mpu[0], -mpu[2]];
    for i in 0..3 {
        let factor = (f32::from(asa[i]) - 128.0) / 256.0 + 1.0;
        let recovered = raw[i] * factor * 0.15;
        assert!(
            (recovered - ak[i]).abs() <= 0.15 * factor * 0.5 + 1e-4,
            "axis {i}: {recovered} vs {}",
            ak[i]
        );
    }
}

#[test]
fn soft_reset() {
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x16]);
    c.latch_at(&field([10.0; 3]), 8 * MS);
    i2c_write(&mut c, AK, &[0x0B, 0x01]);
    assert_eq!(
        i2c_read(&mut c, AK, 0x00, 13),
        Some(vec![0x48, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    );
}

#[test]
fn self_test_procedure() {
    // Datasheet 8.3.12: power-down, ASTC.SELF = 1, MODE = self-test, wait DRDY, read, SELF = 0.
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x10]);
    i2c_write(&mut c, AK, &[0x0C, 0x40]);
    i2c_write(&mut c, AK, &[0x0A, 0x18]);
    c.latch_at(&field([40.0, 40.0, 40.0]), 8 * MS);
    let d = read_st1_to_st2(&mut c);
    let v: Vec<i16> = (0..3)
        .map(|i| i16::from_le_bytes([d[1 + 2 * i], d[2 + 2 * i]]))
        .collect();
    assert_eq!(d[0], 0x01);
    assert!(
        (-200..=200).contains(&v[0]) && (-200..=200).contains(&v[1]),
        "{v:?}"
    );
    assert!((-3200..=-800).contains(&v[2]), "{v:?}");
    i2c_write(&mut c, AK, &[0x0C, 0x00]);
    assert_eq!(i2c_read(&mut c, AK, 0x0A, 1), Some(vec![0x10]));
}

#[test]
fn register_images_feed_the_magnetometer_on_its_own_schedule() {
    use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
    let mut c = bypass([128; 3]);
    i2c_write(&mut c, AK, &[0x0A, 0x16]);
    let cfg = ImageConfig {
        mag_bits: margemu_protocol::regmap::ak8963::MagBits::Bits16,
        ..ImageConfig::NOMINAL
    };
    let image =
        ImageRepr::from_physical([0.0; 3], [0.0; 3], 21.0, [30.0, 15.0, -45.0], &cfg).emit();
    c.latch_image_at(&image, 5 * MS);
    assert_eq!(read_st1_to_st2(&mut c)[0], 0x00, "not due before 7.2 ms");
    c.latch_image_at(&image, 8 * MS);
    assert_eq!(
        read_st1_to_st2(&mut c),
        [0x01, 100, 0, 200, 0, 0x2C, 0x01, 0x10]
    );
}
