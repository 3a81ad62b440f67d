//! MSP (MultiWii Serial Protocol) v1 and v2 from the device, and the requests that poll it.
//!
//! Frames (little-endian):
//!
//! - v1: `'$' 'M' dir len:u8 cmd:u8 payload[len] xor`, `xor` the XOR of `len`, `cmd` and the
//!   payload;
//! - v2: `'$' 'X' dir flag:u8 cmd:u16 len:u16 payload[len] crc8`, `crc8` the CRC-8/DVB-S2
//!   (polynomial 0xD5) of `flag` through the payload.
//!
//! `dir` is `'<'` (to the board: a request), `'>'` (from the board: a reply) or `'!'` (the board's
//! error reply, e.g. for an unsupported command). margemu writes its own small parser on the
//! shared [`Framer`] (a false `'$'` never hides a frame behind it); the crates on crates.io
//! re-synchronise only at the byte after a failed frame and were last released in 2020
//! (`multiwii_serial_protocol_v2`, whose encoder the tests use as an independent reference).
//! v1 "jumbo" frames (`len` = 255) and MSPv2-in-v1 encapsulation are not decoded; a v2 payload
//! longer than [`MAX_PAYLOAD`] bytes is taken for a false start.
//!
//! Replies decoded into samples (units as Betaflight and INAV send them):
//!
//! | command | payload | becomes |
//! |---|---|---|
//! | `MSP_ATTITUDE` (108) | roll i16 (0.1°), pitch i16 (0.1°), yaw i16 (heading, whole degrees 0..359) | an attitude via [`from_msp`] |
//! | `MSP_RAW_IMU` (102) | acc, gyro, mag: 3 × i16 each | an IMU row of **raw counts**, written unscaled and unrotated |
//!
//! `MSP_RAW_IMU`'s units depend on the firmware: Betaflight sends the accelerometer in its ADC
//! counts (`acc_1G` per g, 2048 for most ±16 g sensors), INAV in 1/512 g; both send the gyro in
//! °/s and the magnetometer in the sensor's raw counts. Their axes are the firmware's body axes
//! (forward, left, up for Betaflight: margemu's).

use super::decode::{
    AttitudeSample, Candidate, DecodeCounters, Decoded, FrameFormat, Framer, ImuSample,
    MessageInfo, Reject, Sample, Wire,
};
use super::frames::from_msp;
use std::borrow::Cow;

/// `MSP_RAW_IMU`.
pub const MSP_RAW_IMU: u16 = 102;
/// `MSP_ATTITUDE`.
pub const MSP_ATTITUDE: u16 = 108;
/// The longest MSP v2 payload taken for real, bytes.
pub const MAX_PAYLOAD: usize = 4096;

const CRC8_DVB_S2: crc::Crc<u8> = crc::Crc::<u8>::new(&crc::CRC_8_DVB_S2);

/// Which MSP version the poll requests use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MspVersion {
    /// `$M` frames (every Betaflight, INAV and MultiWii answers them).
    #[default]
    V1,
    /// `$X` frames.
    V2,
}

/// A request for `cmd` (no payload), as the host sends it.
///
/// ```
/// use margemu_hil::dut::msp::{request, MspVersion, MSP_ATTITUDE};
/// assert_eq!(request(MSP_ATTITUDE, MspVersion::V1), b"$M<\x00\x6c\x6c");
/// ```
pub fn request(cmd: u16, version: MspVersion) -> Vec<u8> {
    encode(b'<', cmd, &[], version)
}

/// A frame in direction `dir` (`b'<'`, `b'>'` or `b'!'`). A v1 frame carries the low byte of
/// `cmd` and at most 255 payload bytes (the rest is cut).
pub fn encode(dir: u8, cmd: u16, payload: &[u8], version: MspVersion) -> Vec<u8> {
    match version {
        MspVersion::V1 => {
            let payload = &payload[..payload.len().min(255)];
            let mut f = vec![b'$', b'M', dir, payload.len() as u8, cmd as u8];
            f.extend_from_slice(payload);
            f.push(f[3..].iter().fold(0, |x, b| x ^ b));
            f
        }
        MspVersion::V2 => {
            let len = payload.len().min(usize::from(u16::MAX));
            let mut f = vec![b'$', b'X', dir, 0];
            f.extend_from_slice(&cmd.to_le_bytes());
            f.extend_from_slice(&(len as u16).to_le_bytes());
            f.extend_from_slice(&payload[..len]);
            f.push(CRC8_DVB_S2.checksum(&f[3..]));
            f
        }
    }
}

/// The MSP stream decoder.
pub type MspDecoder = Framer<MspFormat>;

impl MspDecoder {
    /// A decoder for MSP v1 and v2 mixed.
    pub fn new() -> Self {
        Self::with_format(MspFormat)
    }
}

/// MSP framing for the [`Framer`].
#[derive(Debug, Default)]
pub struct MspFormat;

impl FrameFormat for MspFormat {
    fn is_start(byte: u8) -> bool {
        byte == b'$'
    }

    fn candidate(
        &mut self,
        b: &[u8],
        counters: &mut DecodeCounters,
        out: &mut Vec<Decoded>,
    ) -> Candidate {
        let need = |n: usize| b.len() >= n;
        if !need(3) {
            return Candidate::Incomplete;
        }
        let wire = match b[1] {
            b'M' => Wire::Msp1,
            b'X' => Wire::Msp2,
            _ => return Candidate::Reject(Reject::Header),
        };
        let dir = b[2];
        if !matches!(dir, b'<' | b'>' | b'!') {
            return Candidate::Reject(Reject::Header);
        }
        let (cmd, start, len) = match wire {
            Wire::Msp1 if need(5) => (u16::from(b[4]), 5, usize::from(b[3])),
            Wire::Msp2 if need(8) => {
                let len = usize::from(u16::from_le_bytes([b[6], b[7]]));
                if len > MAX_PAYLOAD {
                    return Candidate::Reject(Reject::Header);
                }
                (u16::from_le_bytes([b[4], b[5]]), 8, len)
            }
            _ => return Candidate::Incomplete,
        };
        let total = start + len + 1;
        if !need(total) {
            return Candidate::Incomplete;
        }
        let sum = match wire {
            Wire::Msp1 => b[3..total - 1].iter().fold(0, |x, b| x ^ b),
            _ => CRC8_DVB_S2.checksum(&b[3..total - 1]),
        };
        if sum != b[total - 1] {
            return Candidate::Reject(Reject::Checksum);
        }
        let payload = &b[start..start + len];
        let sample = if dir == b'>' {
            let s = sample_of(cmd, payload);
            if s.is_none() && matches!(cmd, MSP_ATTITUDE | MSP_RAW_IMU) {
                counters.undecoded += 1;
            }
            s
        } else {
            None
        };
        out.push(Decoded {
            message: MessageInfo {
                wire,
                name: name_of(cmd, dir),
                sys_id: None,
                comp_id: None,
                seq: None,
                length: len,
            },
            sample,
        });
        Candidate::Frame(total)
    }
}

/// `MSP_ATTITUDE`, `MSP_RAW_IMU`, else `MSP_CMD_<n>`; `_REQUEST` for `'<'`, `_ERROR` for `'!'`.
fn name_of(cmd: u16, dir: u8) -> Cow<'static, str> {
    let base: Cow<'static, str> = match cmd {
        MSP_ATTITUDE => "MSP_ATTITUDE".into(),
        MSP_RAW_IMU => "MSP_RAW_IMU".into(),
        n => format!("MSP_CMD_{n}").into(),
    };
    match dir {
        b'<' => format!("{base}_REQUEST").into(),
        b'!' => format!("{base}_ERROR").into(),
        _ => base,
    }
}

fn sample_of(cmd: u16, p: &[u8]) -> Option<Sample> {
    let i16_at = |i: usize| i16::from_le_bytes([p[2 * i], p[2 * i + 1]]);
    match cmd {
        MSP_ATTITUDE if p.len() >= 6 => Some(Sample::Attitude(AttitudeSample {
            device_time_us: None,
            attitude: from_msp::attitude(i16_at(0), i16_at(1), i16_at(2)),
        })),
        MSP_RAW_IMU if p.len() >= 18 => {
            let v = |i: usize| [0, 1, 2].map(|k| f64::from(i16_at(i + k)));
            Some(Sample::Imu(ImuSample {
                device_time_us: None,
                accel: v(0),
                gyro: v(3),
                mag: v(6),
            }))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode_all(bytes: &[u8]) -> (Vec<Decoded>, DecodeCounters) {
        let mut d = MspDecoder::new();
        let mut out = Vec::new();
        d.feed(bytes, &mut out);
        d.finish(&mut out);
        (out, d.counters())
    }

    #[test]
    fn v2_request_bytes() {
        // CRC-8/DVB-S2 check value of "123456789" is 0xBC.
        assert_eq!(CRC8_DVB_S2.checksum(b"123456789"), 0xBC);
        let r = request(MSP_RAW_IMU, MspVersion::V2);
        assert_eq!(&r[..8], b"$X<\x00\x66\x00\x00\x00");
        assert_eq!(r[8], CRC8_DVB_S2.checksum(&r[3..8]));
    }

    #[test]
    fn false_starts_hide_nothing() {
        let reply = encode(b'>', MSP_ATTITUDE, &[1, 0, 2, 0, 3, 0], MspVersion::V1);
        for prefix in [&b"$"[..], b"$$", b"$M", b"$$M>", b"$X>\x00", b"$M>\x10\x6c"] {
            let mut bytes = prefix.to_vec();
            bytes.extend_from_slice(&reply);
            let (out, c) = decode_all(&bytes);
            assert_eq!(out.len(), 1, "{prefix:?}");
            assert_eq!(c.bad_bytes, prefix.len() as u64, "{prefix:?}");
        }
    }

    #[test]
    fn a_v2_length_beyond_the_cap_is_a_false_start() {
        let mut bytes = b"$X>\x00\x6c\x00\xff\xff".to_vec();
        bytes.extend(encode(b'>', MSP_ATTITUDE, &[0; 6], MspVersion::V2));
        let (out, c) = decode_all(&bytes);
        assert_eq!((out.len(), c.bad_bytes), (1, 8));
    }

    #[test]
    fn short_payloads_are_logged_but_undecoded_and_errors_named() {
        let mut bytes = encode(b'>', MSP_ATTITUDE, &[1, 2], MspVersion::V1);
        bytes.extend(encode(b'!', 250, &[], MspVersion::V2));
        let (out, c) = decode_all(&bytes);
        assert_eq!(c.undecoded, 1);
        assert_eq!(out[0].message.name, "MSP_ATTITUDE");
        assert_eq!(out[0].sample, None);
        assert_eq!(out[1].message.name, "MSP_CMD_250_ERROR");
    }
}
