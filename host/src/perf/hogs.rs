//! CPU hogs for `margemu bench stream --loaded N`: busy threads at normal priority, each
//! spinning on a core's worth of arithmetic until stopped, so a streaming row measures pacing
//! while the machine has other work to do.
//!
//! ```
//! use margemu::perf::hogs::Hogs;
//! let hogs = Hogs::start(2).unwrap();
//! hogs.wait_running();
//! assert_eq!(hogs.running(), 2);
//! assert_eq!(hogs.stop(), 0); // every hog has ended
//! ```

use std::hint::black_box;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

/// Running hogs; [`Hogs::stop`] (or dropping them) ends them.
#[derive(Debug)]
pub struct Hogs {
    stop: Arc<AtomicBool>,
    running: Arc<AtomicUsize>,
    threads: Vec<JoinHandle<()>>,
}

impl Hogs {
    /// Starts `n` hog threads from the calling thread (which must be at normal priority: a
    /// thread inherits its creator's policy).
    pub fn start(n: usize) -> std::io::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let running = Arc::new(AtomicUsize::new(0));
        let mut hogs = Self {
            stop: stop.clone(),
            running: running.clone(),
            threads: Vec::with_capacity(n),
        };
        for i in 0..n {
            let (stop, running) = (stop.clone(), running.clone());
            let thread = std::thread::Builder::new()
                .name(format!("margemu-hog-{i}"))
                .spawn(move || {
                    running.fetch_add(1, Ordering::SeqCst);
                    let mut x = 1u64;
                    while !stop.load(Ordering::Relaxed) {
                        for _ in 0..1024 {
                            x = black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
                        }
                    }
                    running.fetch_sub(1, Ordering::SeqCst);
                })?;
            hogs.threads.push(thread);
        }
        Ok(hogs)
    }

    /// Hogs spinning now.
    pub fn running(&self) -> usize {
        self.running.load(Ordering::SeqCst)
    }

    /// Returns once every hog started has begun spinning.
    pub fn wait_running(&self) {
        while self.running() < self.threads.len() {
            std::thread::yield_now();
        }
    }

    /// Ends every hog and waits for it; returns how many are still spinning (0).
    pub fn stop(mut self) -> usize {
        self.end();
        self.running()
    }

    fn end(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
    }
}

impl Drop for Hogs {
    fn drop(&mut self) {
        self.end();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hogs_start_and_stop() {
        let hogs = Hogs::start(3).unwrap();
        hogs.wait_running();
        assert_eq!(hogs.running(), 3);
        let running = hogs.running.clone();
        assert_eq!(hogs.stop(), 0);
        assert_eq!(running.load(Ordering::SeqCst), 0);
    }

    #[test]
    fn dropped_hogs_end() {
        let hogs = Hogs::start(1).unwrap();
        hogs.wait_running();
        let running = hogs.running.clone();
        drop(hogs);
        assert_eq!(running.load(Ordering::SeqCst), 0);
        assert_eq!(Hogs::start(0).unwrap().stop(), 0);
    }
}
