# Reads an MCAP file with two independent readers and prints every message, one per line,
# tab-separated: reader, topic, log time, publish time, header stamp (ns; "-" without a header),
# then the message's values (floats in repr, which round-trips) or its text.
# Used by tests/mcap_readers.rs: `python3 -c SCRIPT FILE`.
import sys

path = sys.argv[1]


def stamp(m):
    h = getattr(m, "header", None)
    return "-" if h is None else str(h.stamp.sec * 1_000_000_000 + h.stamp.nanosec)


def values(m):
    t = type(m).__name__.split("__")[-1]
    if t == "PoseStamped":
        p, q = m.pose.position, m.pose.orientation
        v = [p.x, p.y, p.z, q.x, q.y, q.z, q.w]
    elif t == "TwistStamped":
        a, b = m.twist.linear, m.twist.angular
        v = [a.x, a.y, a.z, b.x, b.y, b.z]
    elif t == "Imu":
        o, w, f = m.orientation, m.angular_velocity, m.linear_acceleration
        v = [o.x, o.y, o.z, o.w, w.x, w.y, w.z, f.x, f.y, f.z, m.orientation_covariance[0]]
    elif t == "MagneticField":
        b = m.magnetic_field
        v = [b.x, b.y, b.z]
    elif t == "TFMessage":
        (tr,) = m.transforms
        p, q = tr.transform.translation, tr.transform.rotation
        return [tr.header.frame_id + ">" + tr.child_frame_id] + [
            repr(float(x)) for x in [p.x, p.y, p.z, q.x, q.y, q.z, q.w]
        ]
    elif t == "String":
        return [m.data]
    else:
        raise SystemExit(f"unexpected type {t}")
    return [repr(float(x)) for x in v]


def frame(m):
    h = getattr(m, "header", None)
    return "-" if h is None else h.frame_id


out = []
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

with open(path, "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    for meta in reader.iter_metadata():
        for k, v in sorted(meta.metadata.items()):
            out.append("\t".join(["meta", meta.name, k, v]))
    for ch in reader.get_summary().channels.values():
        for k, v in sorted(ch.metadata.items()):
            out.append("\t".join(["chmeta", ch.topic, k, v]))
    for _, ch, msg, m in reader.iter_decoded_messages(log_time_order=False):
        row = ["mcap", ch.topic, str(msg.log_time), str(msg.publish_time), stamp(m), frame(m)]
        out.append("\t".join(row + values(m)))

from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

with Reader(path) as bag:
    store = get_typestore(Stores.EMPTY)
    for c in bag.connections:
        store.register(get_types_from_msg(c.msgdef.data, c.msgtype))
    for c, t, raw in bag.messages():
        m = store.deserialize_cdr(raw, c.msgtype)
        row = ["rosbags", c.topic, str(t), str(t), stamp(m), frame(m)]
        out.append("\t".join(row + values(m)))
print("\n".join(out))
