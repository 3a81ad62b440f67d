//! What one HIL_SENSOR carries: a scene sample (its truth and device 0's MARG reading) turned
//! into PX4's units and frames, and the HEARTBEAT a simulator sends.
//!
//! | field | value | unit, frame |
//! |---|---|---|
//! | `time_usec` | scene time of the sample, `t_ns / 1000` (floor) | µs since scene start |
//! | `xacc, yacc, zacc` | accelerometer reading `(x, −y, −z)` | m/s², body FRD (level at rest: `(0, 0, −9.81)`) |
//! | `xgyro, ygyro, zgyro` | gyroscope reading `(x, −y, −z)` | rad/s, body FRD |
//! | `xmag, ymag, zmag` | magnetometer reading `(x, −y, −z)` × gauss per scene unit | gauss, body FRD |
//! | `abs_pressure` | ISA pressure at `pressure_alt` | hPa |
//! | `diff_pressure` | 0, not flagged | — |
//! | `pressure_alt` | [`BASE_ALTITUDE_M`] + the plate's height `z` from the truth | m |
//! | `temperature` | the scene's `[sensors] temperature` at `t`, else [`DEFAULT_TEMP_C`] | °C |
//! | `fields_updated` | [`FIELDS_SENT`]: bits 0–9, 11, 12 (`0x1BFF`) | HIL_SENSOR_UPDATED_FLAGS |
//! | `id` | 0: the `mavlink` crate's common dialect has no `id` extension, and MAVLink 2 reads an absent extension as 0 | — |
//!
//! **Frames.** margemu's body axes are x forward, y left, z up; PX4's are FRD (x forward,
//! y right, z down). The two differ by 180° about x, so every vector maps as
//! `(x, y, z) → (x, −y, −z)` ([`crate::dut::frames::from_ned::vector`], the same map the
//! device-under-test reader undoes). Sign flips are exact in `f32`: accelerometer and gyroscope
//! values are the `f32` readings of `marg.csv`, bit for bit; the field is scaled in `f64` and
//! rounded once to `f32`.
//!
//! **Field unit.** µT → gauss is exact: 1 G = 100 µT ([`gauss_per_unit`]). A scene in
//! normalized units ("nu") has no physical scale: the caller chooses one (`--gauss-per-unit`,
//! 0.5 by default: a unit-norm field of 0.5 G, about the Earth's).
//!
//! Sources (read, not copied): PX4-Autopilot `src/modules/simulation/simulator_mavlink/
//! SimulatorMavlink.cpp` (`update_sensors`: accel, gyro and mag taken when their three bits
//! are set, the temperature only with the barometer's), `src/modules/mavlink/
//! mavlink_receiver.cpp` (`handle_message_hil_sensor`, the HITL path), and the MAVLink common
//! dialect's HIL_SENSOR and HIL_SENSOR_UPDATED_FLAGS.

use crate::dut::frames::from_ned;
use margemu_sim::marg::MargSample;
use margemu_sim::scene::FieldUnit;
use margemu_sim::truth::Truth;
use mavlink::dialects::common::{
    HilSensorUpdatedFlags, MavAutopilot, MavMessage, MavModeFlag, MavState, MavType,
    HEARTBEAT_DATA, HIL_SENSOR_DATA,
};

/// Altitude of the bench floor above sea level (m): sea level, the ISA's reference.
pub const BASE_ALTITUDE_M: f64 = 0.0;
/// The temperature sent when the scene has no `[sensors] temperature` (°C): the ISA's at sea
/// level.
pub const DEFAULT_TEMP_C: f64 = 15.0;
/// Gauss per µT.
pub const GAUSS_PER_MICROTESLA: f64 = 0.01;
/// The default scale of a normalized field (gauss per "nu").
pub const DEFAULT_GAUSS_PER_UNIT: f64 = 0.5;

/// The bits of `fields_updated` every HIL_SENSOR carries: accelerometer, gyroscope and
/// magnetometer (bits 0–8), `abs_pressure` (9), `pressure_alt` (11), `temperature` (12); not
/// `diff_pressure` (10) nor the reset bit (31).
pub const FIELDS_SENT: u32 = 0x1BFF;

/// The field's scale to gauss: exact for µT; `normalized` (the caller's choice) for "nu".
pub fn gauss_per_unit(unit: FieldUnit, normalized: f64) -> f64 {
    match unit {
        FieldUnit::Microtesla => GAUSS_PER_MICROTESLA,
        FieldUnit::Normalized => normalized,
    }
}

/// How scene samples become HIL_SENSOR messages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorMapping {
    /// Gauss per unit of the scene's field.
    pub gauss_per_unit: f64,
    /// The scene's `[sensors] temperature`: `[start °C, slope °C/s]`.
    pub temperature: Option<[f64; 2]>,
}

impl SensorMapping {
    /// The HIL_SENSOR of one sample: its truth `t` and device 0's reading `s`.
    pub fn message(&self, t: &Truth, s: &MargSample) -> HIL_SENSOR_DATA {
        let frd = |v: [f32; 3]| from_ned::vector(v.map(f64::from)).map(|x| x as f32);
        let [xacc, yacc, zacc] = frd(s.sample.acc);
        let [xgyro, ygyro, zgyro] = frd(s.sample.gyr);
        let mag = from_ned::vector(s.sample.mag.map(f64::from));
        let [xmag, ymag, zmag] = mag.map(|x| (x * self.gauss_per_unit) as f32);
        let altitude = BASE_ALTITUDE_M + t.position[2];
        let seconds = t.t_ns as f64 * 1e-9;
        let temperature = self
            .temperature
            .map_or(DEFAULT_TEMP_C, |[start, slope]| start + slope * seconds);
        HIL_SENSOR_DATA {
            time_usec: t.t_ns / 1000,
            xacc,
            yacc,
            zacc,
            xgyro,
            ygyro,
            zgyro,
            xmag,
            ymag,
            zmag,
            abs_pressure: isa_pressure_hpa(altitude) as f32,
            diff_pressure: 0.0,
            pressure_alt: altitude as f32,
            temperature: temperature as f32,
            fields_updated: HilSensorUpdatedFlags::from_bits_retain(FIELDS_SENT),
        }
    }
}

/// ISA pressure (hPa) at `altitude_m` in the troposphere: `1013.25·(1 − 2.25577·10⁻⁵·h)^5.25588`.
pub fn isa_pressure_hpa(altitude_m: f64) -> f64 {
    1013.25 * libm::pow(1.0 - 2.255_77e-5 * altitude_m, 5.255_88)
}

/// The simulator's HEARTBEAT: a generic MAVLink component that is no autopilot, active.
pub fn heartbeat() -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_GENERIC,
        autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
        base_mode: MavModeFlag::empty(),
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_model::sensor::Sample;

    fn sample(acc: [f32; 3], gyr: [f32; 3], mag: [f32; 3]) -> MargSample {
        MargSample {
            t_ns: 1_234_567,
            sample: Sample { acc, gyr, mag },
            disturbance: [0.0; 3],
            dropout: 0,
        }
    }

    fn truth(t_ns: u64, z: f64) -> Truth {
        Truth {
            t_ns,
            position: [0.0, 0.0, z],
            ..Truth::default()
        }
    }

    #[test]
    fn flu_becomes_frd_and_microtesla_gauss() {
        let m = SensorMapping {
            gauss_per_unit: gauss_per_unit(FieldUnit::Microtesla, 0.5),
            temperature: None,
        };
        let s = sample([0.5, -1.5, 9.75], [0.1, 0.2, -0.3], [20.0, -5.0, -40.0]);
        let h = m.message(&truth(1_234_567, 0.0), &s);
        assert_eq!(h.time_usec, 1234);
        assert_eq!([h.xacc, h.yacc, h.zacc], [0.5, 1.5, -9.75]);
        assert_eq!([h.xgyro, h.ygyro, h.zgyro], [0.1, -0.2, 0.3]);
        assert_eq!([h.xmag, h.ymag, h.zmag], [0.2, 0.05, 0.4]);
        assert_eq!(h.fields_updated.bits(), 0x1BFF);
        assert_eq!(h.temperature, 15.0);
        assert!((h.abs_pressure - 1013.25).abs() < 1e-4);
    }

    #[test]
    fn height_and_temperature_follow_the_scene() {
        let m = SensorMapping {
            gauss_per_unit: 0.5,
            temperature: Some([20.0, 0.5]),
        };
        let h = m.message(
            &truth(2_000_000_000, 100.0),
            &sample([0.0; 3], [0.0; 3], [1.0; 3]),
        );
        assert_eq!(h.pressure_alt, 100.0);
        assert_eq!(h.temperature, 21.0);
        assert_eq!([h.xmag, h.ymag, h.zmag], [0.5, -0.5, -0.5]);
        // ISA: about 12 hPa less per 100 m near sea level.
        assert!(
            (h.abs_pressure - 1001.29).abs() < 0.05,
            "{}",
            h.abs_pressure
        );
    }
}
