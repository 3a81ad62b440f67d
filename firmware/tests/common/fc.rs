//! Flight-controller register sequences, written from what the drivers do (their register
//! traffic and checks as read in their sources, 2025–2026), not from their code:
//!
//! - [`fc_betaflight`]: Betaflight `accgyro_spi_mpu6000.c` / `accgyro_mpu.c`. Detection: H_RESET,
//!   then up to five tries 150 ms apart for WHO_AM_I = 0x68, then PRODUCT_ID (0x0C) must be one
//!   of the MPU-6000 revisions (0x14–0x18, 0x54–0x5A). Init: H_RESET, 150 ms,
//!   SIGNAL_PATH_RESET = 0x07, 150 ms, PWR_MGMT_1 = 0x03 (PLL, gyro Z), USER_CTRL = I2C_IF_DIS,
//!   PWR_MGMT_2 = 0, SMPLRT_DIV = 0, GYRO_CONFIG = ±2000 °/s, ACCEL_CONFIG = ±16 g,
//!   INT_PIN_CFG = INT_ANYRD_2CLEAR, INT_ENABLE = DATA_RDY, CONFIG = DLPF_CFG 0 (8 kHz). Then on
//!   every data-ready edge one 14-byte burst from ACCEL_XOUT_H (0x3B).
//! - [`fc_ardupilot`]: ArduPilot `AP_InertialSensor_Invensense.cpp`. `_hardware_init`: WHO_AM_I,
//!   USER_CTRL read, DEVICE_RESET, 100 ms, SIGNAL_PATH_RESET = 0x07, 100 ms, USER_CTRL |=
//!   I2C_IF_DIS, PWR_MGMT_1 = 0x03, 5 ms, and PWR_MGMT_1 must read back exactly 0x03 (else
//!   retry, five times). `start`: PWR_MGMT_2 = 0, FIFO reset (FIFO_EN = 0, USER_CTRL without
//!   FIFO_EN, with FIFO_RST, with FIFO_EN, FIFO_EN = TEMP|XG|YG|ZG|ACCEL), CONFIG = FIFO_MODE |
//!   DLPF_CFG (1: 1 kHz, or 0 with fast sampling: 8 kHz), SMPLRT_DIV = 0, GYRO_CONFIG = ±2000 °/s,
//!   PRODUCT_ID read (rev. C parts get ±8 g, others ±16 g), INT_ENABLE = RAW_RDY, INT_PIN_CFG.
//!   Every 1 ms: FIFO_COUNTH/L, `count / 14` records (more than 32: read 24 and reset the FIFO
//!   afterwards) from FIFO_R_W; each record's temperature is checked against a cached TEMP_OUT:
//!   within 400 LSB passes, else TEMP_OUT (0x41) is read again and the record passes within
//!   800 LSB; a failing record resets the FIFO and drops the rest of the read.
//! - [`px4_mpu9250`]: the same sequence as the MPU-9250 driver (WHO_AM_I 0x71, I2C_IF_DIS in
//!   USER_CTRL); a FIFO count of the whole FIFO is an overflow: FIFO reset.
//! - [`px4_icm20602`]: PX4 `icm20602/ICM20602.cpp`: DEVICE_RESET, PWR_MGMT_1 = CLKSEL 1,
//!   I2C_IF = I2C_IF_DIS, ACCEL_CONFIG2 = ACCEL_FCHOICE_B (4 kHz), CONFIG = FIFO_MODE |
//!   DLPF_CFG 7 (8 kHz), GYRO_CONFIG = ±2000 °/s, ACCEL_CONFIG = ±16 g, FIFO_EN = GYRO | ACCEL,
//!   USER_CTRL = FIFO_EN | FIFO_RST; then one burst from FIFO_COUNTH (count, then the FIFO port)
//!   per 1 ms, and the accel check of `ProcessAccel`: with four or more records, either
//!   records 0 = 1 and 2 = 3 (accel taken from odd records) or 1 = 2 (even records), otherwise
//!   the transfer is bad.
//!
//! Each sequence drives any [`SpiTarget`] through a [`Board`] (time and data-ready come from
//! the board) and returns what it decoded, sample by sample; the tests check the order.

use margemu_firmware::chip::SpiTarget;

/// What a sequence needs from the world around the chip.
pub trait Board {
    /// The chip on the SPI bus.
    type Chip: SpiTarget;
    /// The chip, for one transaction.
    fn chip(&mut self) -> &mut Self::Chip;
    /// Lets `ns` pass (the chip latches whatever samples fall in it).
    fn wait_ns(&mut self, ns: u64);
    /// Waits for the next data-ready edge.
    fn wait_data_ready(&mut self);
    /// The driver's initialisation is over: its sampling loop starts (a board measuring the
    /// bus counts from here, at the driver's sample clock).
    fn loop_starts(&mut self) {}
}

/// One decoded record: ACCEL_XOUT, ACCEL_ZOUT, TEMP_OUT, GYRO_XOUT.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Record {
    pub accel_x: i16,
    pub accel_z: i16,
    pub temp: i16,
    pub gyro_x: i16,
}

impl Record {
    /// From the 14 bytes of 0x3B..=0x48 (or a FIFO record of the same layout).
    pub fn parse(bytes: &[u8]) -> Self {
        Self {
            accel_x: super::be(bytes, 0),
            accel_z: super::be(bytes, 4),
            temp: super::be(bytes, 6),
            gyro_x: super::be(bytes, 8),
        }
    }
}

/// What a run decoded.
#[derive(Clone, Debug, Default)]
pub struct FcRun {
    /// Every record the driver accepted, in order.
    pub records: Vec<Record>,
    /// FIFO resets after start-up (each drops what the FIFO held).
    pub fifo_resets: usize,
    /// Transfers the driver rejected (PX4's accel-duplicate check).
    pub bad_transfers: usize,
}

/// Why a sequence gave up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FcError {
    /// WHO_AM_I was not the expected value (what was read).
    WhoAmI(u8),
    /// PRODUCT_ID not in Betaflight's list.
    ProductId(u8),
    /// PWR_MGMT_1 never read back the clock selection (last value read).
    ClockReadBack(u8),
    /// A configured register read back something else (register, value read).
    ReadBack(u8, u8),
}

fn transfer<B: Board>(board: &mut B, mosi: &[u8]) -> Vec<u8> {
    super::spi(board.chip(), mosi)
}

fn read<B: Board>(board: &mut B, addr: u8, n: usize) -> Vec<u8> {
    super::spi_read(board.chip(), addr, n)
}

fn write<B: Board>(board: &mut B, addr: u8, value: u8) {
    transfer(board, &[addr & 0x7F, value]);
}

const MPU6000_PRODUCT_IDS: [u8; 12] = [
    0x14, 0x15, 0x16, 0x17, 0x18, 0x54, 0x55, 0x56, 0x57, 0x58, 0x59, 0x5A,
];

/// Betaflight's MPU-6000 SPI driver: detect, init at 8 kHz, then `samples` data-ready reads.
pub fn fc_betaflight<B: Board>(board: &mut B, samples: usize) -> Result<FcRun, FcError> {
    // Detection.
    write(board, 0x6B, 0x80);
    let mut who_am_i = 0;
    for _ in 0..5 {
        board.wait_ns(150_000_000);
        who_am_i = read(board, 0x75, 1)[0];
        if who_am_i == 0x68 {
            break;
        }
    }
    if who_am_i != 0x68 {
        return Err(FcError::WhoAmI(who_am_i));
    }
    let product_id = read(board, 0x0C, 1)[0];
    if !MPU6000_PRODUCT_IDS.contains(&product_id) {
        return Err(FcError::ProductId(product_id));
    }
    // Init.
    write(board, 0x6B, 0x80);
    board.wait_ns(150_000_000);
    write(board, 0x68, 0x07);
    board.wait_ns(150_000_000);
    for (reg, value) in [
        (0x6B, 0x03), // PLL with gyro Z
        (0x6A, 0x10), // I2C_IF_DIS
        (0x6C, 0x00),
        (0x19, 0x00), // SMPLRT_DIV
        (0x1B, 0x18), // ±2000 °/s
        (0x1C, 0x18), // ±16 g
        (0x37, 0x10), // INT_ANYRD_2CLEAR
        (0x38, 0x01), // DATA_RDY_EN
    ] {
        write(board, reg, value);
        board.wait_ns(15_000);
    }
    write(board, 0x1A, 0x00); // DLPF_CFG 0: 8 kHz
    board.loop_starts(); // Run: one 14-byte burst per data-ready edge.
    let mut run = FcRun::default();
    let mut burst = [0u8; 15];
    burst[0] = 0x80 | 0x3B;
    for _ in 0..samples {
        board.wait_data_ready();
        let miso = transfer(board, &burst);
        run.records.push(Record::parse(&miso[1..]));
    }
    Ok(run)
}

/// Options of [`fc_ardupilot`].
#[derive(Clone, Copy, Debug, Default)]
pub struct ArduPilotOptions {
    /// Fast sampling: DLPF_CFG 0, 8 kHz into the FIFO (else DLPF_CFG 1, 1 kHz).
    pub fast_sampling: bool,
    /// Before poll number `n`, one byte is read from FIFO_R_W on its own (a lost byte, as after
    /// a bus glitch), so the records that follow are misaligned.
    pub lose_byte_before_poll: Option<usize>,
}

/// ArduPilot's Invensense driver on SPI: init, start, then `polls` FIFO reads 1 ms apart.
pub fn fc_ardupilot<B: Board>(
    board: &mut B,
    polls: usize,
    options: ArduPilotOptions,
) -> Result<FcRun, FcError> {
    let mut driver = ardupilot_init(board, options, 0x68)?;
    board.loop_starts();
    let mut run = FcRun::default();
    for poll in 0..polls {
        board.wait_ns(1_000_000);
        if options.lose_byte_before_poll == Some(poll) {
            read(board, 0x74, 1);
        }
        ardupilot_poll(board, &mut driver, &mut run);
    }
    Ok(run)
}

/// What ArduPilot's Invensense driver remembers between polls.
#[derive(Clone, Debug)]
pub struct ArduPilotDriver {
    /// USER_CTRL as it last wrote it.
    pub user_ctrl: u8,
    /// The cached TEMP_OUT of `_check_raw_temp`.
    pub cached_temp: i16,
    /// The registers `start` configured, (register, value), in the order a periodic
    /// read-back (`check_next_register`) visits them.
    pub checked: Vec<(u8, u8)>,
}

/// ArduPilot's `_hardware_init` and `start` for a part answering `who_am_i`.
pub fn ardupilot_init<B: Board>(
    board: &mut B,
    options: ArduPilotOptions,
    who_am_i: u8,
) -> Result<ArduPilotDriver, FcError> {
    let got = read(board, 0x75, 1)[0];
    if got != who_am_i {
        return Err(FcError::WhoAmI(got));
    }
    // _hardware_init
    let mut user_ctrl = 0;
    let mut pwr1 = 0;
    for _ in 0..5 {
        user_ctrl = read(board, 0x6A, 1)[0];
        write(board, 0x6B, 0x80);
        board.wait_ns(100_000_000);
        write(board, 0x68, 0x07);
        board.wait_ns(100_000_000);
        user_ctrl |= 0x10;
        write(board, 0x6A, user_ctrl);
        write(board, 0x6B, 0x03);
        board.wait_ns(5_000_000);
        pwr1 = read(board, 0x6B, 1)[0];
        if pwr1 == 0x03 {
            break;
        }
        board.wait_ns(10_000_000);
    }
    if pwr1 != 0x03 {
        return Err(FcError::ClockReadBack(pwr1));
    }
    // start
    write(board, 0x6C, 0x00);
    board.wait_ns(1_000_000);
    user_ctrl = ardupilot_fifo_reset(board, user_ctrl);
    let config = if options.fast_sampling { 0x40 } else { 0x41 };
    write(board, 0x1A, config);
    write(board, 0x19, 0x00);
    board.wait_ns(1_000_000);
    write(board, 0x1B, 0x18);
    board.wait_ns(1_000_000);
    let product_id = read(board, 0x0C, 1)[0];
    let rev_c = matches!(product_id, 0x14 | 0x15 | 0x54 | 0x55);
    write(board, 0x1C, if rev_c { 0x08 } else { 0x18 });
    board.wait_ns(1_000_000);
    write(board, 0x38, 0x01);
    board.wait_ns(1_000_000);
    let pin_cfg = (read(board, 0x37, 1)[0] | 0x30) & 0x02; // as the driver computes it
    write(board, 0x37, pin_cfg);
    let checked = vec![
        (0x6C, 0x00),
        (0x1A, config),
        (0x19, 0x00),
        (0x1B, 0x18),
        (0x1C, if rev_c { 0x08 } else { 0x18 }),
        (0x38, 0x01),
        (0x37, pin_cfg),
        (0x23, 0xF8),
        (0x6A, user_ctrl),
    ];
    Ok(ArduPilotDriver {
        user_ctrl,
        cached_temp: 0,
        checked,
    })
}

/// One `_read_fifo`: FIFO_COUNT, the records (each checked by `_check_raw_temp`), a FIFO
/// reset when a record fails or more than 32 were waiting.
pub fn ardupilot_poll<B: Board>(board: &mut B, driver: &mut ArduPilotDriver, run: &mut FcRun) {
    let count = u16::from_be_bytes(read(board, 0x72, 2).try_into().unwrap_or([0, 0]));
    let mut n = usize::from(count) / 14;
    let need_reset = n > 32;
    if need_reset {
        n = 24;
    }
    if n == 0 {
        return;
    }
    let data = read(board, 0x74, 14 * n);
    for record in data.chunks_exact(14) {
        let r = Record::parse(record);
        if !ardupilot_temp_ok(board, r.temp, &mut driver.cached_temp) {
            driver.user_ctrl = ardupilot_fifo_reset(board, driver.user_ctrl);
            run.fifo_resets += 1;
            break;
        }
        run.records.push(r);
    }
    if need_reset {
        driver.user_ctrl = ardupilot_fifo_reset(board, driver.user_ctrl);
        run.fifo_resets += 1;
    }
}

/// `_check_raw_temp`: within 400 LSB of the cached TEMP_OUT passes; else re-read TEMP_OUT and
/// pass within 800 LSB.
fn ardupilot_temp_ok<B: Board>(board: &mut B, fifo_temp: i16, cached: &mut i16) -> bool {
    let diff = |a: i16, b: i16| (i32::from(a) - i32::from(b)).abs();
    if diff(fifo_temp, *cached) < 400 {
        return true;
    }
    *cached = super::be(&read(board, 0x41, 2), 0);
    diff(fifo_temp, *cached) < 800
}

/// `_fifo_reset`; returns the USER_CTRL value the driver remembers.
fn ardupilot_fifo_reset<B: Board>(board: &mut B, user_ctrl: u8) -> u8 {
    let base = user_ctrl & !(0x04 | 0x40);
    write(board, 0x23, 0x00);
    write(board, 0x6A, base);
    write(board, 0x6A, base | 0x04);
    write(board, 0x6A, base | 0x40);
    write(board, 0x23, 0xF8);
    board.wait_ns(1_000);
    base | 0x40
}

/// PX4's ICM-20602 driver at 8 kHz: configure, then `polls` FIFO bursts 1 ms apart, each
/// checked for the duplicated-accel pattern. Returns the records of every transfer it accepted.
pub fn px4_icm20602<B: Board>(board: &mut B, polls: usize) -> Result<FcRun, FcError> {
    px4_fifo_8khz(
        board,
        polls,
        (0x12, 1008),
        (0x70, 0x40),
        0x18,
        &mut |_, _| {},
    )
}

/// PX4's MPU-9250 driver (`src/drivers/imu/invensense/mpu9250/MPU9250.cpp`) at 8 kHz: the
/// ICM-20602's sequence with WHO_AM_I 0x71, I2C_IF_DIS in USER_CTRL (bit 4) and FIFO_EN
/// naming temperature, each gyro axis and the accelerometer (the same 14-byte records).
pub fn px4_mpu9250<B: Board>(board: &mut B, polls: usize) -> Result<FcRun, FcError> {
    px4_mpu9250_with(board, polls, &mut |_, _| {})
}

/// [`px4_mpu9250`] calling `before_poll(board, poll)` before each poll (to inject a fault).
pub fn px4_mpu9250_with<B: Board>(
    board: &mut B,
    polls: usize,
    before_poll: &mut dyn FnMut(&mut B, usize),
) -> Result<FcRun, FcError> {
    px4_fifo_8khz(board, polls, (0x71, 512), (0x6A, 0x10), 0xF8, before_poll)
}

/// The PX4 InvenSense 8 kHz FIFO sequence for a part answering `who_am_i` with a FIFO of
/// `fifo_size` bytes, with its I2C interface disabled by `(register, value)` and `fifo_en`
/// giving 14-byte records. A count of the whole FIFO is an overflow (PX4's `FIFOReadCount`
/// check): the driver resets the FIFO (FIFO_EN off, USER_CTRL.FIFO_RST, FIFO_EN back) and
/// counts it in [`FcRun::fifo_resets`].
fn px4_fifo_8khz<B: Board>(
    board: &mut B,
    polls: usize,
    (who_am_i, fifo_size): (u8, usize),
    i2c_if_dis: (u8, u8),
    fifo_en: u8,
    before_poll: &mut dyn FnMut(&mut B, usize),
) -> Result<FcRun, FcError> {
    write(board, 0x6B, 0x80);
    board.wait_ns(2_000_000);
    let got = read(board, 0x75, 1)[0];
    if got != who_am_i {
        return Err(FcError::WhoAmI(got));
    }
    let user_ctrl = if i2c_if_dis.0 == 0x6A {
        i2c_if_dis.1
    } else {
        0
    };
    for (reg, value) in [
        (0x6B, 0x01), // CLKSEL 1
        i2c_if_dis,
        (0x1D, 0x08),    // ACCEL_FCHOICE_B: 4 kHz
        (0x1A, 0x47),    // FIFO_MODE, DLPF_CFG 7: 8 kHz
        (0x1B, 0x18),    // ±2000 °/s
        (0x1C, 0x18),    // ±16 g
        (0x23, fifo_en), // gyro and accel (and, on the MPU-9250, temperature)
        (0x37, 0xA0),    // active low, latched
        (0x38, 0x01),
        (0x6A, user_ctrl | 0x44), // FIFO_EN | FIFO_RST
    ] {
        write(board, reg, value);
    }
    let check = if user_ctrl == 0 {
        i2c_if_dis
    } else {
        (0x1A, 0x47)
    };
    for (reg, value) in [(0x1A, 0x47), (0x1D, 0x08), (0x23, fifo_en), check] {
        let back = read(board, reg, 1)[0];
        if back != value {
            return Err(FcError::ReadBack(reg, back));
        }
    }
    board.loop_starts();
    let mut run = FcRun::default();
    for poll in 0..polls {
        before_poll(board, poll);
        board.wait_ns(1_000_000);
        let count = u16::from_be_bytes(read(board, 0x72, 2).try_into().unwrap_or([0, 0]));
        if usize::from(count) >= fifo_size {
            write(board, 0x23, 0x00);
            write(board, 0x6A, user_ctrl | 0x04);
            write(board, 0x6A, user_ctrl | 0x40);
            write(board, 0x23, fifo_en);
            run.fifo_resets += 1;
            continue;
        }
        let samples = usize::from(count) / 14;
        if samples == 0 {
            continue;
        }
        // One transfer: FIFO_COUNTH, FIFO_COUNTL, then the FIFO port.
        let mut mosi = vec![0u8; 3 + 14 * samples];
        mosi[0] = 0x80 | 0x72;
        let miso = transfer(board, &mosi);
        let records: Vec<Record> = miso[3..].chunks_exact(14).map(Record::parse).collect();
        if !px4_accel_pattern_ok(&miso[3..], samples) {
            run.bad_transfers += 1;
            continue;
        }
        run.records.extend(records);
    }
    Ok(run)
}

/// `ProcessAccel`'s check: with four or more records, accel(0) = accel(1) and accel(2) =
/// accel(3), or accel(1) = accel(2).
pub fn px4_accel_pattern_ok(fifo: &[u8], samples: usize) -> bool {
    if samples < 4 {
        return true;
    }
    let accel = |i: usize| &fifo[14 * i..14 * i + 6];
    (accel(0) == accel(1) && accel(2) == accel(3)) || accel(1) == accel(2)
}

impl<C: super::BenchChip> Board for super::Bench<C> {
    type Chip = C;

    fn chip(&mut self) -> &mut C {
        &mut self.chip
    }

    fn wait_ns(&mut self, ns: u64) {
        super::Bench::wait_ns(self, ns);
    }

    fn wait_data_ready(&mut self) {
        super::Bench::wait_data_ready(self);
    }

    fn loop_starts(&mut self) {
        self.chip.loop_starts();
    }
}
