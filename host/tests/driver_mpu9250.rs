//! The `mpu9250` crate (0.25, embedded-hal 0.2), unmodified, drives the emulated MPU-9250 through
//! margemu's embedded-hal 1.0 adapters (`margemu::bus`), bridged back to 0.2 by
//! `embedded-hal-compat` (`.reverse()`; chip select `.reverse_cell()`).
//!
//! - SPI in MARG mode ([`spi`], the crate 0.25): `SpiBus` + `ChipSelect`; the AK8963 sits behind
//!   the chip's auxiliary I2C master (slave 4 for single transfers, slave 0 copying HXL..ST2 into
//!   EXT_SENS_DATA at every sample).
//! - I2C ([`i2c`], the crate 0.24.1 with its `i2c` feature): the AK8963 is read directly at 0x0C
//!   in bypass mode. The crate's `i2c` feature replaces its SPI constructors, and cargo gives one
//!   version of a crate one set of features per build, so the I2C tests use the release before
//!   (a dev-dependency renamed `mpu9250-i2c`; same driver code on these paths). Both modules
//!   include the same test body (`driver_mpu9250/common.rs`) under their own copy of the crate.
//!
//! For every accelerometer and gyroscope full scale (and both magnetometer resolutions) the
//! driver initialises the chip, then reads accel, gyro, temperature and magnetometer while the
//! chip is fed a kinematic scene's MARG samples. Each value must match the sample to within one
//! LSB of the current full scale in the units the driver actually returns: the sample becomes
//! register counts at the chip's (datasheet) sensitivity, clipped like the register, and is
//! then scaled the driver's way (`Axis::deviation`). Taken at face value instead, the driver's
//! own constants cost up to 18 LSB (gyro) and 1.5 LSB (accel), printed in parentheses.
//!
//! What the driver returns (read in `mpu9250-0.25.0/src`, not its docs):
//! - accel: `lib.rs` `scale_accel` (l. 1320) returns `raw · FS/32768 · G` with `pub const G =
//!   9.807` (l. 164): m/s² on the driver's own g, although `accel()` (l. 1414) and
//!   `MargMeasurements` (l. 2147) say "g". 9.807 is 35.7 ppm above standard gravity (9.80665,
//!   the chip's g): 1.2 LSB at the top of ±2 g.
//! - gyro: `scale_gyro` (l. 1327) returns `raw · FS/32768 · π/180`: rad/s, as documented, but
//!   on 32768/FS LSB per °/s (`conf.rs` l. 138: 131.072, 65.536, 32.768, 16.384), where the
//!   datasheet and the chip use 131, 65.5, 32.8, 16.4: the driver reads 550 ppm low (±250,
//!   ±500 °/s) or 977 ppm high (±1000, ±2000 °/s), up to 18 LSB near full scale.
//! - temperature: `scale_temp` (l. 1334) returns `raw / 333.87 + 21` °C but assembles `raw` as
//!   an **unsigned** u16 (l. 1335), so any reading below 21 °C comes back near 217 °C; the
//!   scene stays above 21 °C and `temperature_below_21_c_reads_as_unsigned` pins the bug.
//! - magnetometer: `scale_and_correct_mag` (l. 841) returns `raw · res · ASA_adj` with
//!   `res = 10 · 4912/32768` (16-bit) or `10 · 4912/8192` (14-bit) (`conf.rs` l. 192): that is
//!   **milligauss** (1 µT = 10 mG), not the µT of its docs (l. 859, l. 2151), and 650 ppm
//!   below the datasheet's 0.15 / 0.6 µT per LSB; `ASA_adj = (ASA − 128)/256 + 1` from the
//!   fuse ROM (l. 721, computed as `u8 − 128`, so an ASA below 128 would panic on overflow in
//!   a debug build). It does **not** remap axes (`to_vector_inverted`, l. 1819, only reads
//!   little-endian): the values are in the AK8963's own axes (x = chip y, y = chip x,
//!   z = −chip z).

mod spi {
    use ::mpu9250;
    include!("driver_mpu9250/common.rs");

    use embedded_hal::spi::SpiDevice as _;
    use embedded_hal_compat::Reverse;
    use std::cell::RefCell;

    type Spi = Reverse<bus::SpiBus<Chip>>;
    type Cs = Reverse<RefCell<bus::ChipSelect<Chip>>>;
    type Mpu = mpu9250::Mpu9250<mpu9250::SpiDevice<Spi, Cs>, Marg>;

    impl_driver!(Mpu);

    /// Raw SPI beside the driver (chip select is released between the driver's accesses).
    struct RawSpi(bus::SpiDevice<Chip>);

    impl Raw for RawSpi {
        fn mpu(&mut self, reg: u8) -> u8 {
            let mut buf = [0x80 | reg, 0];
            self.0.transfer_in_place(&mut buf).unwrap();
            buf[1]
        }
    }

    /// The crate's SPI wiring: a bus and a chip-select pin, both reversed to embedded-hal 0.2.
    fn connect(chip: &Shared<Chip>) -> (Spi, Cs) {
        let (spi, cs) = bus::SpiBus::new(chip.clone());
        (spi.reverse(), cs.reverse_cell())
    }

    fn init(chip: &Shared<Chip>, config: &mut MpuConfig<Marg>) -> (Mpu, RawSpi) {
        let (spi, cs) = connect(chip);
        let mpu = Mpu::marg(spi, cs, &mut ChipDelay::new(chip), config).unwrap();
        (mpu, RawSpi(bus::SpiDevice::new(chip.clone())))
    }

    #[test]
    fn marg_default_initialises_over_spi() {
        guarded(|| {
            let chip = new_chip();
            let (spi, cs) = connect(&chip);
            let mut delay = ChipDelay::new(&chip);
            let mut mpu = Mpu::marg_default(spi, cs, &mut delay).unwrap();
            assert_eq!(Driver::who_am_i(&mut mpu), (0x71, 0x48));
            let waited = delay.clock.now_ns();
            assert!(
                waited >= 100_000_000,
                "100 ms after reset, {waited} ns in all"
            );
            assert_eq!(chip.borrow().now_ns(), waited);
            let mut raw = RawSpi(bus::SpiDevice::new(chip.clone()));
            // marg_default: ±2 g, ±250 °/s, DLPF 0, SMPLRT_DIV untouched, 14-bit magnetometer.
            let expected = [
                (0x1A, 0x00, "CONFIG"),
                (0x1B, 0x00, "GYRO_CONFIG"),
                (0x1C, 0x00, "ACCEL_CONFIG"),
                (0x1D, 0x40, "ACCEL_CONFIG2"),
                (0x19, 0x00, "SMPLRT_DIV"),
                // 0x32 written: I2C_MST_EN | I2C_IF_DIS | I2C_MST_RST (self-clearing).
                (0x6A, 0x30, "USER_CTRL"),
                (0x24, 0x0D, "I2C_MST_CTRL: 400 kHz"),
                (0x25, 0x8C, "I2C_SLV0_ADDR: read from 0x0C"),
                (0x26, 0x03, "I2C_SLV0_REG: HXL"),
                (0x27, 0x87, "I2C_SLV0_CTRL: enabled, 7 bytes (HXL..ST2)"),
            ];
            for (reg, value, what) in expected {
                assert_eq!(raw.mpu(reg), value, "{what}");
            }
            assert_eq!(
                ak8963_peek(&chip, 0x0A),
                0x06,
                "AK8963 CNTL1: 14-bit, mode 2"
            );
            let asa = chip.borrow().config().asa;
            assert_eq!(mpu.mag_adjustments(), asa.map(asa_factor));
        });
    }

    #[test]
    fn every_full_scale_over_spi() {
        guarded(|| every_full_scale("SPI", init));
    }

    #[test]
    fn scales_changed_at_run_time_over_spi() {
        guarded(|| scales_changed_at_run_time(init));
    }

    #[test]
    fn temperature_below_21_c_reads_as_unsigned_over_spi() {
        guarded(|| temperature_below_21_c_reads_as_unsigned(init));
    }
}

mod i2c {
    use ::mpu9250_i2c as mpu9250;
    include!("driver_mpu9250/common.rs");

    use embedded_hal::i2c::I2c as _;
    use embedded_hal_compat::Reverse;

    type Mpu = mpu9250::Mpu9250<mpu9250::I2cDevice<Reverse<bus::I2c<Chip>>>, Marg>;

    impl_driver!(Mpu);

    /// Raw I2C beside the driver, to the MPU-9250 at 0x68.
    struct RawI2c(bus::I2c<Chip>);

    impl Raw for RawI2c {
        fn mpu(&mut self, reg: u8) -> u8 {
            let mut buf = [0];
            self.0.write_read(0x68, &[reg], &mut buf).unwrap();
            buf[0]
        }
    }

    fn init(chip: &Shared<Chip>, config: &mut MpuConfig<Marg>) -> (Mpu, RawI2c) {
        let i2c = bus::I2c::new(chip.clone()).reverse();
        let mpu = Mpu::marg(i2c, &mut ChipDelay::new(chip), config).unwrap();
        (mpu, RawI2c(bus::I2c::new(chip.clone())))
    }

    #[test]
    fn marg_default_initialises_over_i2c_in_bypass() {
        guarded(|| {
            let chip = new_chip();
            let i2c = bus::I2c::new(chip.clone()).reverse();
            let mut mpu = Mpu::marg_default(i2c, &mut ChipDelay::new(&chip)).unwrap();
            assert_eq!(Driver::who_am_i(&mut mpu), (0x71, 0x48));
            let mut raw = RawI2c(bus::I2c::new(chip.clone()));
            assert_eq!(raw.mpu(0x6A), 0x00, "USER_CTRL: I2C master off");
            // ACTL | LATCH_INT_EN | INT_ANYRD_2CLEAR | BYPASS_EN.
            assert_eq!(raw.mpu(0x37), 0xB2, "INT_PIN_CFG");
            assert!(chip.borrow().bypass_active());
            let mut ak = [0];
            raw.0.write_read(0x0C, &[0x0A], &mut ak).unwrap();
            assert_eq!(ak, [0x06], "AK8963 CNTL1 over bypass: 14-bit, mode 2");
            let asa = chip.borrow().config().asa;
            assert_eq!(mpu.mag_adjustments(), asa.map(asa_factor));
        });
    }

    #[test]
    fn every_full_scale_over_i2c() {
        guarded(|| every_full_scale("I2C", init));
    }

    #[test]
    fn scales_changed_at_run_time_over_i2c() {
        guarded(|| scales_changed_at_run_time(init));
    }

    #[test]
    fn temperature_below_21_c_reads_as_unsigned_over_i2c() {
        guarded(|| temperature_below_21_c_reads_as_unsigned(init));
    }
}
