//! The samples of a render, handed out in ranges to the devices as they
//! ask ([`SampleQueue`]). Ranges end only on points of a fixed [`Grid`],
//! the ends of the error-measuring passes and every `step` samples between,
//! so that a render's dispatches cover the same samples however its chunks
//! were timed, stopped or resumed: on the CPU runner an interrupted and
//! resumed render is then the uninterrupted one bit for bit. The queue can
//! be paused (a checkpoint: no new range until the ranges out come back)
//! and stopped (Ctrl-C: no new range at all).
use std::ops::Range;
use std::sync::Mutex;

use super::settings::pass_schedule;

/// Where chunks of samples may end: the end of each pass of
/// [`pass_schedule`] over `first..end`, and within a pass every `step`
/// samples from its start (a device's dispatches are cut the same way, so a
/// chunk is whole dispatches).
#[derive(Clone, Debug)]
pub struct Grid {
    first: u32,
    /// Absolute end of each pass; the last is the render's end.
    passes: Vec<u32>,
    step: u32,
}

impl Grid {
    /// The grid of the samples `samples` (a render's whole range, even when
    /// it resumes from part of it), cut every `step` samples within a pass.
    pub fn new(samples: Range<u32>, step: u32) -> Self {
        let passes = pass_schedule(samples.end - samples.start).into_iter().map(|s| samples.start + s).collect();
        Grid { first: samples.start, passes, step: step.max(1) }
    }

    pub fn first(&self) -> u32 {
        self.first
    }

    pub fn end(&self) -> u32 {
        *self.passes.last().expect("a grid has a pass")
    }

    /// Whether `x` ends a pass.
    pub fn is_pass_end(&self, x: u32) -> bool {
        self.passes.binary_search(&x).is_ok()
    }

    /// The index of the pass that holds sample `x - 1` (that `x` ends or is in).
    pub fn pass_of(&self, x: u32) -> usize {
        self.passes.partition_point(|&e| e < x)
    }

    /// Whether `x` is a point of the grid (where a chunk may start or end).
    pub fn is_point(&self, x: u32) -> bool {
        x == self.first || self.is_pass_end(x) || {
            let i = self.passes.partition_point(|&e| e <= x);
            let start = if i == 0 { self.first } else { self.passes[i - 1] };
            i < self.passes.len() && (x - start).is_multiple_of(self.step)
        }
    }

    /// The end of the pass that holds sample `x` (`x` below the end).
    pub fn pass_end_after(&self, x: u32) -> u32 {
        self.passes[self.passes.partition_point(|&e| e <= x)]
    }

    /// The first point after `x` (`x` below the end).
    pub fn next_after(&self, x: u32) -> u32 {
        let i = self.passes.partition_point(|&e| e <= x);
        let (start, end) = (if i == 0 { self.first } else { self.passes[i - 1] }, self.passes[i]);
        end.min(start.saturating_add(((x - start) / self.step + 1).saturating_mul(self.step)))
    }
}

/// Sample ranges handed out to devices as they ask; ranges given back (by a
/// failed device) go out first. A device leaves only when no range is left
/// and none is being rendered (one may yet come back).
pub struct SampleQueue {
    state: Mutex<State>,
    grid: Grid,
    devices: u32,
}

struct State {
    next: u32,
    given_back: Vec<Range<u32>>,
    /// Ranges taken and neither finished nor given back.
    out: u32,
    paused: bool,
    stopped: bool,
}

/// What a device asking the queue gets.
pub enum Take {
    Range(Range<u32>),
    /// Nothing now, but a range out may come back, or a pause end: ask again.
    Wait,
    Done,
}

impl SampleQueue {
    /// The queue of `samples` (cut every sample) for `devices` devices.
    pub fn new(samples: Range<u32>, devices: u32) -> Self {
        let start = samples.start;
        Self::on_grid(Grid::new(samples, 1), start, devices)
    }

    /// The queue of the samples of `grid` from `start` (a grid point: where
    /// a resumed render's part ends), for `devices` devices.
    pub fn on_grid(grid: Grid, start: u32, devices: u32) -> Self {
        let state = State { next: start, given_back: Vec::new(), out: 0, paused: false, stopped: false };
        SampleQueue { state: Mutex::new(state), grid, devices: devices.max(1) }
    }

    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// About `want` samples (at least to the next grid point; at most half
    /// of a fair share of what is left, so that the end is shared too,
    /// rounded down to a grid point), or a range given back whole.
    pub fn take(&self, want: u32) -> Take {
        self.take_up_to(want, false)
    }

    /// As [`SampleQueue::take`], but never past the end of the pass the
    /// range starts in: a render that scores its image after every pass
    /// needs its sums at each pass end.
    pub fn take_in_pass(&self, want: u32) -> Take {
        self.take_up_to(want, true)
    }

    fn take_up_to(&self, want: u32, in_pass: bool) -> Take {
        let mut s = self.lock();
        if let Some(r) = s.given_back.pop() {
            s.out += 1;
            return Take::Range(r);
        }
        let (start, end) = (s.next, self.grid.end());
        if start >= end || s.stopped {
            return if s.out > 0 { Take::Wait } else { Take::Done };
        }
        if s.paused {
            return Take::Wait;
        }
        let fair = ((end - start) / (2 * self.devices)).max(1);
        let mut limit = start.saturating_add(want.clamp(1, fair));
        if in_pass {
            limit = limit.min(self.grid.pass_end_after(start));
        }
        let mut stop = self.grid.next_after(start);
        while stop < end {
            let next = self.grid.next_after(stop);
            if next > limit {
                break;
            }
            stop = next;
        }
        s.next = stop;
        s.out += 1;
        Take::Range(start..stop)
    }

    /// A range taken is rendered and its sums are read back.
    pub fn finished(&self) {
        self.lock().out -= 1;
    }

    /// A range taken is not rendered: another device takes it.
    pub fn give_back(&self, r: Range<u32>) {
        let mut s = self.lock();
        s.given_back.push(r);
        s.out -= 1;
    }

    /// No new range (ranges given back still go out) until resumed.
    pub fn pause(&self, paused: bool) {
        self.lock().paused = paused;
    }

    /// No new range ever (ranges given back still go out, so that what is
    /// done stays one range from the start).
    pub fn stop(&self) {
        self.lock().stopped = true;
    }

    /// Whether devices should read back their sums now: the queue is
    /// paused or stopped.
    pub fn holding(&self) -> bool {
        let s = self.lock();
        s.paused || s.stopped
    }

    /// Whether no range is out or waiting to go out again.
    pub fn idle(&self) -> bool {
        let s = self.lock();
        s.out == 0 && s.given_back.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_taken_in_pass_end_at_every_pass_end() {
        // Passes of 0..100: 4, 8, 16, 32, 64, 100.
        let q = SampleQueue::on_grid(Grid::new(0..100, 1), 0, 1);
        let mut ranges = Vec::new();
        while let Take::Range(r) = q.take_in_pass(1000) {
            ranges.push(r);
            q.finished();
        }
        let passes = [4, 8, 16, 32, 64, 100];
        for end in passes {
            assert!(ranges.iter().any(|r| r.end == end), "no range ends at {end}: {ranges:?}");
        }
        assert!(ranges.iter().all(|r| !passes.iter().any(|&p| r.start < p && p < r.end)), "{ranges:?}");
        // Without it, a large want runs past pass ends.
        let q = SampleQueue::on_grid(Grid::new(0..100, 1), 0, 1);
        assert!(matches!(q.take(1000), Take::Range(r) if r.end > 4));
    }

    #[test]
    fn grid_points_are_pass_ends_and_steps_within_passes() {
        // Passes of 0..100: 4, 8, 16, 32, 64, 100; step 16.
        let g = Grid::new(0..100, 16);
        let mut points = vec![0];
        while *points.last().unwrap() < 100 {
            points.push(g.next_after(*points.last().unwrap()));
        }
        assert_eq!(points, vec![0, 4, 8, 16, 32, 48, 64, 80, 96, 100]);
        assert!(points.iter().all(|&p| g.is_point(p)));
        assert!(!g.is_point(5) && !g.is_point(40) && !g.is_point(97));
        // A grid from a first sample other than 0 is the same grid shifted.
        let h = Grid::new(10..110, 16);
        assert_eq!(h.next_after(10 + 64), 10 + 80);
        assert!(h.is_pass_end(10 + 32) && !h.is_pass_end(32));
    }

    #[test]
    fn chunks_end_on_grid_points() {
        let q = SampleQueue::on_grid(Grid::new(0..300, 16), 0, 1);
        let mut at = 0;
        for want in [1, 3, 7, 40, 100].into_iter().chain(std::iter::repeat(1000)).take(100) {
            match q.take(want) {
                Take::Range(r) => {
                    assert_eq!(r.start, at);
                    assert!(q.grid().is_point(r.end), "{r:?}");
                    assert!(r.end - r.start <= want.max(q.grid().next_after(r.start) - r.start), "{r:?} for {want}");
                    at = r.end;
                    q.finished();
                }
                _ => break,
            }
        }
        assert_eq!(at, 300);
        assert!(matches!(q.take(1), Take::Done));
    }

    #[test]
    fn a_paused_or_stopped_queue_hands_out_only_ranges_given_back() {
        let q = SampleQueue::new(0..64, 2);
        let Take::Range(a) = q.take(4) else { panic!() };
        q.pause(true);
        assert!(q.holding() && matches!(q.take(4), Take::Wait));
        q.give_back(a.clone());
        assert!(matches!(q.take(4), Take::Range(r) if r == a));
        q.finished();
        assert!(q.idle());
        q.pause(false);
        assert!(matches!(q.take(4), Take::Range(_)));
        q.finished();
        q.stop();
        assert!(matches!(q.take(4), Take::Done));
    }
}
