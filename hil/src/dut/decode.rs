//! What a decoder makes of the device's bytes ([`Decoded`]), and the stream framer both wire
//! formats share ([`Framer`]).
//!
//! The framer keeps the bytes it has not settled yet. At every start byte of its format it asks
//! the format about the candidate frame there: too short yet (wait for more bytes), rejected
//! (a bad header, an unknown message id, a failed checksum: skip that one byte and scan on, so a
//! real frame hidden behind a false start is never lost), or a frame of `n` bytes (decoded, and
//! skipped whole). The outcome therefore does not depend on how the bytes were split into reads.
//! Every byte that ends up outside an accepted frame counts as a bad byte.

use super::frames::Attitude;
use std::borrow::Cow;

/// The wire format and version of one decoded message (the `protocol` column of the CSVs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Wire {
    /// MAVLink 1 (start byte 0xFE).
    Mavlink1,
    /// MAVLink 2 (start byte 0xFD).
    Mavlink2,
    /// MSP v1 (`$M`).
    Msp1,
    /// MSP v2 (`$X`).
    Msp2,
}

impl Wire {
    /// The name written in the `protocol` column: `mavlink1`, `mavlink2`, `msp1`, `msp2`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mavlink1 => "mavlink1",
            Self::Mavlink2 => "mavlink2",
            Self::Msp1 => "msp1",
            Self::Msp2 => "msp2",
        }
    }
}

/// One message as `dut_messages.csv` records it.
#[derive(Clone, Debug, PartialEq)]
pub struct MessageInfo {
    /// Wire format and version.
    pub wire: Wire,
    /// The message's name (`ATTITUDE`, `MSP_ATTITUDE`, …; see the module docs).
    pub name: Cow<'static, str>,
    /// MAVLink sender system id (`None` for MSP).
    pub sys_id: Option<u32>,
    /// MAVLink sender component id (`None` for MSP).
    pub comp_id: Option<u8>,
    /// MAVLink packet sequence number (`None` for MSP).
    pub seq: Option<u8>,
    /// Payload length on the wire, bytes.
    pub length: usize,
}

/// An attitude estimate of the device, in margemu's conventions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeSample {
    /// The device's own time stamp, µs (`None` when the message has none).
    pub device_time_us: Option<u64>,
    /// The attitude.
    pub attitude: Attitude,
}

/// An IMU reading of the device, in margemu's body frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample {
    /// The device's own time stamp, µs (`None` when the message has none).
    pub device_time_us: Option<u64>,
    /// Accelerometer (m/s², or raw counts for `MSP_RAW_IMU`).
    pub accel: [f64; 3],
    /// Gyroscope (rad/s, or raw counts for `MSP_RAW_IMU`).
    pub gyro: [f64; 3],
    /// Magnetometer (µT, or raw counts for `MSP_RAW_IMU`).
    pub mag: [f64; 3],
}

/// What one message carried besides its identity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    /// An attitude (`dut_attitude.csv`).
    Attitude(AttitudeSample),
    /// An IMU reading (`dut_imu.csv`).
    Imu(ImuSample),
}

/// One decoded message.
#[derive(Clone, Debug, PartialEq)]
pub struct Decoded {
    /// Its identity (`dut_messages.csv`).
    pub message: MessageInfo,
    /// Its attitude or IMU content, for the messages margemu evaluates.
    pub sample: Option<Sample>,
}

/// Byte and frame counters of one stream.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DecodeCounters {
    /// Bytes received.
    pub bytes: u64,
    /// Bytes outside every accepted frame (garbage, damaged frames, unknown messages).
    pub bad_bytes: u64,
    /// Candidate frames whose checksum failed.
    pub bad_frames: u64,
    /// MAVLink candidates with a message id outside the common dialect (their CRC cannot be
    /// checked without the id's CRC_EXTRA, so their bytes count as bad bytes).
    pub unknown_ids: u64,
    /// Intact frames whose payload could not be decoded (logged in `dut_messages.csv` only).
    pub undecoded: u64,
}

/// Why a candidate frame was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reject {
    /// Not a header of this format.
    Header,
    /// A message id the decoder does not know.
    UnknownId,
    /// The checksum failed.
    Checksum,
}

/// The verdict on the candidate frame at a start byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Candidate {
    /// More bytes are needed to decide.
    Incomplete,
    /// Not a frame: skip its first byte.
    Reject(Reject),
    /// A frame of this many bytes, already decoded into the output.
    Frame(usize),
}

/// One wire format, as the framer sees it.
pub trait FrameFormat {
    /// Whether a frame can start with `byte`.
    fn is_start(byte: u8) -> bool;
    /// Judges the candidate at the start of `bytes` (which begins with a start byte); on
    /// [`Candidate::Frame`], pushes what it decoded onto `out` (and counts undecodable payloads
    /// in `counters`).
    fn candidate(
        &mut self,
        bytes: &[u8],
        counters: &mut DecodeCounters,
        out: &mut Vec<Decoded>,
    ) -> Candidate;
}

/// Finds the frames of format `F` in a byte stream that arrives in arbitrary pieces.
#[derive(Debug, Default)]
pub struct Framer<F> {
    format: F,
    pending: Vec<u8>,
    counters: DecodeCounters,
}

impl<F: FrameFormat> Framer<F> {
    /// A framer of `format` with nothing pending.
    pub fn with_format(format: F) -> Self {
        Self {
            format,
            pending: Vec::new(),
            counters: DecodeCounters::default(),
        }
    }

    /// Feeds received bytes; pushes every message they complete onto `out`, in order.
    pub fn feed(&mut self, input: &[u8], out: &mut Vec<Decoded>) {
        self.counters.bytes += input.len() as u64;
        self.pending.extend_from_slice(input);
        self.scan(false, out);
    }

    /// The stream has ended: a frame still incomplete is not one, so its bytes are scanned
    /// again for frames behind a false start, and what remains counts as bad bytes.
    pub fn finish(&mut self, out: &mut Vec<Decoded>) {
        self.scan(true, out);
    }

    /// The counters so far.
    pub fn counters(&self) -> DecodeCounters {
        self.counters
    }

    fn scan(&mut self, at_end: bool, out: &mut Vec<Decoded>) {
        let mut i = 0;
        while i < self.pending.len() {
            let Some(skip) = self.pending[i..].iter().position(|&b| F::is_start(b)) else {
                self.counters.bad_bytes += (self.pending.len() - i) as u64;
                i = self.pending.len();
                break;
            };
            self.counters.bad_bytes += skip as u64;
            i += skip;
            let verdict = self
                .format
                .candidate(&self.pending[i..], &mut self.counters, out);
            match verdict {
                Candidate::Incomplete if !at_end => break,
                Candidate::Frame(len) => i += len,
                Candidate::Incomplete | Candidate::Reject(_) => {
                    match verdict {
                        Candidate::Reject(Reject::Checksum) => self.counters.bad_frames += 1,
                        Candidate::Reject(Reject::UnknownId) => self.counters.unknown_ids += 1,
                        _ => {}
                    }
                    self.counters.bad_bytes += 1;
                    i += 1;
                }
            }
        }
        self.pending.drain(..i);
    }
}

/// A decoder of either wire format, as the reader thread uses it.
pub trait StreamDecoder: Send {
    /// Feeds received bytes; pushes every message they complete onto `out`, in order.
    fn feed(&mut self, input: &[u8], out: &mut Vec<Decoded>);
    /// The stream has ended; settles the bytes still pending.
    fn finish(&mut self, out: &mut Vec<Decoded>);
    /// The counters so far.
    fn counters(&self) -> DecodeCounters;
}

impl<F: FrameFormat + Send> StreamDecoder for Framer<F> {
    fn feed(&mut self, input: &[u8], out: &mut Vec<Decoded>) {
        Framer::feed(self, input, out);
    }
    fn finish(&mut self, out: &mut Vec<Decoded>) {
        Framer::finish(self, out);
    }
    fn counters(&self) -> DecodeCounters {
        Framer::counters(self)
    }
}
