//! Register maps of the emulated chips and the one place where physical values become register
//! values (see `docs/spec/mpu9250.md`).
