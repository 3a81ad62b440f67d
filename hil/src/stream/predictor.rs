//! Lazy prediction: a scene's samples computed in order on a thread of their own, a few chunks
//! ahead of the reader, so a session holds a bounded number of them however long the scene.
//!
//! [`Predictions`] is an iterator over what a producer (a closure driving
//! [`run::run`](margemu_sim::run::run)) emits: the thread computes chunks of [`CHUNK`] items and stops
//! when [`DEPTH`] chunks wait unread; dropping the iterator ends the thread at its next chunk. A
//! producer's error is the last item. The computation is the producer's alone, in the same order
//! as a single-threaded run, so its results are bit-identical.

use margemu_sim::run::RunError;
use std::sync::mpsc::{sync_channel, Receiver};
use std::thread::JoinHandle;

/// Items per chunk passed from the producer's thread.
pub const CHUNK: usize = 256;
/// Chunks that may wait unread (a second of a 4 kHz scene, about 1.2 MB).
pub const DEPTH: usize = 16;

/// The producer asked the run to stop: its reader is gone.
pub(super) struct ReaderGone;

/// Why a producer stops a run early: its reader is gone (not an error), or it failed.
pub(super) enum Halt {
    ReaderGone,
    Failed(RunError),
}

impl From<ReaderGone> for Halt {
    fn from(_: ReaderGone) -> Self {
        Halt::ReaderGone
    }
}

/// Emits one item; `Err(ReaderGone)` once nobody reads any more.
pub(super) type Emit<'a, T> = &'a mut dyn FnMut(T) -> Result<(), ReaderGone>;

/// The items of a producer, in order (see the module docs).
pub struct Predictions<T> {
    rx: Option<Receiver<Result<Vec<T>, RunError>>>,
    chunk: std::vec::IntoIter<T>,
    thread: Option<JoinHandle<()>>,
}

impl<T: Send + 'static> Predictions<T> {
    /// Runs `produce` on a new thread; it emits items until done, or returns early with
    /// `Ok(())` when an emit fails.
    pub(super) fn spawn(
        produce: impl FnOnce(Emit<'_, T>) -> Result<(), RunError> + Send + 'static,
    ) -> Self {
        let (tx, rx) = sync_channel(DEPTH);
        let thread = std::thread::Builder::new()
            .name("margemu-predict".into())
            .spawn(move || {
                let mut chunk = Vec::with_capacity(CHUNK);
                let mut emit = |item| {
                    chunk.push(item);
                    if chunk.len() < CHUNK {
                        return Ok(());
                    }
                    let full = std::mem::replace(&mut chunk, Vec::with_capacity(CHUNK));
                    tx.send(Ok(full)).map_err(|_| ReaderGone)
                };
                let result = produce(&mut emit);
                let _ = match result {
                    Ok(()) => tx.send(Ok(chunk)),
                    Err(e) => tx.send(Ok(chunk)).and_then(|()| tx.send(Err(e))),
                };
            })
            .expect("spawning the prediction thread");
        Self {
            rx: Some(rx),
            chunk: Vec::new().into_iter(),
            thread: Some(thread),
        }
    }
}

impl<T> Iterator for Predictions<T> {
    type Item = Result<T, RunError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(item) = self.chunk.next() {
                return Some(Ok(item));
            }
            match self.rx.as_ref()?.recv() {
                Ok(Ok(chunk)) => self.chunk = chunk.into_iter(),
                Ok(Err(e)) => {
                    self.rx = None;
                    return Some(Err(e));
                }
                Err(_) => {
                    self.rx = None;
                    return None;
                }
            }
        }
    }
}

impl<T> Drop for Predictions<T> {
    fn drop(&mut self) {
        drop(self.rx.take());
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Runs `scene` through [`run::run`](margemu_sim::run::run), handing each truth to `each` until it
/// halts: a reader gone ends the run without error, a failure is the run's error.
pub(super) fn run_scene(
    scene: &margemu_sim::scene::Scene,
    each: impl FnMut(&margemu_sim::truth::Truth) -> Result<(), Halt>,
) -> Result<(), RunError> {
    match margemu_sim::run::run(scene, each, |_, _| {})? {
        Ok(_) | Err(Halt::ReaderGone) => Ok(()),
        Err(Halt::Failed(e)) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_come_in_order_and_an_error_comes_last() {
        let all: Vec<_> = Predictions::spawn(|emit| (0..1000u32).try_for_each(emit).or(Ok(())))
            .collect::<Result<_, _>>()
            .unwrap();
        assert_eq!(all, (0..1000).collect::<Vec<_>>());
        let failing = Predictions::spawn(|emit| {
            let _ = emit(1u8);
            Err(RunError::Model(margemu_model::Error::InvalidRate))
        });
        let got: Vec<_> = failing.map(|r| r.is_ok()).collect();
        assert_eq!(got, [true, false]);
    }

    #[test]
    fn dropping_the_reader_ends_an_endless_producer() {
        let mut endless = Predictions::spawn(|emit| {
            let mut i = 0u64;
            while emit(i).is_ok() {
                i += 1;
            }
            Ok(())
        });
        assert_eq!(endless.nth(10_000).map(Result::ok), Some(Some(10_000)));
        drop(endless); // joins the thread: the test ends only if it stopped
    }
}
