//! The ROS 2 message types margemu writes, as `ros2msg` schema text: each type's definition,
//! then every type it depends on, each after a line of 80 `=` and a `MSG: package/Type` line,
//! the layout rosbag2's MCAP storage plugin writes (`rosbag2_storage_mcap`,
//! `LocalMessageDefinitionSource`), so Foxglove, `ros2 bag` and the MCAP libraries decode them.
//! The definitions are those of ROS 2's `common_interfaces` and `rcl_interfaces` packages
//! without their comments and default values (neither changes the encoding); every field type
//! is written with its package, as the parsers resolve no implicit package.

/// One ROS 2 message type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MsgType {
    /// Its name, `package/msg/Type`.
    pub name: &'static str,
    /// Its own definition.
    definition: &'static str,
    /// The types it uses, each once, in the order they are appended.
    deps: &'static [&'static MsgType],
}

impl MsgType {
    /// The `ros2msg` schema text: the definition and every dependency's.
    pub fn schema_text(&self) -> String {
        let mut text = self.definition.to_string();
        for dep in self.deps {
            text.push('\n');
            text.push_str(&"=".repeat(80));
            text.push_str("\nMSG: ");
            text.push_str(&dep.name.replace("/msg/", "/"));
            text.push('\n');
            text.push_str(dep.definition);
        }
        text
    }
}

const fn leaf(name: &'static str, definition: &'static str) -> MsgType {
    MsgType {
        name,
        definition,
        deps: &[],
    }
}

/// `builtin_interfaces/msg/Time`.
pub const TIME: MsgType = leaf("builtin_interfaces/msg/Time", "int32 sec\nuint32 nanosec\n");
/// `std_msgs/msg/Header`.
pub const HEADER: MsgType = MsgType {
    name: "std_msgs/msg/Header",
    definition: "builtin_interfaces/Time stamp\nstring frame_id\n",
    deps: &[&TIME],
};
/// `geometry_msgs/msg/Point`.
pub const POINT: MsgType = leaf(
    "geometry_msgs/msg/Point",
    "float64 x\nfloat64 y\nfloat64 z\n",
);
/// `geometry_msgs/msg/Vector3`.
pub const VECTOR3: MsgType = leaf(
    "geometry_msgs/msg/Vector3",
    "float64 x\nfloat64 y\nfloat64 z\n",
);
/// `geometry_msgs/msg/Quaternion`.
pub const QUATERNION: MsgType = leaf(
    "geometry_msgs/msg/Quaternion",
    "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
);
/// `geometry_msgs/msg/Pose`.
pub const POSE: MsgType = MsgType {
    name: "geometry_msgs/msg/Pose",
    definition: "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    deps: &[&POINT, &QUATERNION],
};
/// `geometry_msgs/msg/PoseStamped`.
pub const POSE_STAMPED: MsgType = MsgType {
    name: "geometry_msgs/msg/PoseStamped",
    definition: "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
    deps: &[&HEADER, &TIME, &POSE, &POINT, &QUATERNION],
};
/// `geometry_msgs/msg/Twist`.
pub const TWIST: MsgType = MsgType {
    name: "geometry_msgs/msg/Twist",
    definition: "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n",
    deps: &[&VECTOR3],
};
/// `geometry_msgs/msg/TwistStamped`.
pub const TWIST_STAMPED: MsgType = MsgType {
    name: "geometry_msgs/msg/TwistStamped",
    definition: "std_msgs/Header header\ngeometry_msgs/Twist twist\n",
    deps: &[&HEADER, &TIME, &TWIST, &VECTOR3],
};
/// `sensor_msgs/msg/Imu`.
pub const IMU: MsgType = MsgType {
    name: "sensor_msgs/msg/Imu",
    definition: "std_msgs/Header header\n\
geometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n\
geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n\
geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
    deps: &[&HEADER, &TIME, &QUATERNION, &VECTOR3],
};
/// `sensor_msgs/msg/MagneticField`.
pub const MAGNETIC_FIELD: MsgType = MsgType {
    name: "sensor_msgs/msg/MagneticField",
    definition: "std_msgs/Header header\ngeometry_msgs/Vector3 magnetic_field\n\
float64[9] magnetic_field_covariance\n",
    deps: &[&HEADER, &TIME, &VECTOR3],
};
/// `std_msgs/msg/String`.
pub const STRING: MsgType = leaf("std_msgs/msg/String", "string data\n");
/// `geometry_msgs/msg/Transform`.
pub const TRANSFORM: MsgType = MsgType {
    name: "geometry_msgs/msg/Transform",
    definition: "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
    deps: &[&VECTOR3, &QUATERNION],
};
/// `geometry_msgs/msg/TransformStamped`.
pub const TRANSFORM_STAMPED: MsgType = MsgType {
    name: "geometry_msgs/msg/TransformStamped",
    definition:
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
    deps: &[&HEADER, &TIME, &TRANSFORM, &VECTOR3, &QUATERNION],
};
/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: MsgType = MsgType {
    name: "tf2_msgs/msg/TFMessage",
    definition: "geometry_msgs/TransformStamped[] transforms\n",
    deps: &[
        &TRANSFORM_STAMPED,
        &HEADER,
        &TIME,
        &TRANSFORM,
        &VECTOR3,
        &QUATERNION,
    ],
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dependencies_follow_separators_with_their_short_names() {
        let text = POSE_STAMPED.schema_text();
        let sep = format!("\n{}\n", "=".repeat(80));
        let parts: Vec<&str> = text.split(&sep).collect();
        assert_eq!(parts.len(), 6);
        assert_eq!(
            parts[0],
            "std_msgs/Header header\ngeometry_msgs/Pose pose\n"
        );
        assert!(
            parts[1].starts_with("MSG: std_msgs/Header\n"),
            "{}",
            parts[1]
        );
    }

    #[test]
    fn every_used_type_is_defined_in_the_text() {
        for t in [
            POSE_STAMPED,
            TWIST_STAMPED,
            IMU,
            MAGNETIC_FIELD,
            STRING,
            TF_MESSAGE,
        ] {
            let text = t.schema_text();
            for line in text
                .lines()
                .filter(|l| l.contains('/') && !l.starts_with("MSG:"))
            {
                let ty = line.split([' ', '[']).next().unwrap();
                assert!(text.contains(&format!("MSG: {ty}\n")), "{}: {ty}", t.name);
            }
        }
    }
}
