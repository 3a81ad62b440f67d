//! Source (b) with a sampling chain: AddVibration messages build the device's chain (the same
//! `setup::model_chain` the host predicts with), and what it cannot hold is refused.

use margemu_firmware::link::setup::{self, ChainSetup, DeviceModel};
use margemu_firmware::link::{VIBRATION_IN_IMAGES, VIBRATION_REFUSED};
use margemu_model::sensor::{MargConfig, Truth};
use margemu_model::vibration::{Harmonic, RpmPoint, Shock, ToneSource, MAX_TONE_SOURCES};
use margemu_protocol::chip::ChainConfig;
use margemu_protocol::link::{
    AddVibration, Configure, DeviceState, ErrorCode, KinematicsBatch, Message, ModelParams, Rate,
    RpmProfile, Source,
};

use crate::common::*;

const SEED: u64 = 0x51B;

fn params() -> ModelParams {
    let mut cfg = MargConfig::default();
    cfg.gyro.errors.noise_density = Some([0.01; 3]);
    cfg.accel.errors.noise_density = Some([0.01; 3]);
    ModelParams::new(SEED, Rate::hz(250).unwrap(), cfg)
}

fn model_configure(chip: ChipModel) -> Configure {
    Configure {
        source: Source::Model(params()),
        ..Configure::new(chip, Rate::hz(1000).unwrap())
    }
}

fn tones(motors: u8) -> AddVibration {
    let mut profile = RpmProfile::new();
    profile
        .push(RpmPoint {
            t_ns: 0,
            rpm: 6_000.0,
        })
        .unwrap();
    let ramp = RpmPoint {
        t_ns: 100_000_000,
        rpm: 24_000.0,
    };
    profile.push(ramp).unwrap();
    let mut t = ToneSource::new(motors, profile);
    t.spread = 0.03;
    let h = Harmonic {
        order: 1.0,
        linear: [2.0, 0.0, 4.0],
        angular: [0.0, 0.3, 0.0],
    };
    t.push(h).unwrap();
    AddVibration::Tones(t)
}

fn shock() -> AddVibration {
    AddVibration::Shock(Shock {
        t_ns: 40_000_000,
        duration_ns: 11_000_000,
        linear: [0.0, 0.0, 150.0],
        angular: [2.0, 0.0, 0.0],
    })
}

fn truth(j: u64) -> Truth {
    Truth {
        angular_rate: [0.01 * j as f32, 0.0, 0.1],
        specific_force: [0.0, 0.0, 9.80665],
        magnetic_field: [0.2, 0.0, 0.4],
        angular_acceleration: [0.0; 3],
        temperature_c: None,
    }
}

/// Configures `chip` in source model, sends `pieces`, 25 kinematics at 250 Hz and Start, and
/// returns the 100 images served at 1 kHz and every Error.
fn serve(chip: ChipModel, pieces: &[AddVibration]) -> (Vec<Image>, Vec<(ErrorCode, u32)>) {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.configure(&mut dev, model_configure(chip));
    for p in pieces {
        host.send(&mut dev, &Message::AddVibration(p.clone()), 0);
    }
    let sent: Vec<Truth> = (0..25).map(truth).collect();
    host.send(
        &mut dev,
        &Message::Kinematics(KinematicsBatch::new(0, &sent)),
        0,
    );
    host.start(&mut dev, 0, 0);
    let mut out = Vec::new();
    let mut images = Vec::new();
    for k in 0..100u64 {
        out.extend(poll(&mut dev, k * MS));
        images.push(dev.last_served().unwrap().image.unwrap());
    }
    (images, errors(&out))
}

/// The host's prediction of [`serve`] with the chain `setup` describes.
fn predict(chip: ChipModel, setup: &ChainSetup) -> Vec<Image> {
    let cfg = model_configure(chip);
    let p = params();
    let chip = setup::build_chip(&cfg).unwrap();
    let mut model = DeviceModel::new(&p.marg, cfg.rate, SEED, &chip, setup).unwrap();
    (0..100u64)
        .map(|k| {
            let t = truth(k / 4);
            setup::model_image(&mut model, k * MS, &t, p.mag_ut_per_unit, &chip)
        })
        .collect()
}

#[test]
fn the_device_serves_the_chain_its_vibration_messages_describe() {
    let rate = Rate::hz(1000).unwrap();
    for chip in [ChipModel::Icm20602, ChipModel::Bmi088] {
        let internal = ChainConfig::default_for(chip, rate).unwrap();
        for path in [None, Some(internal)] {
            let pieces = [AddVibration::Path(path), tones(4), shock()];
            let mut setup = ChainSetup::default();
            for p in &pieces {
                assert!(setup.add(p));
            }
            assert_eq!(setup.messages().collect::<Vec<_>>(), pieces);
            let (served, errors) = serve(chip, &pieces);
            assert_eq!(errors, [], "{chip:?} {path:?}");
            assert_eq!(served, predict(chip, &setup), "{chip:?} {path:?}");
            let (quiet, _) = serve(chip, &[]);
            assert_eq!(quiet, predict(chip, &ChainSetup::default()));
            let differ = served.iter().zip(&quiet).filter(|(a, b)| a != b).count();
            assert!(
                differ > 90,
                "{chip:?} {path:?}: the vibration shows ({differ})"
            );
        }
    }
}

#[test]
fn what_the_device_cannot_hold_is_refused_and_leaves_the_chain_as_it_was() {
    let rate = Rate::hz(1000).unwrap();
    let wrong_family = ChainConfig::default_for(ChipModel::Bmi088, rate).unwrap();
    let mut too_many = vec![tones(1); MAX_TONE_SOURCES];
    too_many.push(tones(2)); // one source too many
    too_many.push(tones(0)); // no motors
    too_many.push(AddVibration::Path(Some(wrong_family)));
    let (served, errs) = serve(ChipModel::Icm20602, &too_many);
    let refused = (ErrorCode::InvalidConfig, VIBRATION_REFUSED);
    assert_eq!(errs, [refused; 3]);
    let mut setup = ChainSetup::default();
    for p in &too_many[..MAX_TONE_SOURCES] {
        assert!(setup.add(p));
    }
    assert_eq!(served, predict(ChipModel::Icm20602, &setup));
}

#[test]
fn vibration_is_refused_before_configure_in_source_images_and_while_running() {
    let mut dev = Dev::new();
    let mut host = Host::new();
    host.hello(&mut dev, 1);
    host.send(&mut dev, &Message::AddVibration(shock()), 0);
    let out = poll(&mut dev, 0);
    assert_eq!(errors(&out), [(ErrorCode::NotConfigured, 0)]);

    let (mut dev, mut host) = configured();
    host.send(&mut dev, &Message::AddVibration(shock()), 0);
    let out = poll(&mut dev, 0);
    let images = (ErrorCode::UnsupportedMode, VIBRATION_IN_IMAGES);
    assert_eq!(errors(&out), [images]);

    host.configure(&mut dev, model_configure(ChipModel::Icm20602));
    host.start(&mut dev, 0, 0);
    host.send(&mut dev, &Message::AddVibration(shock()), 0);
    let out = poll(&mut dev, 0);
    let running = (ErrorCode::InvalidConfig, DeviceState::Running as u32);
    assert_eq!(errors(&out), [running]);
}
