//! Shared by the `vfc_*` tests: the gentle motion every flight controller should follow.

/// Slow rotations on all three axes (a yaw swing of ±46° starting at 0.8·sin 0.6 = 25.9°),
/// light sensor noise, no perturbation, 200 Hz for 3 s: every filter should follow it to a
/// fraction of a degree.
pub const GENTLE: &str = "duration = 3.0\nrate = 200.0\nseed = 5\nmotion = \"kinematic\"\n\
    [joints.roll]\ntype = \"sine\"\namplitude = 0.4\nfrequency = 0.5\n\
    [joints.pitch]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 0.4\n\
    [joints.yaw]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 0.25\nphase = 0.6\n\
    [sensors.gyro]\nnoise_density = [0.002, 0.002, 0.002]\n\
    [sensors.accel]\nnoise_density = [0.005, 0.005, 0.005]\n\
    [sensors.mag]\nnoise_density = [0.001, 0.001, 0.001]\n";
