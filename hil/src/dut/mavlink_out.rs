//! The MAVLink a virtual flight controller sends: ATTITUDE and ATTITUDE_QUATERNION built from a
//! margemu attitude (converted to NED/FRD, see [`from_ned`]) and framed by the `mavlink` crate's
//! own encoder, MAVLink 2 by default.
//!
//! ```
//! use margemu_hil::dut::mavlink_out::{attitude_quaternion, MavlinkWriter};
//! let mut fc = MavlinkWriter::v2();
//! let frame = fc.encode(&attitude_quaternion(1500, [1.0, 0.0, 0.0, 0.0], [0.0; 3])).unwrap();
//! assert_eq!(frame[0], 0xFD);
//! ```

use super::frames::{from_ned, Attitude};
use mavlink::dialects::common::{MavMessage, ATTITUDE_DATA, ATTITUDE_QUATERNION_DATA};
use mavlink::error::MessageWriteError;
use mavlink::{MavHeader, MavlinkVersion};

/// ATTITUDE for the margemu quaternion `q` (body to world, any sign and norm) and body rate
/// (rad/s, margemu body axes) at `time_boot_ms`.
pub fn attitude(time_boot_ms: u32, q: [f64; 4], body_rate: [f64; 3]) -> MavMessage {
    let e = from_ned::euler(Attitude::from_quaternion(q).euler);
    let w = from_ned::vector(body_rate);
    MavMessage::ATTITUDE(ATTITUDE_DATA {
        time_boot_ms,
        roll: e[0] as f32,
        pitch: e[1] as f32,
        yaw: e[2] as f32,
        rollspeed: w[0] as f32,
        pitchspeed: w[1] as f32,
        yawspeed: w[2] as f32,
    })
}

/// ATTITUDE_QUATERNION for the margemu quaternion `q` (normalized here; its sign is kept) and
/// body rate (rad/s, margemu body axes) at `time_boot_ms`.
pub fn attitude_quaternion(time_boot_ms: u32, q: [f64; 4], body_rate: [f64; 3]) -> MavMessage {
    let q = from_ned::quaternion(Attitude::from_quaternion(q).quaternion);
    let w = from_ned::vector(body_rate);
    MavMessage::ATTITUDE_QUATERNION(ATTITUDE_QUATERNION_DATA {
        time_boot_ms,
        q1: q[0] as f32,
        q2: q[1] as f32,
        q3: q[2] as f32,
        q4: q[3] as f32,
        rollspeed: w[0] as f32,
        pitchspeed: w[1] as f32,
        yawspeed: w[2] as f32,
    })
}

/// Frames messages as one MAVLink system/component, numbering them in sequence.
#[derive(Clone, Debug)]
pub struct MavlinkWriter {
    version: MavlinkVersion,
    system_id: u8,
    component_id: u8,
    sequence: u8,
}

impl MavlinkWriter {
    /// MAVLink 2, system 1, component 1 (`MAV_COMP_ID_AUTOPILOT1`).
    pub fn v2() -> Self {
        Self {
            version: MavlinkVersion::V2,
            system_id: 1,
            component_id: 1,
            sequence: 0,
        }
    }

    /// MAVLink 1, system 1, component 1.
    pub fn v1() -> Self {
        Self {
            version: MavlinkVersion::V1,
            ..Self::v2()
        }
    }

    /// The same with other sender ids.
    pub fn with_ids(self, system_id: u8, component_id: u8) -> Self {
        Self {
            system_id,
            component_id,
            ..self
        }
    }

    /// The wire bytes of `message`, with the next sequence number. Fails only for a message
    /// MAVLink 1 cannot carry (id above 255) on a MAVLink 1 writer.
    pub fn encode(&mut self, message: &MavMessage) -> Result<Vec<u8>, MessageWriteError> {
        let header = MavHeader {
            system_id: u32::from(self.system_id),
            component_id: self.component_id,
            sequence: self.sequence,
        };
        let mut out = Vec::with_capacity(64);
        mavlink::write_versioned_msg(&mut out, self.version, header, message)?;
        self.sequence = self.sequence.wrapping_add(1);
        Ok(out)
    }
}
