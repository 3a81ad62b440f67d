//! Fault windows in `events.csv`: the one format of a `fault` row, its writer and its parser.
//!
//! `events.csv` (`host_ns,event,detail`, [`EVENTS_COLUMNS`]) lists every window of the scene's
//! `[[fault]]` schedule as one row with `event` = [`FAULT_EVENT`], in schedule order, before
//! anything else happens: a streaming session writes them when it starts (at `host_ns` 0),
//! `simulate` writes them (at `host_ns` 0) into its run directory's `events.csv`, which it
//! writes only for a scene with faults. The detail is
//!
//! `device=<name>;kind=<kind>;sensor=<accel|gyro|mag|->;start_ns=<n>;end_ns=<n|until_end>`
//!
//! with the device's name ([`crate::scene::Scene::devices`]), the kind's name
//! ([`margemu_model::fault::FaultKind::name`]) and the window in scene time (ns).
//!
//! ```
//! use margemu_sim::fault_log::{detail, parse_detail, FaultRow};
//! use margemu_model::fault::{Fault, FaultKind, Sensor, Window, UNTIL_END};
//! let f = Fault::new(0, Window::new(1_000, UNTIL_END), FaultKind::Stuck { sensor: Sensor::Gyr });
//! let text = detail(&f, "imu");
//! assert_eq!(text, "device=imu;kind=stuck;sensor=gyro;start_ns=1000;end_ns=until_end");
//! assert_eq!(parse_detail(&text).unwrap(), FaultRow {
//!     device: "imu".into(), kind: "stuck".into(), sensor: Some(Sensor::Gyr),
//!     start_ns: 1_000, end_ns: None,
//! });
//! ```

use crate::scene::Scene;
use margemu_model::fault::{Fault, Sensor, UNTIL_END};
use std::io::{self, Write};
use std::path::Path;

/// `events.csv`.
pub const EVENTS_FILE: &str = "events.csv";

/// Header of `events.csv`.
pub const EVENTS_COLUMNS: &str = "host_ns,event,detail";

/// The `event` of a fault window's row.
pub const FAULT_EVENT: &str = "fault";

/// One fault window as `events.csv` lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaultRow {
    /// The device's name.
    pub device: String,
    /// The kind's name.
    pub kind: String,
    /// The sensor of a sensor fault.
    pub sensor: Option<Sensor>,
    /// First instant inside, ns of scene time.
    pub start_ns: u64,
    /// First instant after, ns; `None`: until the end of the run.
    pub end_ns: Option<u64>,
}

/// The detail of `fault`'s row, on the device called `device`.
pub fn detail(fault: &Fault, device: &str) -> String {
    let sensor = fault.kind.sensor().map_or("-", Sensor::name);
    let end = match fault.window.end_ns {
        UNTIL_END => "until_end".to_owned(),
        ns => ns.to_string(),
    };
    format!(
        "device={device};kind={};sensor={sensor};start_ns={};end_ns={end}",
        fault.kind.name(),
        fault.window.start_ns
    )
}

/// The details of every fault of `scene`, in schedule order.
pub fn details(scene: &Scene) -> Vec<String> {
    let devices = scene.devices();
    scene
        .faults
        .iter()
        .map(|f| {
            let name = devices
                .get(usize::from(f.device))
                .map_or("?", |d| d.name.as_str());
            detail(f, name)
        })
        .collect()
}

/// The window a row's detail names, or why it is not a fault detail.
pub fn parse_detail(text: &str) -> Result<FaultRow, String> {
    let mut fields = text.split(';');
    let mut next = |key: &str| -> Result<&str, String> {
        fields
            .next()
            .and_then(|f| f.strip_prefix(key)?.strip_prefix('='))
            .ok_or_else(|| format!("a fault row's detail needs `{key}=` next, in {text:?}"))
    };
    let device = next("device")?.to_owned();
    let kind = next("kind")?.to_owned();
    let sensor = match next("sensor")? {
        "-" => None,
        name => Some(
            Sensor::ALL
                .into_iter()
                .find(|s| s.name() == name)
                .ok_or_else(|| format!("unknown sensor `{name}` in {text:?}"))?,
        ),
    };
    let number = |s: &str| {
        s.parse::<u64>()
            .map_err(|_| format!("`{s}` is not a time in ns in {text:?}"))
    };
    let start_ns = number(next("start_ns")?)?;
    let end_ns = match next("end_ns")? {
        "until_end" => None,
        s => Some(number(s)?),
    };
    Ok(FaultRow {
        device,
        kind,
        sensor,
        start_ns,
        end_ns,
    })
}

/// Writes the rows of `details` at `host_ns` 0 (the detail has no commas).
pub fn write_rows(out: &mut impl Write, details: &[String]) -> io::Result<()> {
    for d in details {
        writeln!(out, "0,{FAULT_EVENT},{d}")?;
    }
    Ok(())
}

/// `simulate`'s `events.csv` in `dir`: the header and the fault rows; nothing for a scene
/// without faults.
pub fn write_run_events(dir: &Path, scene: &Scene) -> io::Result<()> {
    if scene.faults.is_empty() {
        return Ok(());
    }
    let mut out = io::BufWriter::new(std::fs::File::create(dir.join(EVENTS_FILE))?);
    writeln!(out, "{EVENTS_COLUMNS}")?;
    write_rows(&mut out, &details(scene))?;
    out.flush()
}

/// The fault windows of an `events.csv` text (other rows are skipped); a malformed fault row
/// is an error naming its line.
pub fn read_rows(text: &str) -> Result<Vec<FaultRow>, String> {
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        let mut cells = line.splitn(3, ',');
        let (_, event, detail) = (cells.next(), cells.next(), cells.next());
        if event == Some(FAULT_EVENT) {
            let row = parse_detail(detail.unwrap_or_default())
                .map_err(|e| format!("line {}: {e}", n + 1))?;
            rows.push(row);
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_model::fault::{FaultKind, Window};

    #[test]
    fn rows_round_trip_and_bad_ones_are_named() {
        let f = Fault::new(1, Window::new(5, 10), FaultKind::Nak);
        let mut text = format!("{EVENTS_COLUMNS}\n12,start,x\n");
        let mut bytes = Vec::new();
        write_rows(&mut bytes, &[detail(&f, "compass")]).unwrap();
        text.push_str(std::str::from_utf8(&bytes).unwrap());
        let rows = read_rows(&text).unwrap();
        assert_eq!(
            rows,
            [FaultRow {
                device: "compass".into(),
                kind: "nak".into(),
                sensor: None,
                start_ns: 5,
                end_ns: Some(10)
            }]
        );
        let e = read_rows("h\n0,fault,device=a;kind=nak;sensor=-;start_ns=x;end_ns=1\n");
        assert!(e.unwrap_err().starts_with("line 2: `x` is not a time"));
        assert!(parse_detail("kind=nak").is_err());
    }
}
