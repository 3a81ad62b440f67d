//! Host-side helpers: encode messages, collect and decode the device's frames, read the chip.

pub use margemu_firmware::chip::EmulatedChip;
use margemu_firmware::chip::SpiTarget;
use margemu_firmware::link::Device;
pub use margemu_protocol::chip::ChipModel;
use margemu_protocol::chip::ChipSettings;
pub use margemu_protocol::link::Image;
use margemu_protocol::link::{
    Accumulator, Configure, Credit, Encoder, ErrorCode, ErrorReport, FeedResult, FrameRepr,
    HelloAck, ImageBatch, Message, Rate, RegisterOverride, RegisterWrite, ResetCause, ServedSample,
    Start, Telemetry, MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;

pub const CAP: usize = 64;
pub type Dev = Device<CAP>;

/// A device → host message, owned.
#[derive(Clone, Debug, PartialEq)]
pub enum Out {
    Reset(ResetCause),
    HelloAck(HelloAck),
    Credit(Credit),
    Telemetry(Telemetry),
    Writes(u32, Vec<RegisterWrite>),
    Error(ErrorReport),
    Served(u64, u64, Vec<ServedSample>),
}

pub struct Host {
    pub enc: Encoder,
}

impl Host {
    pub fn new() -> Self {
        Self {
            enc: Encoder::new(),
        }
    }

    pub fn wire(&mut self, m: &Message<'_>) -> Vec<u8> {
        let mut buf = [0u8; MAX_WIRE_LEN];
        let n = self.enc.encode(m, &mut buf).unwrap();
        buf[..n].to_vec()
    }

    pub fn send(&mut self, dev: &mut Dev, m: &Message<'_>, now_ns: u64) {
        let bytes = self.wire(m);
        dev.feed(&bytes, now_ns);
    }

    /// Sends `m` with its payload changed by `patch` (the CRC recomputed): a well-framed
    /// message whose content this version may not parse.
    pub fn send_patched(&mut self, dev: &mut Dev, m: &Message<'_>, patch: impl FnOnce(&mut [u8])) {
        use margemu_protocol::link::{emit_frame, stuff, Frame, MAX_FRAME_LEN};
        let mut frame = [0u8; MAX_FRAME_LEN];
        let n = emit_frame(0, m, &mut frame).unwrap();
        let mut f = Frame::new_unchecked(&mut frame[..n]);
        patch(f.payload_mut());
        f.fill_crc();
        let mut wire = [0u8; MAX_WIRE_LEN];
        let w = stuff(&frame[..n], &mut wire).unwrap();
        dev.feed(&wire[..w], 0);
    }

    pub fn hello(&mut self, dev: &mut Dev, session: u32) {
        let hello = margemu_protocol::link::Hello {
            protocol_version: PROTOCOL_VERSION,
            session,
        };
        self.send(dev, &Message::Hello(hello), 0);
    }

    pub fn configure(&mut self, dev: &mut Dev, cfg: Configure) {
        self.send(dev, &Message::Configure(cfg), 0);
    }

    pub fn images(&mut self, dev: &mut Dev, first: u64, images: &[Image], now_ns: u64) {
        for (i, chunk) in images.chunks(16).enumerate() {
            let batch = ImageBatch::new(first + 16 * i as u64, chunk);
            self.send(dev, &Message::Images(batch), now_ns);
        }
    }

    pub fn start(&mut self, dev: &mut Dev, t0_ns: u64, now_ns: u64) {
        self.send(dev, &Message::Start(Start::until_stop(t0_ns)), now_ns);
    }

    /// Start of a scene of `samples` output samples: the device stops by itself at its end.
    pub fn start_scene(&mut self, dev: &mut Dev, samples: u64, now_ns: u64) {
        self.send(dev, &Message::Start(Start::scene(0, samples)), now_ns);
    }
}

/// Polls once and decodes every frame the device sent.
pub fn poll(dev: &mut Dev, now_ns: u64) -> Vec<Out> {
    let mut bytes = Vec::new();
    dev.poll(now_ns, &mut |frame: &[u8]| {
        assert_eq!((frame.first(), frame.last()), (Some(&0), Some(&0)));
        bytes.extend_from_slice(frame);
    });
    decode(&bytes)
}

pub fn decode(mut bytes: &[u8]) -> Vec<Out> {
    let mut acc = Accumulator::new();
    let mut out = Vec::new();
    while !bytes.is_empty() {
        let r = acc.feed(bytes);
        match &r {
            FeedResult::Consumed => break,
            FeedResult::Success { frame, .. } => {
                let repr = FrameRepr::parse(frame).unwrap();
                out.push(match repr.message {
                    Message::Reset(r) => Out::Reset(r.cause),
                    Message::HelloAck(a) => Out::HelloAck(a),
                    Message::Credit(c) => Out::Credit(c),
                    Message::Telemetry(t) => Out::Telemetry(t),
                    Message::RegisterWrites(w) => Out::Writes(w.dropped, w.writes.iter().collect()),
                    Message::Error(e) => Out::Error(e),
                    Message::Served(b) => {
                        Out::Served(b.first_index, b.first_time_ns, b.samples.iter().collect())
                    }
                    other => panic!("host-bound message expected, got {other:?}"),
                });
            }
            damaged => panic!("device sent a damaged frame: {damaged:?}"),
        }
        bytes = r.remaining();
    }
    out
}

/// `(index, underrun)` of every instant the device reported serving in `out`.
pub fn underrun_flags(out: &[Out]) -> Vec<(u64, bool)> {
    served(out).iter().map(|(k, s)| (*k, s.underrun)).collect()
}

pub fn telemetry(out: &[Out]) -> Option<Telemetry> {
    out.iter().rev().find_map(|o| match o {
        Out::Telemetry(t) => Some(*t),
        _ => None,
    })
}

pub fn credits(out: &[Out]) -> Vec<Credit> {
    out.iter()
        .filter_map(|o| match o {
            Out::Credit(c) => Some(*c),
            _ => None,
        })
        .collect()
}

/// Every Served entry, as (index, time, entry), checking that times follow the 1 kHz rate.
pub fn served(out: &[Out]) -> Vec<(u64, ServedSample)> {
    let mut all = Vec::new();
    for o in out {
        if let Out::Served(first, time, samples) = o {
            assert_eq!(*time, first * MS);
            all.extend((*first..).zip(samples.iter().copied()));
        }
    }
    all
}

/// The Served entry of a sample that was latched from `image`.
pub fn served_entry(image: &Image, underrun: bool) -> ServedSample {
    ServedSample {
        crc32c: margemu_protocol::link::CRC32C.checksum(image),
        underrun,
        empty: false,
    }
}

/// Burst read of ACCEL_XOUT_H..=GYRO_ZOUT_L (0x3B..=0x48) over the chip's SPI target.
pub fn burst_sensors(dev: &mut Dev) -> [u8; 14] {
    let chip = dev.chip_mut();
    let mut out = [0u8; 14];
    chip.select();
    out[0] = chip.exchange(0x80 | 0x3B);
    for slot in out.iter_mut().skip(1) {
        *slot = chip.exchange(0x00);
    }
    chip.deselect();
    out
}

/// A distinct, non-trivial image for sample `i`.
pub fn image(i: u64) -> Image {
    let mut im = [0u8; 22];
    for (b, byte) in im.iter_mut().enumerate() {
        *byte = (i.wrapping_mul(31).wrapping_add(b as u64 * 7) & 0xFF) as u8;
    }
    im[21] &= 0x18; // ST2: only HOFL and BITM are meaningful
    Image::from(im)
}

pub fn images(first: u64, n: usize) -> Vec<Image> {
    (first..first + n as u64).map(image).collect()
}

pub const MS: u64 = 1_000_000;

pub fn rate_1khz() -> Rate {
    Rate::hz(1000).unwrap()
}

/// A device after Hello and a 1 kHz images Configure, with its output drained.
pub fn configured() -> (Dev, Host) {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, Configure::new(ChipModel::Mpu9250, rate_1khz()));
    poll(&mut dev, 0);
    (dev, host)
}

/// The `(code, detail)` of every Error in `out`.
pub fn errors(out: &[Out]) -> Vec<(ErrorCode, u32)> {
    out.iter()
        .filter_map(|o| match o {
            Out::Error(e) => Some((e.code, e.detail)),
            _ => None,
        })
        .collect()
}

/// The Configure of `settings`' model at `rate_hz` with its `config_writes` as overrides.
pub fn configure_with(settings: &ChipSettings, rate_hz: u32) -> Configure {
    let mut cfg = Configure::new(settings.model, Rate::hz(rate_hz).unwrap());
    for (file, register, value) in settings.config_writes(f64::from(rate_hz)) {
        let o = RegisterOverride {
            file,
            register,
            value,
        };
        cfg.overrides.push(o).unwrap();
    }
    cfg
}
