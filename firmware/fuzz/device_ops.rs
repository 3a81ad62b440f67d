//! One fuzz input drives the firmware's link handler ([`Device`]) through everything a host
//! link and a device under test can do to it, and checks what must hold whatever they do.
//!
//! The input is read as a sequence of operations (the first byte of each picks it):
//!
//! | op | what |
//! |---|---|
//! | raw bytes | `n` arbitrary bytes fed in one call (frames cut anywhere, garbage, delimiters) |
//! | raw frame | a correctly framed and CRC'd frame of any kind byte, sequence number and payload |
//! | Hello | a Hello of this protocol version, or of another |
//! | Configure | any chip model code, identity, image length, I2C address and rate, images source |
//! | Start | `t0` and `end_index` (until Stop, or a scene end) |
//! | Stop | |
//! | images | a batch of images of the input's length from any first index |
//! | AddFault | a fault of any kind (valid parameters, or any bytes after a valid header) on any device, with any window |
//! | clock | the device clock jumps forward by any amount up to ~2⁶⁰ ns, or back by up to 1 s |
//! | poll | the device serves what is due and sends what it has |
//! | SPI | a burst read or a write of any register through the chip's SPI target, maybe left selected |
//! | I2C | a transaction at any address: register write, then reads, maybe without a stop |
//!
//! Invariants, asserted (a failure is a bug): nothing panics; every frame the device sends is
//! delimited, intact (CRC) and parses as a device → host message; the buffer never holds more
//! than its capacity; polls, clock jumps and bus transactions never lower the served and receive
//! counters (only a Hello resets them); a good Hello is answered whatever came before.
//!
//! Shared by the libFuzzer target (`fuzz_targets/device.rs`) and the firmware's property test
//! (`firmware/tests/link/fuzz_device.rs`), which runs it on every `cargo test`.

use margemu_firmware::chip::{I2cTarget, SpiTarget};
use margemu_firmware::link::Device;
use margemu_firmware::model::fault::{Fault, FaultKind, Sensor, Window};
use margemu_protocol::chip::{ChipModel, Image};
use margemu_protocol::link::{
    stuff, Accumulator, AddFault, Configure, FeedResult, Frame, FrameRepr, Hello, ImageBatch, Kind,
    Message, Rate, Start, CRC_LEN, FRAME_VERSION, HEADER_LEN, MAX_FRAME_LEN, MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;

/// Samples the fuzzed device buffers: small, so that overruns and wrap-around are reached.
pub const CAPACITY: usize = 16;

/// Reads the fuzz input front to back; past its end every read is zero.
struct Input<'a>(&'a [u8]);

impl<'a> Input<'a> {
    fn u8(&mut self) -> u8 {
        let (&b, rest) = self.0.split_first().unwrap_or((&0, &[]));
        self.0 = rest;
        b
    }

    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    fn u64(&mut self) -> u64 {
        u64::from(self.u32()) | (u64::from(self.u32()) << 32)
    }

    fn bytes(&mut self, n: usize) -> &'a [u8] {
        let (head, rest) = self.0.split_at(n.min(self.0.len()));
        self.0 = rest;
        head
    }

    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// The device, its clock and the host's sequence number.
struct Harness {
    device: Box<Device<CAPACITY>>,
    now_ns: u64,
    host_seq: u16,
}

/// The operations, as picked by their first byte.
#[derive(Clone, Copy, Debug)]
enum Op {
    RawBytes,
    RawFrame,
    Hello,
    Configure,
    Start,
    Stop,
    Images,
    Clock,
    Poll,
    Spi,
    I2c,
    AddFault,
}

impl Op {
    const ALL: [Op; 12] = [
        Op::RawBytes,
        Op::RawFrame,
        Op::Hello,
        Op::Configure,
        Op::Start,
        Op::Stop,
        Op::Images,
        Op::Clock,
        Op::Poll,
        Op::Spi,
        Op::I2c,
        Op::AddFault,
    ];

    /// Whether it feeds bytes to the device (which may hold a Hello, resetting its counters).
    fn feeds(self) -> bool {
        !matches!(self, Op::Clock | Op::Poll | Op::Spi | Op::I2c)
    }
}

/// Runs the operations encoded in `data` (see the module docs); returns the instants the device
/// counted as served in its last session.
pub fn run(data: &[u8]) -> u64 {
    let mut input = Input(data);
    let mut h = Harness {
        device: Box::default(),
        now_ns: 0,
        host_seq: 0,
    };
    while !input.is_empty() {
        let before = h.totals();
        let op = h.step(&mut input);
        assert!(h.device.buffer_level() <= CAPACITY, "buffer over capacity");
        // Only a Hello resets the counters; operations that feed no bytes never lower them.
        if !op.feeds() {
            let after = h.totals();
            assert!(
                after.0 >= before.0 && after.1 >= before.1,
                "{op:?}: counters went back"
            );
        }
    }
    let served = h.device.counters().served;
    // Whatever came before, the device still answers a good Hello.
    h.send(&Message::Hello(Hello {
        protocol_version: PROTOCOL_VERSION,
        session: 0x5eed,
    }));
    let out = h.poll();
    assert!(
        out.contains(&"HelloAck"),
        "no HelloAck after a good Hello: {out:?}"
    );
    served
}

impl Harness {
    fn step(&mut self, input: &mut Input<'_>) -> Op {
        let op = Op::ALL[usize::from(input.u8()) % Op::ALL.len()];
        match op {
            Op::RawBytes => {
                let n = usize::from(input.u8());
                let bytes = input.bytes(n);
                self.device.feed(bytes, self.now_ns);
            }
            Op::RawFrame => {
                let (kind, seq, len) = (input.u8(), input.u16(), input.u16());
                let payload = input.bytes(usize::from(len));
                self.raw_frame(kind, seq, payload);
            }
            Op::Hello => {
                let version = if input.u8() < 0xF0 {
                    PROTOCOL_VERSION
                } else {
                    input.u16()
                };
                let session = input.u32();
                self.send(&Message::Hello(Hello {
                    protocol_version: version,
                    session,
                }));
            }
            Op::Configure => self.configure(input),
            Op::Start => {
                let (t0, end) = (input.u64() >> input.u8().min(63), input.u32());
                let start = match end {
                    0 => Start::until_stop(t0),
                    n => Start::scene(t0, u64::from(n % 100_000)),
                };
                self.send(&Message::Start(start));
            }
            Op::Stop => self.send(&Message::Stop),
            Op::Images => {
                let (first, count, len) = (input.u64() % 4096, input.u8() % 40, input.u8() % 33);
                let images: Vec<Image> = (0..count)
                    .filter_map(|_| Image::new(input.bytes(usize::from(len))))
                    .collect();
                self.send(&Message::Images(ImageBatch::new(first, &images)));
            }
            Op::Clock => {
                let step = input.u32();
                if step % 16 == 15 {
                    self.now_ns = self.now_ns.saturating_sub(u64::from(step) % 1_000_000_000);
                } else {
                    let shift = input.u8() % 29;
                    self.now_ns = self.now_ns.saturating_add(u64::from(step) << shift);
                }
            }
            Op::AddFault => self.add_fault(input),
            Op::Poll => {
                self.poll();
            }
            Op::Spi => self.spi(input),
            Op::I2c => self.i2c(input),
        }
        op
    }

    /// An AddFault: half the time a valid message of any kind with fuzzed parameters, else a
    /// valid header (device, seed, window, kind code up to one past the last) followed by any
    /// bytes, so the parser's refusals are reached too.
    fn add_fault(&mut self, input: &mut Input<'_>) {
        let device = input.u8() % 4;
        let seed = input.u64();
        let start_ns = input.u64() % 10_000_000_000;
        let end_ns = start_ns.saturating_add(u64::from(input.u32()));
        if input.u8() & 1 == 0 {
            let f = |input: &mut Input<'_>| f32::from_bits(input.u32());
            let sensor = [Sensor::Acc, Sensor::Gyr, Sensor::Mag][usize::from(input.u8() % 3)];
            let kind = match input.u8() % 18 {
                0 => FaultKind::Stuck { sensor },
                1 => FaultKind::StuckAt {
                    sensor,
                    value: [f(input), f(input), f(input)],
                },
                2 => FaultKind::Dropout { sensor },
                3 => FaultKind::Spikes {
                    sensor,
                    rate_hz: f(input),
                    amplitude: f(input),
                    axes: input.u8() & 7,
                },
                4 => FaultKind::BiasStep {
                    sensor,
                    bias: [f(input), f(input), f(input)],
                },
                5 => FaultKind::Scale {
                    sensor,
                    factor: [f(input), f(input), f(input)],
                },
                6 => FaultKind::Noise {
                    sensor,
                    std: [f(input), f(input), f(input)],
                },
                7 => FaultKind::MagSaturation {
                    field: [f(input), f(input), f(input)],
                },
                8 => FaultKind::Reset,
                9 => FaultKind::WrongIdentity { value: input.u8() },
                10 => FaultKind::FifoOverflow,
                11 => FaultKind::Nak,
                12 => FaultKind::Corrupt {
                    probability: f(input),
                },
                13 => FaultKind::ClockStretch {
                    stretch_ns: input.u32(),
                },
                14 => FaultKind::ClockOffset {
                    ppm: f(input),
                    drift_ppm_per_s: f(input),
                },
                15 => FaultKind::DrdyJitter {
                    max_ns: input.u32(),
                },
                16 => FaultKind::MissingDrdy {
                    probability: f(input),
                },
                _ => FaultKind::Late {
                    delay_ns: input.u32(),
                },
            };
            let fault = Fault::new(device, Window::new(start_ns, end_ns), kind);
            self.send(&Message::AddFault(AddFault { fault, seed }));
        } else {
            let mut payload = Vec::with_capacity(64);
            payload.push(device);
            payload.extend_from_slice(&seed.to_le_bytes());
            payload.extend_from_slice(&start_ns.to_le_bytes());
            payload.extend_from_slice(&end_ns.to_le_bytes());
            payload.push(input.u8() % 19);
            let n = usize::from(input.u8() % 48);
            payload.extend_from_slice(input.bytes(n));
            let seq = self.host_seq;
            self.raw_frame(Kind::AddFault as u8, seq, &payload);
        }
    }

    fn configure(&mut self, input: &mut Input<'_>) {
        let code = input.u8() % 8;
        let model = ChipModel::from_code(code).unwrap_or(ChipModel::Mpu9250);
        let mut cfg = Configure::new(model, Rate::hz(1000).unwrap_or_else(|| unreachable!()));
        if let Some(rate) = Rate::new(input.u32() % 40_000 + 1, input.u8() as u32 % 8 + 1) {
            cfg.rate = rate;
        }
        match input.u8() % 4 {
            0 => {}
            1 => cfg.who_am_i = input.u8(),
            2 => cfg.image_len = input.u8(),
            _ => cfg.i2c_address = input.u8(),
        }
        cfg.telemetry_period_ns = u64::from(input.u16()) * 1000;
        if ChipModel::from_code(code).is_some() {
            self.send(&Message::Configure(cfg));
        } else {
            // A chip code this version does not know: the same Configure with the code patched.
            let mut buf = [0u8; MAX_FRAME_LEN];
            let Ok(n) = margemu_protocol::link::emit_frame(
                self.host_seq,
                &Message::Configure(cfg),
                &mut buf,
            ) else {
                return;
            };
            let mut frame = Frame::new_unchecked(&mut buf[..n]);
            if let Some(b) = frame.payload_mut().first_mut() {
                *b = code;
            }
            frame.fill_crc();
            self.host_seq = self.host_seq.wrapping_add(1);
            self.feed_frame(&buf[..n]);
        }
    }

    fn spi(&mut self, input: &mut Input<'_>) {
        let (first, n, deselect) = (input.u8(), input.u8() % 40, !input.u8().is_multiple_of(8));
        let chip = self.device.chip_mut();
        chip.select();
        chip.exchange(first);
        for _ in 0..n {
            let mosi = input.u8();
            chip.exchange(mosi);
        }
        if deselect {
            chip.deselect();
        }
    }

    fn i2c(&mut self, input: &mut Input<'_>) {
        let (address, register, reads, stop) = (
            input.u8() & 0x7F,
            input.u8(),
            input.u8() % 40,
            !input.u8().is_multiple_of(8),
        );
        let write = input.u8().is_multiple_of(2);
        let value = input.u8();
        let chip = self.device.chip_mut();
        if chip.start(address, false) {
            chip.write(register);
            if write {
                chip.write(value);
            }
        }
        if reads > 0 && chip.start(address, true) {
            for _ in 0..reads {
                chip.read();
            }
        }
        if stop {
            chip.stop();
        }
    }

    /// A frame of any kind byte and payload, framed and CRC'd correctly.
    fn raw_frame(&mut self, kind: u8, seq: u16, payload: &[u8]) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = payload.len().min(MAX_FRAME_LEN - HEADER_LEN - CRC_LEN);
        let total = HEADER_LEN + len + CRC_LEN;
        let mut frame = Frame::new_unchecked(&mut buf[..total]);
        frame.set_version(FRAME_VERSION);
        frame.set_kind(kind);
        frame.set_seq(seq);
        frame.set_payload_len(len as u16);
        frame.payload_mut().copy_from_slice(&payload[..len]);
        frame.fill_crc();
        self.feed_frame(&buf[..total]);
    }

    fn send(&mut self, message: &Message<'_>) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        if let Ok(n) = margemu_protocol::link::emit_frame(self.host_seq, message, &mut buf) {
            self.host_seq = self.host_seq.wrapping_add(1);
            self.feed_frame(&buf[..n]);
        }
    }

    fn feed_frame(&mut self, frame: &[u8]) {
        let mut wire = [0u8; MAX_WIRE_LEN];
        if let Ok(w) = stuff(frame, &mut wire) {
            self.device.feed(&wire[..w], self.now_ns);
        }
    }

    /// Polls once; every frame sent must be intact and a device → host message (returned by
    /// name).
    fn poll(&mut self) -> Vec<&'static str> {
        let mut names = Vec::new();
        self.device.poll(self.now_ns, &mut |wire: &[u8]| {
            assert_eq!(
                (wire.first(), wire.last()),
                (Some(&0), Some(&0)),
                "frame not delimited"
            );
            let mut acc = Accumulator::new();
            let mut rest = wire;
            while !rest.is_empty() {
                let r = acc.feed(rest);
                match &r {
                    FeedResult::Consumed => break,
                    FeedResult::Success { frame, .. } => {
                        let repr = FrameRepr::parse(frame).expect("the device's frame parses");
                        names.push(device_message(&repr.message));
                    }
                    damaged => panic!("the device sent a damaged frame: {damaged:?}"),
                }
                rest = r.remaining();
            }
        });
        names
    }

    /// Instants served, and damaged, lost or rejected frames.
    fn totals(&self) -> (u64, u64) {
        let c = self.device.counters();
        let rx = c.rx;
        let rx = [
            rx.crc_errors,
            rx.framing_errors,
            rx.lost_frames,
            rx.rejected_messages,
        ];
        (c.served, rx.iter().map(|&n| u64::from(n)).sum())
    }
}

/// The name of a device → host message; panics on a host → device one.
fn device_message(m: &Message<'_>) -> &'static str {
    match m {
        Message::HelloAck(_) => "HelloAck",
        Message::Credit(_) => "Credit",
        Message::Telemetry(_) => "Telemetry",
        Message::RegisterWrites(_) => "RegisterWrites",
        Message::Reset(_) => "Reset",
        Message::Error(_) => "Error",
        Message::Served(_) => "Served",
        other => panic!("the device sent a host → device message: {other:?}"),
    }
}
