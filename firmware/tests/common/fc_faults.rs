//! The chip faults (`Chip::fault_*` hooks) as the 6xxx flight-controller sequences of [`fc`]
//! meet them: ArduPilot's periodic read-back of its configured registers
//! (`AP_InertialSensor_Invensense.cpp` with the HAL's `check_next_register`: one checked
//! register re-read per poll) notices a reset, and the driver recovers by initialising again.

use super::fc::{ardupilot_init, ardupilot_poll, ArduPilotOptions, Board, FcError, Record};

/// What an ArduPilot-style run with read-back saw.
#[derive(Clone, Debug, Default)]
pub struct CheckedRun {
    /// The records each poll decoded, by poll.
    pub records: Vec<(usize, Record)>,
    /// The polls whose read-back did not match (the driver initialised again after each).
    pub mismatches: Vec<usize>,
}

/// ArduPilot's init for a part answering `who_am_i`, then `polls` FIFO reads 1 ms apart, each
/// followed by the read-back of the next checked register; on a mismatch the driver
/// initialises again. `before_poll(board, poll)` runs before each poll (to inject a fault).
pub fn ardupilot_checked<B: Board>(
    board: &mut B,
    polls: usize,
    who_am_i: u8,
    before_poll: &mut dyn FnMut(&mut B, usize),
) -> Result<CheckedRun, FcError> {
    let options = ArduPilotOptions::default();
    let mut driver = ardupilot_init(board, options, who_am_i)?;
    board.loop_starts();
    let mut out = CheckedRun::default();
    let mut next = 0;
    for poll in 0..polls {
        before_poll(board, poll);
        board.wait_ns(1_000_000);
        let mut run = super::fc::FcRun::default();
        ardupilot_poll(board, &mut driver, &mut run);
        out.records
            .extend(run.records.into_iter().map(|r| (poll, r)));
        let (reg, value) = driver.checked[next % driver.checked.len()];
        next += 1;
        if super::spi_read(board.chip(), reg, 1)[0] != value {
            out.mismatches.push(poll);
            driver = ardupilot_init(board, options, who_am_i)?;
            next = 0;
        }
    }
    Ok(out)
}

/// Checks `records` are consecutive samples from the first one converted at ±16 g on
/// (ACCEL_XOUT = GYRO_XOUT = the sample number, 1 g, as [`super::numbered`] makes them at
/// 1 kHz; the first few records after an initialisation carry the reset full scales, as in
/// `fc_ardupilot`'s own tests); returns the first sample number.
pub fn assert_consecutive(records: &[&Record]) -> i16 {
    let start = records.iter().position(|r| r.accel_z == 2048).unwrap();
    assert!(start <= 4, "{start} records before the full scales");
    let first = records[start].gyro_x;
    for (i, r) in records[start..].iter().enumerate() {
        let k = first + i as i16;
        assert_eq!((r.gyro_x, r.accel_x, r.accel_z), (k, k, 2048), "record {i}");
    }
    first
}
