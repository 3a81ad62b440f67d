//! MAVLink 1 and 2 from the device: frames found by the [`Framer`], checked and decoded by the
//! `mavlink` crate (common dialect): its raw frame types give the header fields, its
//! `has_valid_crc` checks the CRC with the message's CRC_EXTRA, and `MavMessage::parse` decodes
//! the payload (zero-extended as MAVLink 2 requires).
//!
//! Accepted: MAVLink 1; MAVLink 2 with the incompatibility flags the crate supports (signed
//! frames are accepted on their CRC; their signature is not verified). A message id outside the
//! common dialect cannot be CRC-checked, so such a candidate is rejected and counted
//! ([`DecodeCounters::unknown_ids`]). An intact frame whose payload the crate refuses (e.g. an
//! enum value newer than its dialect) is still logged in `dut_messages.csv` and counted as
//! undecoded.

use super::decode::{
    AttitudeSample, Candidate, DecodeCounters, Decoded, FrameFormat, Framer, ImuSample,
    MessageInfo, Reject, Sample, Wire,
};
use super::frames::{from_ned, Attitude, STANDARD_GRAVITY};
use mavlink::dialects::common::{
    MavMessage, ATTITUDE_DATA, ATTITUDE_QUATERNION_DATA, HIGHRES_IMU_DATA,
};
use mavlink::{
    consts, MAVLinkV1MessageRaw, MAVLinkV2MessageRaw, MavlinkVersion, Message, MAV_STX, MAV_STX_V2,
};
use std::borrow::Cow;

/// The MAVLink stream decoder.
pub type MavlinkDecoder = Framer<MavlinkFormat>;

impl MavlinkDecoder {
    /// A decoder for MAVLink 1 and 2 mixed.
    pub fn new() -> Self {
        Self::with_format(MavlinkFormat)
    }
}

/// MAVLink framing for the [`Framer`].
#[derive(Debug, Default)]
pub struct MavlinkFormat;

/// Where a candidate's fields are: header length (after STX), signature length, message id.
struct Layout {
    version: MavlinkVersion,
    header: usize,
    signature: usize,
    id: u32,
}

fn layout(b: &[u8]) -> Result<Layout, Candidate> {
    let need = |n: usize| {
        if b.len() < n {
            Err(Candidate::Incomplete)
        } else {
            Ok(())
        }
    };
    if b[0] == MAV_STX {
        need(6)?;
        return Ok(Layout {
            version: MavlinkVersion::V1,
            header: consts::v1::HEADER_SIZE,
            signature: 0,
            id: u32::from(b[5]),
        });
    }
    need(3)?;
    let flags = b[consts::v2::INCOMPAT_FLAGS_OFFSET];
    if flags & !consts::v2::SUPPORTED_IFLAGS != 0 {
        return Err(Candidate::Reject(Reject::Header));
    }
    let wide = flags & consts::v2::IFLAG_SYSID32 != 0;
    let extra = if wide {
        consts::v2::SYSID32_EXTRA_HEADER_SIZE
    } else {
        0
    };
    let id_at = 7 + extra;
    need(id_at + 3)?;
    Ok(Layout {
        version: MavlinkVersion::V2,
        header: consts::v2::MIN_HEADER_SIZE + extra,
        signature: if flags & consts::v2::IFLAG_SIGNED != 0 {
            consts::v2::SIGNATURE_SIZE
        } else {
            0
        },
        id: u32::from_le_bytes([b[id_at], b[id_at + 1], b[id_at + 2], 0]),
    })
}

impl FrameFormat for MavlinkFormat {
    fn is_start(byte: u8) -> bool {
        byte == MAV_STX || byte == MAV_STX_V2
    }

    fn candidate(
        &mut self,
        b: &[u8],
        counters: &mut DecodeCounters,
        out: &mut Vec<Decoded>,
    ) -> Candidate {
        let l = match layout(b) {
            Ok(l) => l,
            Err(verdict) => return verdict,
        };
        let Some(known) = MavMessage::default_message_from_id(l.id) else {
            return Candidate::Reject(Reject::UnknownId);
        };
        let len = usize::from(b[consts::PAYLOAD_LEN_OFFSET]);
        let total = consts::STX_SIZE + l.header + len + consts::CHECKSUM_SIZE + l.signature;
        if b.len() < total {
            return Candidate::Incomplete;
        }
        let (wire, raw) = match l.version {
            MavlinkVersion::V1 => {
                let mut raw = MAVLinkV1MessageRaw::new();
                raw.as_mut_slice()[..total].copy_from_slice(&b[..total]);
                if !raw.has_valid_crc::<MavMessage>() {
                    return Candidate::Reject(Reject::Checksum);
                }
                (Wire::Mavlink1, mavlink::MAVLinkMessageRaw::V1(raw))
            }
            MavlinkVersion::V2 => {
                let mut raw = MAVLinkV2MessageRaw::new();
                raw.as_mut_slice()[..total].copy_from_slice(&b[..total]);
                if !raw.has_valid_crc::<MavMessage>() {
                    return Candidate::Reject(Reject::Checksum);
                }
                (Wire::Mavlink2, mavlink::MAVLinkMessageRaw::V2(raw))
            }
        };
        let parsed = MavMessage::parse(l.version, l.id, raw.payload());
        let (name, sample) = match &parsed {
            Ok(m) => (m.message_name(), sample_of(m)),
            Err(_) => {
                counters.undecoded += 1;
                (known.message_name(), None)
            }
        };
        out.push(Decoded {
            message: MessageInfo {
                wire,
                name: Cow::Borrowed(name),
                sys_id: Some(raw.system_id()),
                comp_id: Some(raw.component_id()),
                seq: Some(raw.sequence()),
                length: len,
            },
            sample,
        });
        Candidate::Frame(total)
    }
}

/// The attitude or IMU content of the messages margemu evaluates (module docs of `dut`).
fn sample_of(m: &MavMessage) -> Option<Sample> {
    let ms = |t: u32| Some(u64::from(t) * 1000);
    let f = |v: f32| f64::from(v);
    Some(match m {
        MavMessage::ATTITUDE(ATTITUDE_DATA {
            time_boot_ms,
            roll,
            pitch,
            yaw,
            ..
        }) => {
            let [r, p, y] = from_ned::euler([f(*roll), f(*pitch), f(*yaw)]);
            Sample::Attitude(AttitudeSample {
                device_time_us: ms(*time_boot_ms),
                attitude: Attitude::from_euler(r, p, y),
            })
        }
        MavMessage::ATTITUDE_QUATERNION(ATTITUDE_QUATERNION_DATA {
            time_boot_ms,
            q1,
            q2,
            q3,
            q4,
            ..
        }) => Sample::Attitude(AttitudeSample {
            device_time_us: ms(*time_boot_ms),
            attitude: Attitude::from_quaternion(from_ned::quaternion([
                f(*q1),
                f(*q2),
                f(*q3),
                f(*q4),
            ])),
        }),
        MavMessage::SCALED_IMU(d) => scaled_imu(
            d.time_boot_ms,
            [
                d.xacc, d.yacc, d.zacc, d.xgyro, d.ygyro, d.zgyro, d.xmag, d.ymag, d.zmag,
            ],
        ),
        MavMessage::SCALED_IMU2(d) => scaled_imu(
            d.time_boot_ms,
            [
                d.xacc, d.yacc, d.zacc, d.xgyro, d.ygyro, d.zgyro, d.xmag, d.ymag, d.zmag,
            ],
        ),
        MavMessage::SCALED_IMU3(d) => scaled_imu(
            d.time_boot_ms,
            [
                d.xacc, d.yacc, d.zacc, d.xgyro, d.ygyro, d.zgyro, d.xmag, d.ymag, d.zmag,
            ],
        ),
        MavMessage::HIGHRES_IMU(d) => highres_imu(d),
        _ => return None,
    })
}

/// SCALED_IMU, SCALED_IMU2, SCALED_IMU3: mG, mrad/s, mgauss in FRD.
fn scaled_imu(time_boot_ms: u32, v: [i16; 9]) -> Sample {
    let scaled = |i: usize, k: f64| {
        from_ned::vector([
            f64::from(v[i]) * k,
            f64::from(v[i + 1]) * k,
            f64::from(v[i + 2]) * k,
        ])
    };
    Sample::Imu(ImuSample {
        device_time_us: Some(u64::from(time_boot_ms) * 1000),
        accel: scaled(0, STANDARD_GRAVITY / 1000.0),
        gyro: scaled(3, 1e-3),
        // 1 mgauss = 0.1 µT.
        mag: scaled(6, 0.1),
    })
}

/// HIGHRES_IMU: m/s², rad/s, gauss in FRD (`fields_updated` is not consulted: every field is
/// written as received).
fn highres_imu(d: &HIGHRES_IMU_DATA) -> Sample {
    let v = |x: f32, y: f32, z: f32, k: f64| {
        from_ned::vector([f64::from(x) * k, f64::from(y) * k, f64::from(z) * k])
    };
    Sample::Imu(ImuSample {
        device_time_us: Some(d.time_usec),
        accel: v(d.xacc, d.yacc, d.zacc, 1.0),
        gyro: v(d.xgyro, d.ygyro, d.zgyro, 1.0),
        // 1 gauss = 100 µT.
        mag: v(d.xmag, d.ymag, d.zmag, 100.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::MavHeader;

    fn frame(version: MavlinkVersion, seq: u8, m: &MavMessage) -> Vec<u8> {
        let mut out = Vec::new();
        let header = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: seq,
        };
        mavlink::write_versioned_msg(&mut out, version, header, m).unwrap();
        out
    }

    fn heartbeat() -> MavMessage {
        MavMessage::HEARTBEAT(Default::default())
    }

    fn system_time() -> MavMessage {
        MavMessage::SYSTEM_TIME(mavlink::dialects::common::SYSTEM_TIME_DATA {
            time_unix_usec: 0x0102_0304_0506_0708,
            time_boot_ms: 0x1122_3344,
        })
    }

    #[test]
    fn a_damaged_frame_is_one_bad_frame_and_the_next_is_recovered() {
        let good = frame(MavlinkVersion::V2, 1, &system_time());
        let mut damaged = frame(MavlinkVersion::V2, 0, &system_time());
        // Byte 12 is in the payload; the frame holds no other start byte before or after.
        damaged[12] ^= 0x40;
        assert!(!damaged[1..].iter().any(|&b| MavlinkFormat::is_start(b)));
        let mut bytes = damaged.clone();
        bytes.extend_from_slice(&good);
        let mut d = MavlinkDecoder::new();
        let mut out = Vec::new();
        for b in &bytes {
            d.feed(std::slice::from_ref(b), &mut out);
        }
        d.finish(&mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].message.seq, Some(1));
        let c = d.counters();
        assert_eq!(
            (c.bytes, c.bad_bytes, c.bad_frames),
            (bytes.len() as u64, damaged.len() as u64, 1)
        );
    }

    #[test]
    fn a_truncated_frame_at_the_end_hides_no_frame() {
        // A v1 start byte claiming 200 payload bytes swallows a whole frame until the stream
        // ends; then the frame behind it is found.
        let good = frame(MavlinkVersion::V1, 7, &heartbeat());
        let mut bytes = vec![MAV_STX, 200, 0, 1, 1, 0];
        bytes.extend_from_slice(&good);
        let mut d = MavlinkDecoder::new();
        let mut out = Vec::new();
        d.feed(&bytes, &mut out);
        assert!(out.is_empty());
        d.finish(&mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].message.wire, Wire::Mavlink1);
        assert_eq!(d.counters().bad_bytes, 6);
    }

    #[test]
    fn unknown_ids_are_counted_not_decoded() {
        // Message id 0xFFFFFF is in no dialect.
        let bytes = [MAV_STX_V2, 0, 0, 0, 0, 1, 1, 0xFF, 0xFF, 0xFF, 0, 0];
        let mut d = MavlinkDecoder::new();
        let mut out = Vec::new();
        d.feed(&bytes, &mut out);
        d.finish(&mut out);
        assert!(out.is_empty());
        let c = d.counters();
        assert_eq!((c.unknown_ids, c.bad_bytes), (1, 12));
    }
}
