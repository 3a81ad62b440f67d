//! Sensor faults in the host's model: what `MargSim` gives inside a window is what the fault
//! defines, outside it the fault-free run's bytes; a scene without sensor faults is unchanged.

use margemu_sim::marg::{MargSample, MargSim, MargWriter};
use margemu_sim::scene::Scene;
use std::path::Path;

/// A moving bench with noise, so consecutive samples differ.
const BASE: &str = "duration = 1.0\nrate = 200.0\nseed = 5\nmotion = \"kinematic\"\n\
    [joints.yaw]\ntype = \"sine\"\namplitude = 0.5\nfrequency = 1.0\n\
    [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n[sensors.accel]\nnoise_density = [0.01, 0.01, 0.01]\n\
    [sensors.mag]\nnoise_density = [0.001, 0.001, 0.001]\n";

fn samples(text: &str) -> Vec<MargSample> {
    let scene = Scene::parse_str(text, Path::new("faults.toml")).unwrap();
    let mut marg = MargSim::new(&scene).unwrap();
    let mut out = Vec::new();
    margemu_sim::run::run(
        &scene,
        |t| -> Result<(), ()> {
            out.push(marg.try_sample(&scene, t).unwrap());
            Ok(())
        },
        |_, _| {},
    )
    .unwrap()
    .unwrap();
    out
}

fn csv(samples: &[MargSample]) -> Vec<String> {
    let mut bytes = Vec::new();
    let mut w = MargWriter::new(&mut bytes, None).unwrap();
    for s in samples {
        w.write(s).unwrap();
    }
    w.finish().unwrap();
    String::from_utf8(bytes)
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect()
}

/// The window [0.25 s, 0.5 s): samples 50 to 99 at 200 Hz.
const INSIDE: std::ops::Range<usize> = 50..100;

fn with_fault(table: &str) -> Vec<MargSample> {
    samples(&format!(
        "{BASE}[[fault]]\n{table}\nstart = 0.25\nduration = 0.25\n"
    ))
}

#[test]
fn a_scene_without_sensor_faults_gives_the_same_bytes() {
    let clean = csv(&samples(BASE));
    // A chip fault is not the model's: the samples are those of the fault-free run.
    assert_eq!(csv(&with_fault("kind = \"nak\"")), clean);
    assert_eq!(clean.len(), 201);
}

#[test]
fn stuck_holds_the_last_value_inside_the_window_only() {
    let clean = samples(BASE);
    let got = with_fault("kind = \"stuck\"\nsensor = \"gyro\"");
    let held = clean[INSIDE.start - 1].sample.gyr;
    for k in 0..clean.len() {
        if INSIDE.contains(&k) {
            assert_eq!(got[k].sample.gyr, held, "sample {k}");
            assert_ne!(clean[k].sample.gyr, held, "sample {k}");
            assert_eq!(got[k].sample.acc, clean[k].sample.acc);
        } else {
            assert_eq!(got[k], clean[k], "sample {k}");
        }
    }
}

#[test]
fn bias_and_scale_change_the_value_by_what_they_say() {
    let clean = samples(BASE);
    let biased = with_fault("kind = \"bias_step\"\nsensor = \"accel\"\nbias = [1.0, 0.0, -2.0]");
    let scaled = with_fault("kind = \"scale\"\nsensor = \"mag\"\nfactor = 2.0");
    for k in 0..clean.len() {
        let (c, b, s) = (clean[k].sample, biased[k].sample, scaled[k].sample);
        if INSIDE.contains(&k) {
            assert_eq!(b.acc, [c.acc[0] + 1.0, c.acc[1], c.acc[2] - 2.0]);
            assert_eq!(s.mag, c.mag.map(|x| x * 2.0));
        } else {
            assert_eq!((b, s), (c, c), "sample {k}");
        }
    }
}

#[test]
fn dropout_writes_nan_and_names_the_sensor() {
    let clean = samples(BASE);
    let got = with_fault("kind = \"dropout\"\nsensor = \"accel\"");
    let (clean_rows, rows) = (csv(&clean), csv(&got));
    for k in 0..clean.len() {
        // Row 0 is the header.
        if INSIDE.contains(&k) {
            assert_eq!(got[k].dropout, 1, "sample {k}");
            let cells: Vec<_> = rows[k + 1].split(',').collect();
            assert_eq!(&cells[1..4], ["NaN"; 3]);
            let clean_cells: Vec<_> = clean_rows[k + 1].split(',').collect();
            assert_eq!(cells[4..], clean_cells[4..]);
        } else {
            assert_eq!(got[k].dropout, 0);
            assert_eq!(rows[k + 1], clean_rows[k + 1], "sample {k}");
        }
    }
}

#[test]
fn noise_and_spikes_are_seeded() {
    let noise = "kind = \"noise\"\nsensor = \"gyro\"\nstd = 0.5";
    assert_eq!(csv(&with_fault(noise)), csv(&with_fault(noise)));
    let spikes =
        "kind = \"spikes\"\nsensor = \"gyro\"\nrate = 40.0\namplitude = 10.0\naxes = \"z\"";
    let clean = samples(BASE);
    let got = with_fault(spikes);
    let spiked = INSIDE
        .filter(|&k| (got[k].sample.gyr[2] - clean[k].sample.gyr[2]).abs() == 10.0)
        .count();
    // 0.25 s at 40 Hz: 10 expected.
    assert!((2..=25).contains(&spiked), "{spiked}");
    assert_eq!(csv(&got), csv(&with_fault(spikes)));
}

fn run_dir(tag: &str, text: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-faults-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scene = Scene::parse_str(text, Path::new("faults.toml")).unwrap();
    let stop = std::sync::atomic::AtomicBool::new(false);
    margemu_sim::run::simulate_to_dir(&scene, &dir, &stop, |_, _| {}).unwrap();
    dir
}

#[test]
fn simulate_lists_the_fault_windows_in_events_csv() {
    use margemu_sim::fault_log::{read_rows, FaultRow, EVENTS_FILE};
    let text = format!(
        "{BASE}[[fault]]\nkind = \"stuck\"\nsensor = \"gyro\"\nstart = 0.25\nduration = 0.25\n\
         [[fault]]\nkind = \"reset\"\nstart = 0.5\nuntil_end = true\n"
    );
    let dir = run_dir("events", &text);
    let events = std::fs::read_to_string(dir.join(EVENTS_FILE)).unwrap();
    assert!(
        events.starts_with("host_ns,event,detail\n0,fault,device=mpu9250;kind=stuck;"),
        "{events}"
    );
    assert_eq!(
        read_rows(&events).unwrap(),
        [
            FaultRow {
                device: "mpu9250".into(),
                kind: "stuck".into(),
                sensor: Some(margemu_model::fault::Sensor::Gyr),
                start_ns: 250_000_000,
                end_ns: Some(500_000_000),
            },
            FaultRow {
                device: "mpu9250".into(),
                kind: "reset".into(),
                sensor: None,
                start_ns: 500_000_000,
                end_ns: None,
            },
        ]
    );
    let _ = std::fs::remove_dir_all(&dir);
    // A scene without faults: no events.csv, the run directory as before.
    let clean = run_dir("clean", BASE);
    assert!(!clean.join(EVENTS_FILE).exists());
    let _ = std::fs::remove_dir_all(&clean);
}
