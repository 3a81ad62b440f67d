//! The receiving half of a session: a thread that reads the port, feeds the link's
//! [`Accumulator`], and turns every frame outcome into an owned [`RxEvent`] on a channel, so the
//! pacing loop never blocks on the port. Every device → host message is passed on (HelloAck,
//! Credit, Telemetry, RegisterWrites, Reset, Error, Served); a host → device kind coming back
//! is counted as rejected.
//!
//! The thread ends when the port reports end of file or an error (a vanished device), or when
//! the session sets the shutdown flag (checked whenever a read returns, so the reader must time
//! out: a `TTYPort` does, after its timeout).

use margemu_protocol::link::{
    Accumulator, Credit, ErrorReport, FeedResult, FrameRepr, HelloAck, Message, RegisterWrite,
    Reset, RxStats, SeqTracker, ServedSample, Telemetry,
};
use std::io::{self, Read};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::Arc;

use super::clock::Clock;

/// A device → host message, owned.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceMessage {
    /// Answer to Hello.
    HelloAck(HelloAck),
    /// Flow-control window.
    Credit(Credit),
    /// Counters and state.
    Telemetry(Telemetry),
    /// Writes made by the device under test, and how many were dropped before them.
    RegisterWrites {
        /// Writes lost since the previous batch.
        dropped: u32,
        /// The writes, oldest first.
        writes: Vec<RegisterWrite>,
    },
    /// The device (re)booted.
    Reset(Reset),
    /// The device refused something.
    Error(ErrorReport),
    /// What the chip presented at consecutive sample instants.
    Served {
        /// Output sample index of the first entry.
        first_index: u64,
        /// Device scene time at which the first entry was served.
        first_time_ns: u64,
        /// One entry per instant: CRC-32C of the image latched, underrun and empty flags.
        samples: Vec<ServedSample>,
    },
}

/// What the reader thread saw.
#[derive(Debug)]
pub enum RxEvent {
    /// An intact frame with a device → host message.
    Message {
        /// When it was decoded, host time (ns since the session's origin).
        at_ns: u64,
        /// Its sequence number.
        seq: u16,
        /// The message.
        message: DeviceMessage,
    },
    /// The receive counters changed (a damaged or rejected frame, or a sequence gap).
    Stats(RxStats),
    /// The port is gone: end of file or a read error. The thread has ended.
    Closed(Option<io::Error>),
}

/// Spawns the reader thread over `port`; events are stamped with `clock`.
pub fn spawn(
    mut port: impl Read + Send + 'static,
    clock: impl Clock + 'static,
    shutdown: Arc<AtomicBool>,
) -> (Receiver<RxEvent>, std::thread::JoinHandle<()>) {
    let (tx, rx) = std::sync::mpsc::channel();
    let handle = std::thread::Builder::new()
        .name("margemu-rx".into())
        .spawn(move || {
            let mut decoder = Decoder::default();
            let mut buf = [0u8; 4096];
            while !shutdown.load(Ordering::Relaxed) {
                match port.read(&mut buf) {
                    Ok(0) => {
                        let _ = tx.send(RxEvent::Closed(None));
                        return;
                    }
                    Ok(n) => {
                        if decoder.feed(&buf[..n], clock.now_ns(), &tx).is_err() {
                            return; // the session is gone
                        }
                    }
                    Err(e) if is_transient(&e) => {}
                    Err(e) => {
                        let _ = tx.send(RxEvent::Closed(Some(e)));
                        return;
                    }
                }
            }
        })
        .expect("spawn the receive thread");
    (rx, handle)
}

/// A read error that only means "nothing yet" (timeout, would block, interrupted).
pub(crate) fn is_transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

/// Accumulator, sequence tracker and counters of the device → host direction.
#[derive(Default)]
pub struct Decoder {
    acc: Accumulator,
    seq: SeqTracker,
    stats: RxStats,
}

impl Decoder {
    /// Feeds bytes received at host time `at_ns`; sends one event per message and one
    /// [`RxEvent::Stats`] per chunk that changed the counters. Fails only when the receiving end
    /// of `tx` is gone.
    pub fn feed(
        &mut self,
        mut input: &[u8],
        at_ns: u64,
        tx: &Sender<RxEvent>,
    ) -> Result<(), std::sync::mpsc::SendError<RxEvent>> {
        let before = self.stats;
        while !input.is_empty() {
            let result = self.acc.feed(input);
            input = result.remaining();
            match result {
                FeedResult::Consumed => {}
                FeedResult::Success { frame, .. } => {
                    self.stats.frames = self.stats.frames.wrapping_add(1);
                    match FrameRepr::parse(&frame) {
                        Ok(repr) => {
                            if matches!(repr.message, Message::Reset(_)) {
                                self.seq.restart();
                            }
                            let event = self.seq.observe(repr.seq);
                            self.stats.record_seq(event);
                            match owned(&repr.message) {
                                Some(message) => tx.send(RxEvent::Message {
                                    at_ns,
                                    seq: repr.seq,
                                    message,
                                })?,
                                // A host → device kind coming back is refused; a device → host
                                // kind this host does not use (e.g. a newer one) is skipped.
                                None if repr.message.kind().is_host_to_device() => self.reject(),
                                None => {}
                            }
                        }
                        Err(e) => self.stats.record_error(e),
                    }
                }
                damaged => self.stats.record(&damaged),
            }
        }
        if self.stats != before {
            tx.send(RxEvent::Stats(self.stats))?;
        }
        Ok(())
    }

    fn reject(&mut self) {
        self.stats.rejected_messages = self.stats.rejected_messages.wrapping_add(1);
    }
}

/// The owned form of a device → host message the session uses; `None` otherwise.
fn owned(message: &Message<'_>) -> Option<DeviceMessage> {
    Some(match message {
        Message::HelloAck(m) => DeviceMessage::HelloAck(*m),
        Message::Credit(m) => DeviceMessage::Credit(*m),
        Message::Telemetry(m) => DeviceMessage::Telemetry(*m),
        Message::RegisterWrites(b) => DeviceMessage::RegisterWrites {
            dropped: b.dropped,
            writes: b.writes.iter().collect(),
        },
        Message::Reset(m) => DeviceMessage::Reset(*m),
        Message::Error(m) => DeviceMessage::Error(*m),
        Message::Served(b) => DeviceMessage::Served {
            first_index: b.first_index,
            first_time_ns: b.first_time_ns,
            samples: b.samples.iter().collect(),
        },
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_protocol::link::{Encoder, MAX_WIRE_LEN};

    #[test]
    fn garbage_is_counted_and_the_next_frame_recovered() {
        let mut enc = Encoder::new();
        let mut wire = [0u8; MAX_WIRE_LEN];
        let credit = Credit {
            next_index: 256,
            limit: 320,
        };
        let n = enc.encode(&Message::Credit(credit), &mut wire).unwrap();
        let mut bytes = vec![0x00, 0x42, 0x13, 0x37];
        bytes.extend_from_slice(&wire[..n]);
        let (tx, rx) = std::sync::mpsc::channel();
        let mut decoder = Decoder::default();
        decoder.feed(&bytes[..5], 0, &tx).unwrap();
        decoder.feed(&bytes[5..], 0, &tx).unwrap();
        let events: Vec<RxEvent> = rx.try_iter().collect();
        // The garbage ends at the frame's leading 0x00: one damaged frame, reported first.
        assert!(
            matches!(&events[0], RxEvent::Stats(s) if s.frames == 0),
            "{events:?}"
        );
        assert!(matches!(
            &events[1],
            RxEvent::Message { seq: 0, message: DeviceMessage::Credit(c), .. } if *c == credit
        ));
        let RxEvent::Stats(stats) = &events[2] else {
            panic!("{events:?}")
        };
        assert_eq!(
            (stats.frames, stats.crc_errors + stats.framing_errors),
            (1, 1)
        );
    }
}
