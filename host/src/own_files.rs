//! Every file name margemu writes into a run or session directory, gathered from the layers
//! that write them (each list is defined next to its writer): what `--force` may remove
//! ([`margemu_sim::rundir::prepare`]).

use margemu_sim::rundir::OwnFiles;

/// The lists: a run's, a session's, the device under test's, an evaluation's and the demo's.
pub const OWN_FILES: OwnFiles = &[
    &margemu_sim::output::RUN_FILES,
    &margemu_sim::mcap::FILES,
    &margemu_hil::stream::log::SESSION_FILES,
    &margemu_hil::dut::log::FILES,
    &margemu_hil::hitl::session::HITL_FILES,
    &margemu_eval::evaluate::report::FILES,
    &[crate::demo::table::FILE],
];
