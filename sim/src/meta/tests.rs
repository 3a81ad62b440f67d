use super::*;
use crate::rundir::Status;
use crate::scene::Scene;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-meta-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn completion() -> Completion {
    Completion {
        status: Status::Interrupted,
        samples_written: 12,
        samples_expected: Some(40),
        ended: "interrupted".into(),
    }
}

fn session() -> SessionMeta {
    let scene = Scene::parse_str(
        "duration = 0.2\nrate = 200.0\nseed = 1\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let run = crate::run::metadata(&scene);
    SessionMeta {
        margemu_version: run.margemu_version,
        protocol_version: margemu_protocol::PROTOCOL_VERSION,
        scene_file: run.scene_file,
        scene_sha256: run.scene_sha256,
        seed: run.seed,
        samples: run.samples,
        duration_s: run.duration_s,
        rate_hz: run.rate_hz,
        rate_num: 200,
        rate_den: 1,
        port: "/dev/pts/9".into(),
        baud: 921_600,
        source: "model".into(),
        kinematics_hold: Some(4),
        kinematics_rate_hz: Some(50.0),
        lead_ns: 200_000_000,
        batch: 32,
        telemetry_period_ns: 20_000_000,
        session_id: 7,
        field_unit: run.field_unit,
        mag_ut_per_unit: 50.0,
        default_temp_c: 21.5,
        chip: ChipMeta {
            model: "icm42688p".into(),
            who_am_i: 0x47,
            bus: "spi".into(),
            i2c_address: 0x68,
            image_len: 14,
            accel_range_g: Some(8.0),
            gyro_range_dps: Some(1000.0),
            mag_range_gauss: None,
            rotation: Some([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            name: Some("imu".into()),
            chip_select: Some(0),
            offset: None,
            filters: Some([("gyro_aaf_delt".to_string(), 6u8)].into_iter().collect()),
            sampling_path: Some("internal".into()),
        },
        other_devices: vec![ChipMeta {
            model: "ist8310".into(),
            who_am_i: 0x10,
            bus: "i2c".into(),
            i2c_address: 0x0E,
            image_len: 6,
            accel_range_g: None,
            gyro_range_dps: None,
            mag_range_gauss: None,
            rotation: None,
            name: Some("compass".into()),
            chip_select: None,
            offset: Some([0.0, 0.0, 0.03]),
            filters: None,
            sampling_path: None,
        }],
        image: None,
        scene_text: run.scene_text,
        device: None,
        dut: None,
        completion: None,
    }
}

#[test]
fn a_run_reads_back_as_written_before_and_after_its_completion_record() {
    let dir = scratch("run");
    let scene = Scene::parse_str(
        "duration = 0.2\nrate = 200.0\nseed = 9\nmotion = \"bench\"\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let mut meta = crate::run::metadata(&scene);
    write(&dir, &meta).unwrap();
    let read_back = |dir: &Path| match read(dir).unwrap() {
        MetaFile::Run(m) => *m,
        other => panic!("not a run: {other:?}"),
    };
    assert_eq!(read_back(&dir), meta);
    assert_eq!((meta.seed, meta.samples, meta.pid.len()), (9, 40, 6));
    crate::rundir::write_completion(&dir, &completion()).unwrap();
    meta.completion = Some(completion());
    assert_eq!(read_back(&dir), meta);
    assert_eq!(read(&dir).unwrap().completion(), Some(&completion()));
}

#[test]
fn a_session_reads_back_as_written_at_every_stage() {
    let dir = scratch("session");
    let mut meta = session();
    write(&dir, &meta).unwrap();
    let read_back = |dir: &Path| match read(dir).unwrap() {
        MetaFile::Session(m) => *m,
        other => panic!("not a session: {other:?}"),
    };
    assert_eq!(read_back(&dir), meta);
    let device = DeviceMeta {
        protocol_version: 3,
        firmware: "1.2.3".into(),
        device_id: "00ff".into(),
        chips: 31,
        modes: 3,
        buses: 1,
        max_batch: 108,
        buffer_capacity: 4096,
    };
    append(&dir, Appended::Device(&device)).unwrap();
    meta.device = Some(device);
    assert_eq!(read_back(&dir), meta);
    let dut = DutMeta {
        protocol: "mavlink".into(),
        messages: 3,
        attitude_rows: 2,
        imu_rows: 0,
        bytes: 99,
        bad_bytes: 1,
        bad_frames: 0,
        unknown_ids: 0,
        undecoded: 0,
        requests_sent: 0,
        end: "disconnected (the port said \"gone\" \\ closed)".into(),
        per_message: [("ATTITUDE".to_string(), 2), ("HEARTBEAT".to_string(), 1)].into(),
    };
    append(&dir, Appended::Dut(&dut)).unwrap();
    meta.dut = Some(dut);
    assert_eq!(read_back(&dir), meta);
    crate::rundir::write_completion(&dir, &completion()).unwrap();
    meta.completion = Some(completion());
    assert_eq!(read_back(&dir), meta);
    assert_eq!(
        read(&dir).unwrap().session().unwrap().chip.model,
        "icm42688p"
    );
}

#[test]
fn appended_tables_keep_their_layout() {
    let text = Appended::Completion(&completion()).to_toml();
    assert_eq!(
        text,
        "\n[completion]\nstatus = \"interrupted\"\nsamples_written = 12\nsamples_expected = 40\nended = \"interrupted\"\n"
    );
}

#[test]
fn a_file_without_margemu_version_is_foreign() {
    let dir = scratch("foreign");
    std::fs::write(
        dir.join(META_FILE),
        "start_host_ns = 42\nnotes = \"mine\"\n",
    )
    .unwrap();
    let meta = read(&dir).unwrap();
    assert_eq!(
        meta,
        MetaFile::Foreign(ForeignMeta {
            start_host_ns: Some(42)
        })
    );
    assert_eq!((meta.completion(), meta.scene_text()), (None, None));
}

#[test]
fn a_bad_field_is_named_with_its_line() {
    let dir = scratch("bad");
    let mut text = to_toml(&session());
    text = text.replacen("baud = 921600", "baud = \"fast\"", 1);
    std::fs::write(dir.join(META_FILE), text).unwrap();
    let e = read(&dir).unwrap_err().to_string();
    assert!(e.contains("meta.toml: TOML parse error at line 12"), "{e}");
    assert!(e.contains("baud"), "{e}");
    let missing = "margemu_version = \"0\"\n";
    std::fs::write(dir.join(META_FILE), missing).unwrap();
    let e = read(&dir).unwrap_err().to_string();
    assert!(e.contains("missing field"), "{e}");
}
