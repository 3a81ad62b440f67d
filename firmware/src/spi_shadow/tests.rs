use margemu_protocol::regmap::mpu6xxx::image::IMAGE_LEN;
use margemu_protocol::regmap::mpu6xxx::{is_read_only, reg};

use super::sim::{SimPort, Timing, FAST, SIM_LEN, SLOW, UNDERRUN};
use super::*;
use crate::chip::{Chip, EmulatedChip, SpiTarget};

const READ: u8 = 0x80;
/// The MPU-9250's burst start ([`Chip::burst_start`]).
const DEFAULT_START: u8 = reg::ACCEL_XOUT_H;

/// A chip with a recognisable sample latched (every image byte distinct and non-zero).
fn chip_with_sample() -> EmulatedChip {
    let mut chip = EmulatedChip::default();
    let image: [u8; IMAGE_LEN] = core::array::from_fn(|i| 0x11 + i as u8 * 7);
    chip.latch_image_at(&image, 1_000_000);
    chip
}

/// What the chip itself puts on MISO for `mosi` (one byte ahead, as `SpiTarget` specifies),
/// on a copy so the chip is left as it was.
fn reference(chip: &EmulatedChip, mosi: &[u8]) -> [u8; SIM_LEN] {
    let mut chip = chip.clone();
    let mut miso = [0; SIM_LEN];
    let mut next = chip.select();
    for (slot, &m) in miso.iter_mut().zip(mosi) {
        *slot = next;
        next = chip.exchange(m);
    }
    chip.deselect();
    miso
}

/// Serves `mosi` through the simulated port from `shadow`; returns the capture and the MISO the
/// controller saw, and checks the capture records exactly what was sent.
fn transact(timing: Timing, shadow: &mut Shadow, mosi: &[u8]) -> (Capture, [u8; SIM_LEN]) {
    let mut port = SimPort::new(timing, mosi, shadow.stream());
    let mut capture = Capture::new();
    serve(&mut port, shadow, &mut capture);
    let n = capture.sent().len();
    assert_eq!(
        capture.sent(),
        &port.miso()[..n],
        "capture records what was sent"
    );
    (capture, port.shifted)
}

fn burst(start: u8, data_bytes: usize) -> [u8; 40] {
    let mut mosi = [0; 40];
    mosi[0] = READ | start;
    mosi[data_bytes + 1..].fill(0xA5); // beyond the burst: marks bytes a test must not send
    mosi
}

#[test]
fn shadow_reads_what_the_bus_reads_and_streams_the_burst() {
    let chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 3);
    assert_eq!(chip.burst_start(), DEFAULT_START);
    for addr in 0..128u8 {
        assert_eq!(
            shadow.read(addr),
            chip.spi_peek(addr),
            "register {addr:#04x}"
        );
    }
    let mut mosi = [0u8; STREAM_LEN];
    mosi[0] = READ | DEFAULT_START;
    let want = reference(&chip, &mosi);
    assert_eq!(&shadow.stream()[..], &want[..STREAM_LEN]);
    assert_eq!(shadow.generation(), 3);
    assert_eq!(shadow.burst_address(0x3B, 1), 0x3B);
    assert_eq!(shadow.burst_address(0x3B, 6), 0x40);
    assert_eq!(shadow.burst_address(reg::FIFO_R_W, 9), reg::FIFO_R_W);
    assert_eq!(shadow.burst_address(0x7F, 2), 0x00);
}

#[test]
fn write_through_matches_the_chip_wherever_it_acts() {
    for addr in 0..128u8 {
        for value in [0x00, 0xFF, 0xA5, 0x5A] {
            let mut chip = chip_with_sample();
            let mut shadow = Shadow::new();
            shadow.capture(&chip, DEFAULT_START, 0);
            let mosi = [addr, value];
            shadow.write_through(&mosi);
            replay(&mut chip, &Capture::from_bytes(&mosi, &[0, 0], 0, None), 0);
            let mut fresh = Shadow::new();
            fresh.capture(&chip, DEFAULT_START, 0);
            if chip.spi_plain_write(addr, value).is_none() {
                continue; // left to the replay and the next capture
            }
            assert_eq!(shadow, fresh, "write {value:#04x} to {addr:#04x}");
        }
    }
}

#[test]
fn write_through_ignores_reads_and_read_only_registers() {
    let chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let before = shadow.clone();
    shadow.write_through(&[READ | reg::SMPLRT_DIV, 0x07]);
    shadow.write_through(&[reg::WHO_AM_I, 0x00]);
    shadow.write_through(&[reg::ACCEL_XOUT_H, 0x00, 0x00]);
    shadow.write_through(&[]);
    assert!(is_read_only(reg::WHO_AM_I));
    assert_eq!(shadow, before);
}

#[test]
fn sim_port_fast_burst_at_the_predicted_start_is_served_by_the_stream() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = burst(DEFAULT_START, 21);
    let want = reference(&chip, &mosi[..22]);
    let (capture, miso) = transact(FAST, &mut shadow, &mosi[..22]);
    assert_eq!(&miso[..22], &want[..22]);
    assert_eq!(capture.takeover(), None);
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Hit);
}

#[test]
fn sim_port_slow_register_read_is_taken_over_in_time() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = [READ | reg::WHO_AM_I, 0, 0];
    let (capture, miso) = transact(SLOW, &mut shadow, &mosi);
    assert_eq!(&miso[..3], &reference(&chip, &mosi)[..3]);
    assert_eq!(miso[1], 0x71);
    assert_eq!(capture.takeover(), Some(1));
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Fixed);
}

#[test]
fn sim_port_fast_register_read_misses_the_first_byte_and_is_counted() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = [READ | reg::WHO_AM_I, 0, 0, 0];
    let want = reference(&chip, &mosi);
    let (capture, miso) = transact(FAST, &mut shadow, &mosi);
    assert_eq!(miso[1], shadow.stream()[1], "the speculated byte went out");
    assert_ne!(miso[1], want[1]);
    assert!(!miso[..4].contains(&UNDERRUN));
    let took = capture.takeover().expect("a read elsewhere is taken over");
    assert!(took >= 2);
    assert_eq!(
        &miso[took..4],
        &want[took..4],
        "right again from the takeover on"
    );
    let mut stats = Stats::default();
    let outcome = replay(&mut chip, &capture, 0);
    stats.record(outcome);
    assert_eq!(
        outcome,
        Outcome::Miss {
            start: reg::WHO_AM_I
        }
    );
    assert_eq!((stats.transactions, stats.misses), (1, 1));
}

#[test]
fn sim_port_write_reaches_the_shadow_at_once_and_the_chip_on_replay() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = [reg::SMPLRT_DIV, 0x07, 0x03]; // SMPLRT_DIV, then CONFIG
    let (capture, _) = transact(FAST, &mut shadow, &mosi);
    assert_eq!(
        (shadow.read(reg::SMPLRT_DIV), shadow.read(reg::CONFIG)),
        (0x07, 0x03)
    );
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Write);
    assert_eq!(
        (chip.spi_peek(reg::SMPLRT_DIV), chip.spi_peek(reg::CONFIG)),
        (0x07, 0x03)
    );
    // The read-back, even at a fast clock, is served in time only by a takeover; at a slow one
    // it is right.
    let (capture, miso) = transact(SLOW, &mut shadow, &[READ | reg::SMPLRT_DIV, 0]);
    assert_eq!(miso[1], 0x07);
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Fixed);
}

#[test]
fn read_side_effects_reach_the_chip_through_the_replay() {
    let mut chip = chip_with_sample();
    let mut setup =
        |mosi: &[u8]| replay(&mut chip, &Capture::from_bytes(mosi, &[0; 3], 0, None), 0);
    setup(&[reg::INT_ENABLE, 0x01]);
    setup(&[reg::INT_PIN_CFG, 0x20]); // LATCH_INT_EN: the status holds until read
    let image = [0x22; IMAGE_LEN];
    chip.latch_image_at(&image, 2_000_000);
    assert_eq!(chip.spi_peek(reg::INT_STATUS), 0x01);
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 1);
    let (capture, miso) = transact(SLOW, &mut shadow, &[READ | reg::INT_STATUS, 0]);
    assert_eq!(miso[1], 0x01);
    assert_eq!(replay(&mut chip, &capture, 1), Outcome::Fixed);
    assert_eq!(
        chip.spi_peek(reg::INT_STATUS),
        0x00,
        "cleared by the replayed read"
    );
}

#[test]
fn sim_port_burst_from_an_older_shadow_is_stale_not_a_miss() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    chip.latch_image_at(&[0x33; IMAGE_LEN], 2_000_000); // generation 1, not yet in the shadow
    let mosi = burst(DEFAULT_START, 14);
    let (capture, _) = transact(FAST, &mut shadow, &mosi[..15]);
    assert_eq!(
        replay(&mut chip, &capture, 1),
        Outcome::Stale {
            start: DEFAULT_START
        }
    );
}

#[test]
fn sim_port_speculator_learns_a_new_burst_start() {
    let mut chip = chip_with_sample();
    let mut speculator = Speculator::new();
    let mut shadow = Shadow::new();
    let gyro = burst(reg::GYRO_XOUT_H, 6);
    let mut outcomes = [Outcome::Empty; 6];
    for outcome in &mut outcomes {
        shadow.capture(&chip, speculator.predict(chip.burst_start()), 0);
        let (capture, _) = transact(FAST, &mut shadow, &gyro[..7]);
        *outcome = replay(&mut chip, &capture, 0);
        speculator.observe(&capture);
    }
    let miss = Outcome::Miss {
        start: reg::GYRO_XOUT_H,
    };
    // The first burst has no predecessor, the second's predecessor has no successor yet.
    assert_eq!(
        outcomes,
        [
            miss,
            miss,
            Outcome::Hit,
            Outcome::Hit,
            Outcome::Hit,
            Outcome::Hit
        ]
    );
    assert_eq!(speculator.predict(DEFAULT_START), reg::GYRO_XOUT_H);
    assert_eq!(
        speculator.fallback(),
        Some(reg::GYRO_XOUT_H),
        "after SWITCH_AFTER bursts"
    );
    // Single-register reads and writes do not move the fallback.
    for mosi in [[READ | reg::WHO_AM_I, 0, 0], [reg::CONFIG, 1, 0]] {
        for _ in 0..2 * SWITCH_AFTER {
            let len = if mosi[0] & READ != 0 { 2 } else { 3 };
            let capture = Capture::from_bytes(&mosi[..len], &[0; 3], 0, None);
            speculator.observe(&capture);
        }
    }
    assert_eq!(speculator.fallback(), Some(reg::GYRO_XOUT_H));
}

/// Feeds reads starting at `starts` (one data byte each, `READ` set) to `speculator`, and
/// returns how many of them it predicted.
fn predicted(speculator: &mut Speculator, starts: &[u8]) -> usize {
    let mut right = 0;
    for &start in starts {
        right += usize::from(speculator.predict(DEFAULT_START) == start & 0x7F);
        speculator.observe(&Capture::from_bytes(&[start, 0, 0], &[0; 3], 0, None));
    }
    right
}

#[test]
fn speculator_learns_an_alternating_pair_and_keeps_it_through_odd_transactions() {
    let mut speculator = Speculator::new();
    let count = READ | reg::FIFO_COUNTH;
    let data = READ | reg::FIFO_R_W;
    // Missed while each has no successor yet (the first has no predecessor), then all right.
    assert_eq!(predicted(&mut speculator, &[count, data, count, data]), 1);
    assert_eq!(predicted(&mut speculator, &[count, data, count, data]), 4);
    // A register check after the data read is missed, so is the read after it (an unknown
    // predecessor), and the pair is still known.
    let check = READ | reg::CONFIG;
    assert_eq!(predicted(&mut speculator, &[check]), 0);
    assert_eq!(predicted(&mut speculator, &[count, data, count]), 2);
    assert_eq!(speculator.predict(DEFAULT_START), reg::FIFO_R_W);
    // The old rule alone never moves: the two starts alternate.
    assert_eq!(speculator.fallback(), None);
    // A new pattern replaces the old one after MAX_CONFIDENCE + 1 contradictions.
    let other = READ | reg::GYRO_XOUT_H;
    let right: [usize; 4] = core::array::from_fn(|_| predicted(&mut speculator, &[data, other]));
    assert_eq!(right, [1, 0, 1, 2]);
    assert_eq!(predicted(&mut speculator, &[data, other]), 2);
}

#[test]
fn speculator_is_bounded_and_deterministic() {
    let starts: [u8; 300] = core::array::from_fn(|i| READ | ((i * 37 + i / 7) % 128) as u8);
    let (mut a, mut b) = (Speculator::new(), Speculator::new());
    let right_a = predicted(&mut a, &starts);
    let right_b = predicted(&mut b, &starts);
    assert_eq!((right_a, a), (right_b, b));
    // Keys beyond SUCCESSORS push the least recently used out: a key seen SUCCESSORS + 1 keys
    // ago is forgotten, one seen just before is still known.
    let mut s = Speculator::new();
    let keys: [u8; SUCCESSORS + 1] = core::array::from_fn(|i| READ | (i as u8 + 1));
    let mut sequence = [0u8; 2 * (SUCCESSORS + 1)];
    for (pair, &key) in sequence.chunks_exact_mut(2).zip(&keys) {
        pair.copy_from_slice(&[key, READ | 0x70]);
    }
    predicted(&mut s, &sequence);
    predicted(&mut s, &[keys[0]]);
    assert_eq!(
        s.predict(DEFAULT_START),
        DEFAULT_START,
        "forgotten: the chip's start"
    );
    predicted(&mut s, &[keys[SUCCESSORS]]);
    assert_eq!(s.predict(DEFAULT_START), 0x70);
}

#[test]
fn fifo_count_and_fifo_data_are_served_exactly_when_predicted() {
    let mut chip = chip_with_sample();
    let mut setup =
        |mosi: &[u8]| replay(&mut chip, &Capture::from_bytes(mosi, &[0; 3], 0, None), 0);
    setup(&[reg::USER_CTRL, 0x40]); // FIFO_EN
    setup(&[reg::FIFO_EN, 0xF8]); // accel, temperature, gyro: 14 bytes a sample
    for k in 0..3u8 {
        chip.latch_image_at(&[0x20 + k; IMAGE_LEN], 2_000_000 + u64::from(k) * 1_000_000);
    }
    let mut shadow = Shadow::new();
    shadow.capture(&chip, reg::FIFO_COUNTH, 1);
    let count = [READ | reg::FIFO_COUNTH, 0, 0];
    let want = reference(&chip, &count);
    let (capture, miso) = transact(FAST, &mut shadow, &count);
    assert_eq!(&miso[..3], &want[..3]);
    assert_eq!(
        &miso[1..3],
        &[0, 42],
        "three samples of 14 bytes, FIFO_COUNTL latched"
    );
    assert_eq!(replay(&mut chip, &capture, 1), Outcome::Hit);
    shadow.capture(&chip, reg::FIFO_R_W, 1);
    let mut data = [0u8; 1 + 42];
    data[0] = READ | reg::FIFO_R_W;
    let want = reference(&chip, &data);
    let (capture, miso) = transact(FAST, &mut shadow, &data);
    assert_eq!(&miso[..43], &want[..43]);
    assert_eq!(
        (miso[1], miso[15], miso[29]),
        (0x20, 0x21, 0x22),
        "one record each"
    );
    assert_eq!(replay(&mut chip, &capture, 1), Outcome::Hit);
}

#[test]
fn sim_port_overlong_and_empty_transactions() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mut long = [0u8; STREAM_LEN + 50];
    long[0] = READ | DEFAULT_START;
    let (capture, _) = transact(FAST, &mut shadow, &long);
    assert!(capture.truncated());
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Truncated);
    let (capture, _) = transact(FAST, &mut shadow, &[]);
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Empty);
}

#[test]
fn speculator_tells_an_empty_count_from_a_full_one() {
    let mut s = Speculator::new();
    let read =
        |start: u8, data: u8| Capture::from_bytes(&[READ | start, 0, 0], &[0, 0, data], 0, None);
    let (count, empty, data) = (
        read(reg::FIFO_COUNTH, 14),
        read(reg::FIFO_COUNTH, 0),
        read(reg::FIFO_R_W, 0x5A),
    );
    // Polls: count then data, and now and then an empty count and nothing else.
    let polls = [
        &count, &data, &empty, &count, &data, &count, &data, &empty, &count, &data,
    ];
    let mut right = [false; 10];
    for (r, capture) in right.iter_mut().zip(polls.iter().cycle()) {
        let start = capture.mosi()[0] & 0x7F;
        *r = s.predict(DEFAULT_START) == start;
        s.observe(capture);
    }
    // Once each transaction has been seen before, every prediction is right: after an empty
    // count comes the next count, after a full one the data.
    assert_eq!(
        right,
        [false, false, false, false, true, true, true, true, true, true]
    );
}

#[test]
fn speculator_tells_reads_apart_by_length() {
    // A driver that got a wrong count reads far too much, then re-reads TEMP_OUT and resets
    // its FIFO; its normal polls read one record and go on with the next count. Keyed by the
    // start alone, the two successors of the FIFO read alternate and the recovery's wins half
    // the time, so the next count is missed, the driver gets a wrong count again, and so on.
    let mut s = Speculator::new();
    let read = |start: u8, len: usize| {
        let mosi = [READ | start; 200];
        Capture::from_bytes(&mosi[..len], &[0x5A; 200][..len], 0, None)
    };
    let (count, record, long, temp) = (
        read(reg::FIFO_COUNTH, 3),
        read(reg::FIFO_R_W, 15),
        read(reg::FIFO_R_W, 200),
        read(reg::TEMP_OUT_H, 3),
    );
    let polls = [
        &count, &long, &temp, &count, &record, &count, &record, &count,
    ];
    let mut right = [false; 8];
    for (r, capture) in right.iter_mut().zip(polls) {
        *r = s.predict(DEFAULT_START) == capture.mosi()[0] & 0x7F;
        s.observe(capture);
    }
    assert_eq!(right, [false, false, false, false, true, false, true, true]);
}

#[test]
fn speculator_tells_writes_apart_by_the_value_written() {
    // A bank select written before the sensor burst (bank 0) and before a bank-1 check.
    let mut s = Speculator::new();
    let bank = |b: u8| Capture::from_bytes(&[0x76, b], &[0, 0], 0, None);
    let burst = Capture::from_bytes(&[READ | 0x2D, 0, 0, 0], &[0, 1, 2, 3], 0, None);
    let check = Capture::from_bytes(&[READ | 0x0C, 0], &[0, 6], 0, None);
    let sequence = [&bank(1), &check, &bank(0), &burst];
    for capture in sequence.iter().chain(&sequence) {
        s.observe(capture);
    }
    s.observe(&bank(1));
    assert_eq!(s.predict(DEFAULT_START), 0x0C);
    s.observe(&check);
    s.observe(&bank(0));
    assert_eq!(s.predict(DEFAULT_START), 0x2D);
}

/// A chip with two register banks, for the shadow's sake only: REG_BANK_SEL at 0x76 in both
/// (its write is not plain), a FIFO port at bank 0's 0x30 that pops and does not increment, a
/// read-only count at bank 0's 0x2E; everything else stores what is written.
#[derive(Clone, Debug)]
struct Banked {
    regs: [[u8; 128]; 2],
    bank: usize,
    fifo: [u8; 64],
    head: usize,
    len: usize,
    phase: Option<(bool, u8)>,
    selected: bool,
    now_ns: u64,
}

impl Default for Banked {
    fn default() -> Self {
        Self {
            regs: [[0; 128]; 2],
            bank: 0,
            fifo: [0; 64],
            head: 0,
            len: 0,
            phase: None,
            selected: false,
            now_ns: 0,
        }
    }
}

const BANK_SEL: u8 = 0x76;
const FIFO_DATA: u8 = 0x30;
const FIFO_COUNT: u8 = 0x2E;

impl Banked {
    fn push(&mut self, byte: u8) {
        if self.len < self.fifo.len() {
            self.fifo[(self.head + self.len) % self.fifo.len()] = byte;
            self.len += 1;
        }
    }
    fn fifo_port(&self, addr: u8) -> bool {
        self.bank == 0 && addr == FIFO_DATA
    }
    fn commit_read(&mut self, addr: u8) {
        if self.fifo_port(addr) && self.len > 0 {
            self.head = (self.head + 1) % self.fifo.len();
            self.len -= 1;
        }
    }
    fn store(&mut self, addr: u8, value: u8) {
        match addr {
            BANK_SEL => self.bank = usize::from(value & 1),
            _ if self.bank == 0 && addr == FIFO_COUNT => {}
            _ if self.fifo_port(addr) => self.push(value),
            _ => self.regs[self.bank][usize::from(addr)] = value,
        }
    }
}

impl SpiTarget for Banked {
    fn select(&mut self) -> u8 {
        self.selected = true;
        self.phase = None;
        0
    }
    fn exchange(&mut self, mosi: u8) -> u8 {
        if !self.selected {
            return 0;
        }
        match self.phase {
            None => {
                let addr = mosi & 0x7F;
                self.phase = Some((mosi & 0x80 != 0, addr));
                if mosi & 0x80 != 0 {
                    self.spi_peek(addr)
                } else {
                    0
                }
            }
            Some((true, addr)) => {
                self.commit_read(addr);
                let next = self.spi_next_address(addr);
                self.phase = Some((true, next));
                self.spi_peek(next)
            }
            Some((false, addr)) => {
                self.store(addr, mosi);
                self.phase = Some((false, self.spi_next_address(addr)));
                0
            }
        }
    }
    fn deselect(&mut self) {
        self.selected = false;
    }
}

impl crate::chip::I2cTarget for Banked {
    fn start(&mut self, _address: u8, _read: bool) -> bool {
        false
    }
    fn write(&mut self, _byte: u8) -> bool {
        false
    }
    fn read(&mut self) -> u8 {
        0xFF
    }
    fn stop(&mut self) {}
}

impl Chip for Banked {
    fn model(&self) -> margemu_protocol::chip::ChipModel {
        margemu_protocol::chip::ChipModel::Mpu9250
    }
    fn settings(&self) -> margemu_protocol::chip::ChipSettings {
        EmulatedChip::default().settings()
    }
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        for &b in image {
            self.push(b);
        }
        self.now_ns = now_ns;
    }
    fn latch_at(&mut self, _sample: &crate::chip::PhysicalSample, now_ns: u64) {
        self.now_ns = now_ns;
    }
    fn advance(&mut self, now_ns: u64) {
        self.now_ns = now_ns;
    }
    fn now_ns(&self) -> u64 {
        self.now_ns
    }
    fn sample_period_ns(&self) -> u64 {
        1_000_000
    }
    fn int_pin_at(&self, _now_ns: u64) -> bool {
        false
    }
    fn int_open_drain(&self) -> bool {
        false
    }
    fn int_pulse_end_ns(&self) -> Option<u64> {
        None
    }
    fn pop_write(&mut self) -> Option<crate::chip::RegisterWrite> {
        None
    }
    fn writes_dropped(&self) -> u32 {
        0
    }
    fn write_register(&mut self, _file: u8, register: u8, value: u8) -> bool {
        self.store(register & 0x7F, value);
        true
    }
    fn i2c_address(&self) -> u8 {
        0x68
    }
    // A test double of the shadow's view of a banked chip: it models no faults.
    fn fault_reset(&mut self) -> bool {
        false
    }
    fn fault_identity(&mut self, _value: Option<u8>) -> bool {
        false
    }
    fn fault_fifo_overflow(&mut self, _on: bool) -> bool {
        false
    }
    fn spi_peek(&self, addr: u8) -> u8 {
        let addr = addr & 0x7F;
        match addr {
            BANK_SEL => self.bank as u8,
            _ if self.bank == 0 && addr == FIFO_COUNT => self.len as u8,
            _ if self.fifo_port(addr) => {
                if self.len > 0 {
                    self.fifo[self.head]
                } else {
                    0xFF
                }
            }
            _ => self.regs[self.bank][usize::from(addr)],
        }
    }
    fn spi_next_address(&self, addr: u8) -> u8 {
        if self.fifo_port(addr & 0x7F) {
            addr & 0x7F
        } else {
            (addr + 1) & 0x7F
        }
    }
    fn spi_plain_write(&self, addr: u8, value: u8) -> Option<u8> {
        let addr = addr & 0x7F;
        let special =
            addr == BANK_SEL || (self.bank == 0 && addr == FIFO_COUNT) || self.fifo_port(addr);
        (!special).then_some(value)
    }
    fn burst_start(&self) -> u8 {
        FIFO_COUNT
    }
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        crate::chip::spi_read_burst_on_copy(self, start, out);
    }
}

fn xfer(target: &mut impl SpiTarget, mosi: &[u8]) -> [u8; 64] {
    let mut miso = [0; 64];
    sim::transfer(target, mosi, &mut miso);
    miso
}

#[test]
fn a_banked_chip_is_served_through_the_boundary_alone() {
    let mut t = sim::ShadowTarget::new(Banked::default(), SLOW);
    // Setup at the slow clock: a register in bank 1, written and read back, then bank 0.
    xfer(&mut t, &[BANK_SEL, 1]);
    xfer(&mut t, &[0x10, 0x42]);
    assert_eq!(
        xfer(&mut t, &[READ | 0x10, 0])[1],
        0x42,
        "bank 1, after the recapture"
    );
    // A write burst through the bank select: the bytes after it go to bank 0 (replayed).
    xfer(&mut t, &[0x75, 0x11, 0, 0x33]);
    assert_eq!(xfer(&mut t, &[READ | 0x77, 0])[1], 0x33);
    assert_eq!(
        xfer(&mut t, &[READ | 0x10, 0])[1],
        0x00,
        "bank 0's own 0x10"
    );
    assert_eq!(t.stats().misses, 0);
    // The sampling loop at the fast clock: count, then that many FIFO bytes.
    t.set_timing(FAST);
    t.reset_stats();
    for k in 0..500u32 {
        let n = 4 + (k % 3) as usize;
        let record: [u8; 6] =
            core::array::from_fn(|i| (k as u8).wrapping_mul(7).wrapping_add(i as u8));
        t.chip_mut()
            .latch_image_at(&record[..n], u64::from(k) * 1_000_000);
        let count = xfer(&mut t, &[READ | FIFO_COUNT, 0])[1];
        assert_eq!(usize::from(count), n);
        let mut mosi = [0u8; 7];
        mosi[0] = READ | FIFO_DATA;
        let got = xfer(&mut t, &mosi[..=n]);
        if k > 0 {
            assert_eq!(&got[1..=n], &record[..n], "sample {k}");
        }
    }
    let stats = t.stats();
    assert_eq!(t.divergences(), 0);
    // The count is the chip's burst start; only the first FIFO read (no successor yet) misses.
    assert_eq!((stats.reads(), stats.misses), (1000, 1), "{stats:?}");
}
