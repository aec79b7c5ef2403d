//! How far a long load has got: the loaders count the bytes they have read
//! or parsed, and whoever watches shows it (the command draws a bar once a
//! load has taken a second). The library only counts; with nobody watching,
//! counting costs an atomic add per block of a few megabytes.
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// One load in progress.
pub struct Work {
    /// What is being done, as a bar's message: "reading mesh big.obj".
    pub what: String,
    /// Bytes in all.
    pub total: u64,
    pub started: Instant,
    done: AtomicU64,
}

impl Work {
    /// Bytes done so far.
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }
}

static CURRENT: Mutex<Option<Arc<Work>>> = Mutex::new(None);

/// The load being tracked until it is dropped.
pub struct Tracked(Arc<Work>);

impl Drop for Tracked {
    fn drop(&mut self) {
        let mut current = CURRENT.lock().unwrap_or_else(|e| e.into_inner());
        if current.as_ref().is_some_and(|w| Arc::ptr_eq(w, &self.0)) {
            *current = None;
        }
    }
}

/// Starts tracking a load of `total` bytes (the one shown until it ends).
pub fn track(what: impl Into<String>, total: u64) -> Tracked {
    let work = Arc::new(Work { what: what.into(), total, started: Instant::now(), done: AtomicU64::new(0) });
    *CURRENT.lock().unwrap_or_else(|e| e.into_inner()) = Some(work.clone());
    Tracked(work)
}

impl Tracked {
    /// `bytes` more done.
    pub fn add(&self, bytes: u64) {
        self.0.done.fetch_add(bytes, Ordering::Relaxed);
    }
}

/// `bytes` more done of the load being tracked, if any (for code that
/// does not hold its [`Tracked`]: a parser's chunks).
pub fn add(bytes: u64) {
    if let Some(w) = CURRENT.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
        w.done.fetch_add(bytes, Ordering::Relaxed);
    }
}

/// The load being tracked, if any.
pub fn current() -> Option<Arc<Work>> {
    CURRENT.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (Other tests load files meanwhile, each tracked in its turn: this
    /// one looks at its own load only.)
    #[test]
    fn a_tracked_load_counts_until_dropped() {
        let t = track("reading x", 100);
        t.add(30);
        t.add(20);
        assert_eq!((t.0.what.as_str(), t.0.total, t.0.done()), ("reading x", 100, 50));
        let work = t.0.clone();
        drop(t);
        assert!(current().is_none_or(|w| !Arc::ptr_eq(&w, &work)), "a dropped load is no longer shown");
    }
}
