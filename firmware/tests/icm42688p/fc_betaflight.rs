//! Betaflight's ICM-426xx driver (`src/main/drivers/accgyro/accgyro_spi_icm426xx.c`, read for
//! its register sequence, no code taken): soft reset, WHO_AM_I, sensors off, gyro and accel
//! anti-alias filters (banks 1 and 2), UI filters at low latency, INT1 pulsed push-pull active
//! high with data ready routed to it, 8 µs pulses without de-assert time, AFSR off
//! ([`betaflight_init`] can leave that write out, as Betaflight did before PR #13132), sensors on,
//! ±2000 °/s and ±16 g at the gyro ODR. Then no FIFO: on each INT1 pulse one 15-byte
//! transaction, the read flag with 0x1D and 14 data bytes (temperature, accel, gyro;
//! big-endian).

use super::fc::{Decoded, Recorder, Rig, Run};
use super::*;

/// Runs Betaflight's init and `n` data-ready reads at `odr_code` (3 = 8 kHz … 6 = 1 kHz).
pub fn betaflight_sequence(rig: &mut impl Rig, odr_code: u8, n: usize) -> Run {
    let mut r = Recorder::new(rig);
    betaflight_init(&mut r, odr_code, true);
    let period = r.rig.image_config(); // full scales the driver assumes
    assert_eq!(
        period,
        margemu_protocol::regmap::icm42688p::image::ImageConfig::NOMINAL
    );
    let period_ns = 1_000_000u64 >> (6 - odr_code.clamp(3, 6));
    let t0 = 100 * MS;
    r.rig.loop_starts();
    for k in 0..n {
        let t = t0 + k as u64 * period_ns;
        r.latch(k as i16, t, None);
        if r.rig.int1(t) {
            let d = betaflight_read(&mut r);
            r.run.samples.push(d);
        }
        assert!(!r.rig.int1(t + 8 * US), "the 8 µs pulse has ended");
    }
    r.run
}

/// Betaflight's data-ready read: one 15-byte burst from TEMP_DATA1, decoded big-endian.
pub fn betaflight_read(r: &mut Recorder<impl Rig>) -> Decoded {
    let b = r.burst(0x1D, 14);
    let be = |i: usize| i32::from(i16::from_be_bytes([b[i], b[i + 1]]));
    Decoded {
        accel: [be(2), be(4), be(6)],
        gyro: [be(8), be(10), be(12)],
    }
}

/// Betaflight's detection and `icm426xxGyroInit` at `odr_code`; `afsr_off` = false leaves out
/// the INTF_CONFIG1 read-modify-write that turns AFSR off (Betaflight before PR #13132).
pub fn betaflight_init(r: &mut Recorder<impl Rig>, odr_code: u8, afsr_off: bool) {
    r.write(0x11, 0x01); // DEVICE_CONFIG: soft reset
    r.write(0x4E, 0x00); // detection: PWR_MGMT0 off
    assert_eq!(r.read(0x75), 0x47, "WHO_AM_I");
    r.write(0x76, 0); // bank 0, sensors off while configuring
    r.write(0x4E, 0x00);
    r.write(0x76, 1); // gyro AAF 258 Hz: DELT 6, DELTSQR 36, BITSHIFT 10
    r.write(0x0C, 6);
    r.write(0x0D, 36);
    r.write(0x0E, 10 << 4);
    r.write(0x76, 2); // accel AAF, same
    r.write(0x03, 6 << 1);
    r.write(0x04, 36);
    r.write(0x05, 10 << 4);
    r.write(0x76, 0);
    r.write(0x52, 0xFF); // GYRO_ACCEL_CONFIG0: low-latency UI filters
    r.write(0x14, 0x03); // INT_CONFIG: INT1 pulsed, push-pull, active high
    r.write(0x63, 0x00); // INT_CONFIG0: clear on status read
    r.write(0x65, 0x08); // INT_SOURCE0: UI data ready on INT1
    let int_config1 = r.read(0x64);
    r.write(0x64, (int_config1 & !0x10) | 0x60); // async reset off, 8 µs, no de-assert
    if afsr_off {
        let intf_config1 = r.read(0x4D);
        r.write(0x4D, (intf_config1 & !0xC0) | 0x40); // AFSR off
    }
    r.write(0x4E, 0x0F); // gyro and accel low noise
    r.write(0x4F, odr_code); // ±2000 °/s
    r.write(0x50, odr_code); // ±16 g
}
