//! Marks on the process's clock: what a short run spends besides its
//! kernels (Vulkan's instance, the device, pipelines, uploads, the image
//! file), so that `render --explain` can say where the time went.
//!
//! A mark costs a lock and a push; code marks once per stage, never per
//! sample or chunk.

use std::sync::{Mutex, OnceLock};
use std::time::Instant;

static START: OnceLock<Instant> = OnceLock::new();
static MARKS: Mutex<Vec<(&'static str, f64)>> = Mutex::new(Vec::new());

/// Starts the clock (the first call wins; `main` calls it first thing).
pub fn start() -> Instant {
    *START.get_or_init(Instant::now)
}

/// Seconds since [`start`].
pub fn now_s() -> f64 {
    start().elapsed().as_secs_f64()
}

/// The most marks kept: a process that renders again and again (an
/// engine, a benchmark) keeps its first stages, not a list without end.
const MAX_MARKS: usize = 256;

/// Records that `what` ended now.
pub fn mark(what: &'static str) {
    let at = now_s();
    let mut marks = MARKS.lock().unwrap_or_else(|e| e.into_inner());
    if marks.len() < MAX_MARKS {
        marks.push((what, at));
    }
}

/// The marks so far, in time order: (what ended, seconds
/// since the start).
pub fn marks() -> Vec<(&'static str, f64)> {
    let mut marks = MARKS.lock().unwrap_or_else(|e| e.into_inner()).clone();
    // Threads (the devices open beside the scene's loading) mark in any order.
    marks.sort_by(|a, b| a.1.total_cmp(&b.1));
    marks
}

/// The marks as one line of stages and their durations, each from the mark
/// before: `arguments 0.001 s, Vulkan 0.102 s, ...`.
pub fn summary() -> String {
    let mut last = 0.0;
    marks()
        .into_iter()
        .map(|(what, at)| {
            let part = format!("{what} {:.3}", at - last);
            last = at;
            part
        })
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Marks from several threads come back in time order, each stage's
    /// duration from the mark before, and the list stops at its cap.
    #[test]
    fn marks_are_in_time_order_and_capped() {
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    for _ in 0..100 {
                        mark("test stage");
                    }
                });
            }
        });
        let marks = marks();
        assert_eq!(marks.len(), MAX_MARKS);
        assert!(marks.windows(2).all(|w| w[0].1 <= w[1].1));
        let summary = summary();
        // Other tests of this process may have marked too (a device opened).
        let others = marks.iter().filter(|m| m.0 != "test stage").count();
        assert_eq!(summary.matches("test stage").count(), MAX_MARKS - others);
        assert!(summary.split(", ").all(|part| part.rsplit(' ').next().unwrap().parse::<f64>().unwrap() >= 0.0), "{summary}");
    }
}
