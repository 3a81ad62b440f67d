//! Source (b): kinematics in, the shared model on the device, images bit-identical to the
//! host's own `Marg` + `ImageRepr::from_physical`.

use margemu_firmware::chip::Mpu6xxx;
use margemu_model::sensor::{Marg, MargConfig, Truth};
use margemu_protocol::link::{Configure, KinematicsBatch, Message, ModelParams, Rate, Source};
use margemu_protocol::regmap::mpu6xxx::image::ImageRepr;

use crate::common::*;

const SEED: u64 = 0x5EED;
const MAG_SCALE: f64 = 48.5;

fn marg_config() -> MargConfig {
    let mut cfg = MargConfig::default();
    cfg.gyro.errors.noise_density = Some([0.0224; 3]);
    cfg.gyro.errors.bias = Some([0.01, -0.02, 0.005]);
    cfg.accel.errors.noise_density = Some([0.0224; 3]);
    cfg.accel.errors.range = Some([156.0; 3]);
    cfg.mag.errors.noise_density = Some([0.0022; 3]);
    cfg.mag.hard_iron = Some([0.1, 0.0, -0.05]);
    cfg
}

fn truth(j: u64) -> Truth {
    let x = j as f32 * 0.01;
    Truth {
        angular_rate: [x.sin(), 0.3 * x.cos(), -0.2],
        specific_force: [0.5 * x, -0.1, 9.80665],
        magnetic_field: [0.4, 0.05 * x, -0.8],
        angular_acceleration: [0.0, x, 0.0],
        temperature_c: (!j.is_multiple_of(3)).then_some(25.0 + x),
    }
}

#[test]
fn model_images_equal_the_hosts_prediction_bit_for_bit() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    let out_rate = Rate::hz(1000).unwrap();
    let truth_rate = Rate::hz(200).unwrap();
    let mut params = ModelParams::new(SEED, truth_rate, marg_config());
    params.mag_ut_per_unit = MAG_SCALE;
    host.configure(
        &mut dev,
        Configure {
            source: Source::Model(params),
            ..Configure::new(ChipModel::Mpu9250, out_rate)
        },
    );
    let sent: Vec<Truth> = (0..40).map(truth).collect();
    for (i, chunk) in sent.chunks(28).enumerate() {
        let batch = KinematicsBatch::new(28 * i as u64, chunk);
        host.send(&mut dev, &Message::Kinematics(batch), 0);
    }
    host.start(&mut dev, 0, 0);
    assert_eq!(dev.buffer_level(), 40);

    // The host's prediction, computed independently of the device's code.
    let mut marg = Marg::new(&marg_config(), 1000.0, SEED).unwrap();
    let cfg = Mpu6xxx::new().image_config();
    for k in 0..220u64 {
        poll(&mut dev, k * MS);
        let j = (k / 5).min(39); // 200 Hz truth held over 5 outputs; 39 is the last sent
        let t = sent[j as usize];
        let s = marg.sample(&t);
        let mag = s.mag.map(|m| (f64::from(m) * MAG_SCALE) as f32);
        let temp = t.temperature_c.unwrap_or(21.0);
        let expected = ImageRepr::from_physical(s.acc, s.gyr, temp, mag, &cfg).emit();
        let served = dev.last_served().unwrap();
        assert_eq!(served.index, k);
        assert_eq!(served.image, Some(Image::from(expected)), "sample {k}");
        assert_eq!(served.underrun, k >= 200, "sample {k}");
        assert_eq!(burst_sensors(&mut dev), expected[..14]);
    }
    assert_eq!(dev.counters().underruns, 20);
    // The window starts at the kinematics index in effect (219 ms → 43).
    assert_eq!(dev.credit().limit, 43 + CAP as u64);
}

#[test]
fn the_model_stops_at_the_scene_end_without_underruns() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    let params = ModelParams::new(SEED, Rate::hz(200).unwrap(), marg_config());
    host.configure(
        &mut dev,
        Configure {
            source: Source::Model(params),
            ..Configure::new(ChipModel::Mpu9250, Rate::hz(1000).unwrap())
        },
    );
    // 40 kinematics at 200 Hz cover 200 outputs at 1 kHz: the scene's 200 samples.
    let sent: Vec<Truth> = (0..40).map(truth).collect();
    for (i, chunk) in sent.chunks(28).enumerate() {
        let batch = KinematicsBatch::new(28 * i as u64, chunk);
        host.send(&mut dev, &Message::Kinematics(batch), 0);
    }
    host.start_scene(&mut dev, 200, 0);
    let mut out = Vec::new();
    for k in 0..260u64 {
        out.extend(poll(&mut dev, k * MS)); // the host's Stop never comes
    }
    let c = dev.counters();
    assert_eq!((c.served, c.underruns), (200, 0));
    assert_eq!(dev.last_served().unwrap().index, 199);
    let t = telemetry(&out).unwrap();
    assert_eq!(t.state, margemu_protocol::link::DeviceState::Stopped);
    assert_eq!(t.time_ns, 200 * MS);
}
