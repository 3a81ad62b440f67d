//! The CSV files `simulate` writes for the shipped scenes, pinned by their SHA-256: the digests
//! were computed from the files of the writer that came before [`margemu_sim::csv_row`] (ryu
//! for every float, `write!` for the time stamps), so any change of a byte in any row, header or
//! line end of these files fails here. A change of the dynamics or the sensor model that moves
//! a sample moves them too; then the new digests belong in the same commit, with the reason.

use margemu_sim::run::simulate_to_dir;
use margemu_sim::scene::Scene;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// `(scene, file, SHA-256 of the file)`.
const GOLDEN: [(&str, &str, &str); 19] = [
    (
        "bmi270",
        "marg.csv",
        "611b3d8fe3b27eebd7528d173df0b88db1f3598311dd2337acc2525013db2e1a",
    ),
    (
        "bmi270",
        "truth.csv",
        "10d8e01bb8dc43f32dd18885ac83920ab875d3e0f98cc5b6a3055ebb46c3fb37",
    ),
    (
        "case-study",
        "marg.csv",
        "7c24ac6fe4d00db190b5473c7fb77eaf1df92f9073d0948105b328579644f55e",
    ),
    (
        "case-study",
        "perturbation.csv",
        "c99af055688225c1aa02e194ebe3eb3287f8b55c07a1e29034b3a358cc554d00",
    ),
    (
        "case-study",
        "truth.csv",
        "40ad653f3242a50618d52e52bb04724e3cb0a52adedfa99edb90e35204067426",
    ),
    (
        "figure3",
        "marg.csv",
        "8a23c87d981eb0e11c638c302b9274e0d252564f77ecf2eefd0954a99ddd5f13",
    ),
    (
        "figure3",
        "truth.csv",
        "998625d4b009627c335d8a0fe5a0688a5bdc4b856773d6b3605a39feefa74cd6",
    ),
    (
        "gimbal-lock",
        "marg.csv",
        "ab184ad78d74cc7d79ff50d03eb53d7a2365681f5acbc12b034dc514afa2f34e",
    ),
    (
        "gimbal-lock",
        "truth.csv",
        "289054adc12ce742b79374fe6394919949605b4b88804d646e8fb4793de38f04",
    ),
    (
        "icm42688p",
        "marg.csv",
        "1c900b965d5663ed3dfdfb9ee7630baf2112b3f3a872478b18c8744a6528e08e",
    ),
    (
        "icm42688p",
        "truth.csv",
        "23b4b1834af02a5f7063cf508b3b8bd3a610b0e06e49c60d4f69d9684811b8e4",
    ),
    (
        "mpu6000",
        "marg.csv",
        "301bba7fa237da1cd222e293daa0f2b4cd8cf832d2807d43f73fe0ded2cb10f1",
    ),
    (
        "mpu6000",
        "truth.csv",
        "b0063c75c1e4547e7cdede254728fa37cbc4d3ec6743d0e568f3a2f940f3a206",
    ),
    (
        "rig",
        "marg.csv",
        "234dff5048aef8665b582088753313b358d263e794e1dcfb34625201ca7ae560",
    ),
    (
        "rig",
        "truth.csv",
        "513b5a41cf80fa77226dda413ebe1b7770b4cd649e5bb002b47bb7b6e5ca7f03",
    ),
    (
        "static",
        "marg.csv",
        "5558c17ad54e37ac4332fd1db9d3394206c9440588ebb18c08f06ece5c987c8b",
    ),
    (
        "static",
        "truth.csv",
        "9bb7370d4b8b34846372610b0060ede7962180dc8550b8adbff7df3a6d02ae0f",
    ),
    (
        "vibration",
        "marg.csv",
        "6f851a3646c4ba8b7a675afaff477d376559b24d2f174fa0bbd12eb4807801af",
    ),
    (
        "vibration",
        "truth.csv",
        "7493b413034e94ce2b55a810d0a14a02dbf8227d75fe3347d91c122b6672d082",
    ),
];

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-fixtures/scenes")
}

fn sha256(path: &Path) -> String {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn shipped_scenes_write_the_pinned_csv_bytes() {
    let root = std::env::temp_dir().join(format!("margemu-csv-golden-{}", std::process::id()));
    let mut scenes: Vec<&str> = GOLDEN.iter().map(|(scene, _, _)| *scene).collect();
    scenes.dedup();
    let mut wrong = Vec::new();
    for name in scenes {
        let scene = Scene::load(&scenes_dir().join(format!("{name}.toml"))).unwrap();
        let dir = root.join(name);
        simulate_to_dir(&scene, &dir, &AtomicBool::new(false), |_, _| {}).unwrap();
        for (_, file, want) in GOLDEN.iter().filter(|(s, _, _)| *s == name) {
            let got = sha256(&dir.join(file));
            if got != *want {
                wrong.push(format!("{name}/{file}: {got}"));
            }
        }
    }
    std::fs::remove_dir_all(&root).ok();
    assert!(wrong.is_empty(), "CSV bytes changed:\n{}", wrong.join("\n"));
}

#[test]
fn every_shipped_scene_is_pinned() {
    let mut shipped: Vec<String> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            name.strip_suffix(".toml").map(str::to_owned)
        })
        .collect();
    shipped.sort();
    let mut pinned: Vec<String> = GOLDEN.iter().map(|(s, _, _)| s.to_string()).collect();
    pinned.dedup();
    assert_eq!(shipped, pinned);
}
