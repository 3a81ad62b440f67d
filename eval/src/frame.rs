//! Named world frames at the edges: `--frame nwu|enu|ned` on `filter` and `evaluate --external`
//! converts a recording's vectors and quaternions once, as they are read, into margemu's own
//! frames, and the estimates back as they are written. The frames and their maps are
//! [`margemu_sim::frame`]'s (the one home of the NED map, which the MAVLink readers use too).
//!
//! What is converted: the IMU columns (body vectors, `ned` only), the reference and estimate
//! quaternions (body to world), the magnetic reference given with `--mag-reference` (a world
//! vector), and, when writing, the estimates (back into the named frame, their Euler angles
//! taken in it). The Euler angles of `errors.csv` and the figures are margemu's (NWU, ZYX).

pub use margemu_sim::frame::Frame;
