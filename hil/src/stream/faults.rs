//! The scene's fault schedule on the link: one AddFault per `[[fault]]`, in schedule order,
//! each with its device's seed (`docs/spec/link.md` §5.16), sent after Configure, AddDevice and
//! AddVibration and before Start, in both source modes.
//!
//! What the device then does with each class: source (b)'s model applies device 0's sensor
//! faults exactly as the host's prediction ([`predict_model`](super::predict_model)) does; in
//! source (a) the images carry them; the chips apply the chip faults at their windows' edges;
//! the timing faults move the instants the device latches samples, which its Served reports
//! carry (a shifted sample in a batch of its own, at its latch time) and the session logs as
//! reported: the Served check compares the images' CRCs, not the instants.
//!
//! ```
//! use margemu_hil::stream::fault_messages;
//! use margemu_model::fault::{Fault, FaultKind, Window};
//! use margemu_sim::scene::Scene;
//! let mut scene = Scene::parse_str(
//!     "duration = 0.01\nrate = 1000.0\nseed = 5\nmotion = \"static\"\n",
//!     std::path::Path::new("inline.toml"),
//! ).unwrap();
//! scene.faults.push(Fault::new(0, Window::new(0, 1_000_000), FaultKind::Late { delay_ns: 10 }));
//! let msgs = fault_messages(&scene);
//! assert_eq!((msgs.len(), msgs[0].seed), (1, 5));
//! ```

use margemu_model::fault::MAX_FAULTS;
use margemu_protocol::link::AddFault;
use margemu_sim::marg::device_seed;
use margemu_sim::scene::Scene;

/// Why the device would refuse `scene`'s schedule, before anything is sent: more than
/// [`MAX_FAULTS`] faults, or a timing fault that moves the latch (clock_offset, late,
/// drdy_jitter) on a device other than the first (a rig's devices share the device's one
/// serving clock). The scene check refuses the rest (overlaps, unknown devices).
pub fn fault_refusal(scene: &Scene) -> Option<String> {
    if scene.faults.len() > MAX_FAULTS {
        return Some(format!(
            "the scene has {} faults: the device holds at most {MAX_FAULTS}",
            scene.faults.len()
        ));
    }
    let (i, f) = scene
        .faults
        .iter()
        .enumerate()
        .find(|(_, f)| f.device != 0 && f.kind.moves_latch())?;
    Some(format!(
        "fault {} ({} on device {}): a rig's devices share the device's one serving clock, \
         so only the first device's samples can be moved; put it on device 0",
        i + 1,
        f.kind.name(),
        f.device
    ))
}

/// The AddFault messages of `scene`'s schedule, in order (see the module docs).
pub fn fault_messages(scene: &Scene) -> Vec<AddFault> {
    scene
        .faults
        .iter()
        .map(|&fault| AddFault {
            fault,
            seed: device_seed(scene.spec.seed, usize::from(fault.device)),
        })
        .collect()
}
