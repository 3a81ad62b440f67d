//! The Foxglove layout `hil-fixtures/foxglove/truth-vs-dut.json`: valid JSON, every panel the
//! layout tree places is configured, and every topic and frame it names is one margemu writes
//! ([`margemu::mcap`]; the device topics of the default chip, `mpu9250`).

use margemu::mcap::{topic_name, DUT_FRAME, DUT_TOPIC, FIXED_TOPICS, PLATE_FRAME, WORLD_FRAME};
use serde_json::Value;
use std::collections::BTreeSet;

const LAYOUT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../hil-fixtures/foxglove/truth-vs-dut.json"
);

/// Every string in `v` (object keys too).
fn strings<'a>(v: &'a Value, out: &mut Vec<&'a str>) {
    match v {
        Value::String(s) => out.push(s),
        Value::Array(a) => a.iter().for_each(|v| strings(v, out)),
        Value::Object(o) => o.iter().for_each(|(k, v)| {
            out.push(k);
            strings(v, out);
        }),
        _ => {}
    }
}

/// The panel ids the layout tree places.
fn panels<'a>(v: &'a Value, out: &mut Vec<&'a str>) {
    match v {
        Value::String(id) => out.push(id),
        Value::Object(o) => ["first", "second"].iter().for_each(|k| panels(&o[*k], out)),
        other => panic!("not a layout node: {other}"),
    }
}

#[test]
fn the_layout_is_json_and_names_only_topics_and_frames_margemu_writes() {
    let text = std::fs::read_to_string(LAYOUT).unwrap();
    let layout: Value = serde_json::from_str(&text).expect("valid JSON");
    let configs = layout["configById"].as_object().expect("configById");
    let mut placed = Vec::new();
    panels(&layout["layout"], &mut placed);
    let placed: BTreeSet<&str> = placed.into_iter().collect();
    let configured: BTreeSet<&str> = configs.keys().map(String::as_str).collect();
    assert_eq!(placed, configured);

    let device = topic_name("mpu9250");
    let mut written: BTreeSet<String> = FIXED_TOPICS.iter().map(|t| t.to_string()).collect();
    written.insert(DUT_TOPIC.to_string());
    written.insert(format!("/{device}/imu"));
    written.insert(format!("/{device}/mag"));
    let frames = [WORLD_FRAME, PLATE_FRAME, DUT_FRAME].map(|f| format!("frame:{f}"));

    let mut all = Vec::new();
    strings(&layout, &mut all);
    let mut topics = BTreeSet::new();
    for s in all {
        if let Some(path) = s.strip_prefix('/') {
            // A message path: the topic, then `.field` and `.@function`s.
            let topic = format!("/{}", path.split('.').next().unwrap());
            assert!(
                written.contains(&topic),
                "{s}: {topic} is not a topic margemu writes"
            );
            topics.insert(topic);
        }
        if s.starts_with("frame:") {
            assert!(
                frames.contains(&s.to_string()),
                "{s}: not a frame margemu writes"
            );
        }
    }
    for needed in ["/truth/pose", DUT_TOPIC, "/events", "/tf"] {
        assert!(topics.contains(needed), "the layout shows no {needed}");
    }
}
