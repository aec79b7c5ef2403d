//! The render loop, one for every render: a single device is a list of one.
//!
//! Each device runs on its own thread: it prepares its copy of the scene
//! ([`Prepared`]), then takes chunks of samples from a shared
//! [`SampleQueue`] as it finishes the last, sized by its own rate (about
//! [`CHUNK_S`] each), so a fast GPU takes most and a slow device still
//! helps. Its dispatches add to its own accumulation; it reads the sums back
//! only when they are needed: when the queue has nothing new for it (at the
//! end), at the end of a pass whose error is measured, at a checkpoint or a
//! stop. A chunk stays out in the queue until its sums are read back, so a
//! device that fails hands its unread chunks back to the others, who wait
//! for them.
//!
//! This thread gathers what the devices read back: it adds their sums, makes
//! each pass's row, writes checkpoints (the queue pauses until every chunk
//! out is read back, so that what is done is one range of samples), and on a
//! stop (Ctrl-C) lets the chunks under way finish and keeps them. Treelet's
//! random numbers are counted from (seed, pixel, sample), so the image is the
//! one-device image up to the devices' rounding, and a render resumed from a
//! part continues the same sums.
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use rayon::prelude::*;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};

use super::dispatch_size::DispatchSize;
use super::image_io::HdrImage;
use super::outcome::{PassRow, RenderResult, Share, Stopped};
use super::prepared::Prepared;
use super::queue::{Grid, SampleQueue, Take};
use super::settings::{samples_per_dispatch, MemoryEstimate, RenderSettings};
use super::sums::{add_sums, error_row, mean_image};
use super::variant::Plan;
use crate::runtime::backend::{Backend, DeviceClass};

/// Seconds of work a device takes at a time. (On two H100s, chunks of 0.5
/// and 1 s rendered the same images within 1% of the time of 0.25 s ones.)
pub const CHUNK_S: f64 = 0.25;

/// What steers a render from outside: a stop, checkpoints, a part to resume
/// from, and (for tests) a failure to inject.
#[derive(Default)]
pub struct Control<'a> {
    /// Set (by a Ctrl-C handler) to stop: no new chunk is handed out, the
    /// chunks under way finish, and the result holds the samples done.
    pub stop: Option<&'a AtomicBool>,
    /// Every so often, the sums of the samples done so far (one range from
    /// the first sample) go to `on_checkpoint`.
    pub checkpoint: Option<(Duration, &'a mut dyn FnMut(Range<u32>, &[[f32; 4]]) -> Result<()>)>,
    /// A part to continue: its sample range (which starts at the render's
    /// first sample) and its per-pixel sums.
    pub resume: Option<(Range<u32>, &'a [[f32; 4]])>,
    pub inject: Option<InjectedFailure>,
}

/// A failure injected for tests: device `device` fails when it takes its
/// chunk number `chunk` (from 0).
#[derive(Clone, Copy, Debug)]
pub struct InjectedFailure {
    pub device: usize,
    pub chunk: u32,
}

/// Renders `scene` on `b`; `on_pass` sees each pass's row as it completes.
/// An error if the device fails.
pub fn render<B: Backend>(
    b: &mut B,
    scene: &crate::scene::Scene,
    settings: &RenderSettings,
    reference: Option<&HdrImage>,
    on_pass: impl FnMut(&PassRow),
) -> Result<RenderResult> {
    let r = render_with(b, scene, settings, reference, Control::default(), on_pass)?;
    match &r.stopped {
        Some(Stopped::Failed(why)) => {
            bail!("the device failed after samples {}..{}: {why}", r.samples.start, r.samples.end)
        }
        _ => Ok(r),
    }
}

/// [`render`] steered by `control`: the result may stop short (see
/// [`RenderResult::stopped`]).
pub fn render_with<B: Backend>(
    b: &mut B,
    scene: &crate::scene::Scene,
    settings: &RenderSettings,
    reference: Option<&HdrImage>,
    control: Control<'_>,
    on_pass: impl FnMut(&PassRow),
) -> Result<RenderResult> {
    let prims = scene.traced_primitives();
    MemoryEstimate::of(settings, prims, &[b.class()]).check(settings, prims)?;
    super::prepared::prepare_pipelines(b, scene, settings);
    let step = samples_per_dispatch(settings.width as u64 * settings.height as u64, b.class());
    let name = b.adapter();
    let worker: Worker<'_> = Box::new(move |job| device_loop(b, job));
    run(vec![(name, worker)], step, scene, settings, reference, control, on_pass)
}

/// A device's thread: runs [`device_loop`] on its backend.
pub type Worker<'a> = Box<dyn FnOnce(&DeviceJob<'_>) + Send + 'a>;

/// What a device's thread is given.
pub struct DeviceJob<'a> {
    pub device: usize,
    scene: &'a crate::scene::Scene,
    settings: &'a RenderSettings,
    queue: &'a SampleQueue,
    /// The sums device 0 starts from (a resumed part), and their range.
    base: Option<(Range<u32>, &'a [[f32; 4]])>,
    rows: bool,
    inject: Option<u32>,
    events: Sender<Event>,
}

enum Event {
    Ready {
        device: usize,
        plan: Plan,
        build_ms: f64,
        prepare_s: f64,
    },
    Chunk {
        device: usize,
        range: Range<u32>,
        kernel_ms: f64,
        /// Samples per pixel of its largest dispatch.
        dispatch_samples: u32,
    },
    /// A device's sums so far, which hold the samples of `covers`.
    ReadBack {
        device: usize,
        sums: Vec<[f32; 4]>,
        covers: Vec<Range<u32>>,
        read_s: f64,
        for_rows: bool,
    },
    /// A device failed; the chunks in `lost` were done but not read back.
    Failed {
        device: usize,
        error: anyhow::Error,
        lost: Vec<Range<u32>>,
    },
}

/// One device's loop: prepare, then chunks until the queue is done.
pub fn device_loop<B: Backend>(b: &mut B, job: &DeviceJob<'_>) {
    let send = |e: Event| {
        let _ = job.events.send(e);
    };
    let base = job.base.clone().filter(|_| job.device == 0);
    let prepare_start = Instant::now();
    let prepared = match Prepared::new(b, job.scene, job.settings, base.as_ref().map(|b| b.1)) {
        Ok(p) => p,
        Err(error) => return send(Event::Failed { device: job.device, error, lost: Vec::new() }),
    };
    crate::runtime::timeline::mark("scene on the device");
    send(Event::Ready {
        device: job.device,
        plan: prepared.plan.clone(),
        build_ms: prepared.build_ms,
        prepare_s: prepare_start.elapsed().as_secs_f64(),
    });
    // Ranges in the accumulation, and those of them not read back yet. A
    // range stays out in the queue until it is read back: if the device
    // fails first, it goes back for the others, who wait for it meanwhile.
    let mut covers: Vec<Range<u32>> = base.into_iter().map(|b| b.0).collect();
    let mut unread: Vec<Range<u32>> = Vec::new();
    let read_back = |b: &mut B, covers: &[Range<u32>], unread: &mut Vec<Range<u32>>, for_rows: bool| -> Result<()> {
        let start = Instant::now();
        let sums = prepared.read_sums(b)?;
        send(Event::ReadBack {
            device: job.device,
            sums,
            covers: covers.to_vec(),
            read_s: start.elapsed().as_secs_f64(),
            for_rows,
        });
        for _ in unread.drain(..) {
            job.queue.finished();
        }
        Ok(())
    };
    // The first chunk, a few samples, measures the device's rate.
    let (mut want, mut chunks) = (1u32, 0u32);
    let pixels = job.settings.width as u64 * job.settings.height as u64;
    let mut size = DispatchSize::new(pixels, b.class());
    let outcome: Result<()> = loop {
        // A render scored after every pass takes no range past a pass end.
        let taken = if job.rows { job.queue.take_in_pass(want) } else { job.queue.take(want) };
        let range = match taken {
            Take::Range(r) => r,
            Take::Wait => {
                // Nothing new to take: read back what this device holds (the
                // others may be waiting for it, and a checkpoint or stop needs it).
                if !unread.is_empty() {
                    if let Err(e) = read_back(b, &covers, &mut unread, false) {
                        break Err(e);
                    }
                }
                std::thread::sleep(Duration::from_millis(2));
                continue;
            }
            // Unread ranges are out: the queue says done only when there are none.
            Take::Done => break Ok(()),
        };
        if job.inject == Some(chunks) {
            job.queue.give_back(range);
            break Err(anyhow!("injected failure"));
        }
        let chunk_start = Instant::now();
        let len = range.end - range.start;
        // Dispatched pass by pass, each cut by the dispatch size (on a CPU
        // device fixed, every `step` from the pass's start as the grid is,
        // so that every render's dispatches are the same). A GPU's sizes
        // follow its timing anyway, so unless passes are scored one by one
        // its chunk is cut evenly across pass ends: the passes of 4, 8, 16
        // and 32 samples early in a render otherwise make short dispatches,
        // whose lanes wait on their longest paths (see `DispatchSize`).
        let by_pass = job.rows || b.class() != DeviceClass::Gpu;
        let dispatched = (|| -> Result<(f64, u32)> {
            let (mut at, mut largest) = (range.start, 0);
            while at < range.end {
                let to = if by_pass { job.queue.grid().pass_end_after(at).min(range.end) } else { range.end };
                largest = largest.max(prepared.dispatch_samples(b, at, to - at, &size)?);
                at = to;
            }
            Ok((b.take_times()?.get("render"), largest))
        })();
        let (kernel_ms, dispatch_samples) = match dispatched {
            Ok(ms) => ms,
            Err(e) => {
                job.queue.give_back(range);
                break Err(e);
            }
        };
        chunks += 1;
        size.measured(len, kernel_ms / 1e3);
        covers.push(range.clone());
        unread.push(range.clone());
        send(Event::Chunk { device: job.device, range: range.clone(), kernel_ms, dispatch_samples });
        // Chunks are sized by the device's own rate, to take about CHUNK_S
        // each: a slow device never holds a large chunk at the end, and a
        // fast one waits seldom.
        let rate = len as f64 / chunk_start.elapsed().as_secs_f64().max(1e-6);
        want = (rate * CHUNK_S).clamp(1.0, 4096.0) as u32;
        // Sums stay on the device (a read-back of the whole image per chunk
        // cost each of two H100s 8 to 10% of its rate) but for an error row,
        // a checkpoint or a stop.
        let for_rows = job.rows && job.queue.grid().is_pass_end(range.end);
        if for_rows || job.queue.holding() {
            if let Err(e) = read_back(b, &covers, &mut unread, for_rows) {
                break Err(e);
            }
        }
    };
    if let Err(error) = outcome {
        // What was done and not read back is lost with the device: the
        // others render it again.
        for r in &unread {
            job.queue.give_back(r.clone());
        }
        send(Event::Failed { device: job.device, error, lost: unread });
    }
}

/// Runs `workers` (one per device, with its name) over the samples of
/// `settings`, cut on a grid of `step` samples within passes.
pub fn run(
    workers: Vec<(String, Worker<'_>)>,
    step: u32,
    scene: &crate::scene::Scene,
    settings: &RenderSettings,
    reference: Option<&HdrImage>,
    mut control: Control<'_>,
    mut on_pass: impl FnMut(&PassRow),
) -> Result<RenderResult> {
    let RenderSettings { width, height, spp, first_sample: first, error_each_pass, .. } = *settings;
    let Some(end) = first.checked_add(spp) else {
        bail!("samples {first}.. plus {spp}: the sample index must stay below 2^32")
    };
    if let Some(r) = reference {
        if (r.width, r.height) != (width, height) {
            bail!("reference image is {}x{}, the render {width}x{height}", r.width, r.height);
        }
    }
    let pixels = width as usize * height as usize;
    let resume_at = match &control.resume {
        Some((r, sums)) => {
            if r.start != first || r.end <= first || r.end > end {
                bail!("the part to resume holds samples {}..{}; this render is of {first}..{end}", r.start, r.end);
            }
            if sums.len() != pixels {
                bail!("the part to resume has {} pixels, the render {width}x{height}", sums.len());
            }
            r.end
        }
        None => first,
    };
    let devices = workers.len();
    let start = Instant::now();
    let grid = Grid::new(first..end, if devices == 1 { step } else { 1 });
    let queue = SampleQueue::on_grid(grid, resume_at, devices as u32);
    let (tx, rx) = mpsc::channel();
    let names: Vec<String> = workers.iter().map(|w| w.0.clone()).collect();
    let names_and_workers = workers;
    let mut g = Gather::new(&names, first, (width, height), control.resume.as_ref());
    let mut checkpoint_due = control.checkpoint.as_ref().and_then(|(every, _)| start.checked_add(*every));
    let mut checkpointing = false;
    let mut interrupted = false;
    let jobs: Vec<DeviceJob<'_>> = (0..devices)
        .map(|device| DeviceJob {
            device,
            scene,
            settings,
            queue: &queue,
            base: control.resume.clone(),
            rows: error_each_pass,
            inject: control.inject.filter(|f| f.device == device).map(|f| f.chunk),
            events: tx.clone(),
        })
        .collect();
    drop(tx);
    std::thread::scope(|s| -> Result<()> {
        for ((_, worker), job) in names_and_workers.into_iter().zip(jobs) {
            s.spawn(move || worker(&job));
        }
        loop {
            match rx.recv_timeout(Duration::from_millis(20)) {
                Ok(event) => g.take(event, &queue, start, reference, error_each_pass, &mut on_pass),
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if !interrupted && control.stop.is_some_and(|f| f.load(Ordering::Relaxed)) {
                interrupted = true;
                queue.stop();
            }
            if !checkpointing && checkpoint_due.is_some_and(|t| Instant::now() >= t) {
                checkpointing = true;
                queue.pause(true);
            }
            if checkpointing && queue.idle() {
                if let Some(done) = g.consistent() {
                    // The sums are copied: the devices go on while the part is written.
                    let sums = (done.end > first).then(|| g.sums_f32());
                    checkpointing = false;
                    queue.pause(false);
                    if let Some((every, write)) = control.checkpoint.as_mut() {
                        if let Some(sums) = sums {
                            write(done, &sums)?;
                        }
                        checkpoint_due = Instant::now().checked_add(*every);
                    }
                }
            }
        }
        Ok(())
    })?;
    crate::runtime::timeline::mark("render (kernels, read-backs)");
    let result = g.finish(start, first..end, interrupted, reference, &mut on_pass);
    crate::runtime::timeline::mark("image made");
    result
}

/// What this thread knows of the devices' work.
struct Gather {
    first: u32,
    width: u32,
    height: u32,
    pixels: usize,
    /// Each device's latest read-back sums and the ranges they hold.
    read: Vec<Option<(Vec<[f32; 4]>, Vec<Range<u32>>)>>,
    /// Every chunk done (read back or not), for progress.
    done: Vec<Range<u32>>,
    shares: Vec<Share>,
    errors: Vec<(usize, anyhow::Error)>,
    plan: Option<Plan>,
    build_ms: f64,
    kernel_ms: f64,
    /// Seconds spent reading back sums that only the error rows needed.
    measuring_s: f64,
    rows: Vec<PassRow>,
    /// The last sample whose pass row was given.
    row_at: u32,
}

impl Gather {
    fn new(
        names: &[String],
        first: u32,
        (width, height): (u32, u32),
        resume: Option<&(Range<u32>, &[[f32; 4]])>,
    ) -> Self {
        let mut read: Vec<_> = names.iter().map(|_| None).collect();
        let mut done = Vec::new();
        if let Some((r, sums)) = resume {
            // Device 0 starts from these sums; until it reads back, they are here.
            read[0] = Some((sums.to_vec(), vec![r.clone()]));
            done.push(r.clone());
        }
        let shares = names
            .iter()
            .map(|name| Share {
                device: name.clone(),
                samples: 0,
                chunks: 0,
                dispatch_samples: 0,
                seconds: 0.0,
                paths_per_s: 0.0,
                failed: None,
                prepare_s: 0.0,
                build_s: 0.0,
                kernel_s: 0.0,
                read_s: 0.0,
            })
            .collect();
        let row_at = resume.map_or(first, |r| r.0.end);
        Gather {
            first,
            width,
            height,
            pixels: width as usize * height as usize,
            read,
            done,
            shares,
            errors: Vec::new(),
            plan: None,
            build_ms: 0.0,
            kernel_ms: 0.0,
            measuring_s: 0.0,
            rows: Vec::new(),
            row_at,
        }
    }

    fn take(
        &mut self,
        event: Event,
        queue: &SampleQueue,
        start: Instant,
        reference: Option<&HdrImage>,
        error_rows: bool,
        on_pass: &mut impl FnMut(&PassRow),
    ) {
        match event {
            Event::Ready { device, plan, build_ms, prepare_s } => {
                self.shares[device].prepare_s = prepare_s;
                self.shares[device].build_s = build_ms / 1e3;
                if self.plan.is_none() {
                    self.plan = Some(plan);
                    self.build_ms = build_ms;
                }
            }
            Event::Chunk { device, range, kernel_ms, dispatch_samples } => {
                let share = &mut self.shares[device];
                share.dispatch_samples = share.dispatch_samples.max(dispatch_samples);
                share.samples += range.end - range.start;
                share.chunks += 1;
                share.kernel_s += kernel_ms / 1e3;
                share.seconds = start.elapsed().as_secs_f64();
                self.kernel_ms += kernel_ms;
                self.done.push(range);
                if !error_rows {
                    // Progress: a row without error for each pass now done
                    // (the last pass's row, with its error, comes at the end).
                    let done_to = prefix_end(self.first, &self.done);
                    while let Some(next) = self.next_pass_end(queue.grid(), done_to) {
                        self.row_at = next;
                        let row = self.row(queue.grid(), next, start, None, None);
                        on_pass(&row);
                    }
                }
            }
            Event::ReadBack { device, sums, covers, read_s, for_rows } => {
                self.shares[device].read_s += read_s;
                let last = covers.iter().any(|r| r.end == queue.grid().end());
                self.read[device] = Some((sums, covers));
                if for_rows && !last {
                    self.measuring_s += read_s;
                }
                if error_rows {
                    if let Some(done) = self.consistent() {
                        if queue.grid().is_pass_end(done.end) && done.end > self.row_at {
                            self.row_at = done.end;
                            let sums = self.sums_f32();
                            let row = self.row(queue.grid(), done.end, start, Some(&sums), reference);
                            on_pass(&row);
                            self.rows.push(row);
                        }
                    }
                }
            }
            Event::Failed { device, error, lost } => {
                self.done.retain(|r| !lost.contains(r));
                let share = &mut self.shares[device];
                share.samples -= lost.iter().map(|r| r.end - r.start).sum::<u32>();
                share.chunks -= lost.len() as u32;
                share.failed = Some(format!("{error:#}"));
                self.errors.push((device, error));
            }
        }
    }

    /// The next pass end after the last row, if the samples up to it are done.
    fn next_pass_end(&self, grid: &Grid, done_to: u32) -> Option<u32> {
        let mut x = self.row_at;
        while x < done_to {
            x = grid.next_after(x);
            if x <= done_to && x < grid.end() && grid.is_pass_end(x) {
                return Some(x);
            }
        }
        None
    }

    /// The pass row at sample `at`, its error measured from `sums` if given.
    fn row(
        &self,
        grid: &Grid,
        at: u32,
        start: Instant,
        sums: Option<&[[f32; 4]]>,
        reference: Option<&HdrImage>,
    ) -> PassRow {
        let elapsed_s = start.elapsed().as_secs_f64();
        let times = (elapsed_s, elapsed_s - self.measuring_s, (self.build_ms + self.kernel_ms) / 1e3);
        let pass = grid.pass_of(at) as u32;
        let spp = at - self.first;
        match sums {
            Some(sums) => error_row(pass, spp, times, sums, reference),
            None => PassRow {
                pass,
                spp,
                elapsed_s,
                wall_s: times.1,
                kernel_s: times.2,
                rmse: None,
                rel_mse: None,
                mean_std_error: None,
            },
        }
    }

    /// The samples the read-back sums hold, if they are every sample done
    /// and one range from the first.
    fn consistent(&self) -> Option<Range<u32>> {
        let mut held: Vec<Range<u32>> = self.read.iter().flatten().flat_map(|(_, c)| c.iter().cloned()).collect();
        let mut done = self.done.clone();
        held.sort_by_key(|r| r.start);
        done.sort_by_key(|r| r.start);
        if held != done {
            return None;
        }
        let end = prefix_end(self.first, &held);
        (held.iter().map(|r| r.end - r.start).sum::<u32>() == end - self.first).then_some(self.first..end)
    }

    /// The devices' read-back sums, added.
    fn sums_f64(&self) -> Vec<[f64; 4]> {
        let mut total = vec![[0f64; 4]; self.pixels];
        for (sums, _) in self.read.iter().flatten() {
            add_sums(&mut total, sums);
        }
        total
    }

    fn sums_f32(&self) -> Vec<[f32; 4]> {
        self.sums_f64().par_iter().map(|t| t.map(|v| v as f32)).collect()
    }

    fn finish(
        mut self,
        start: Instant,
        asked: Range<u32>,
        interrupted: bool,
        reference: Option<&HdrImage>,
        on_pass: &mut impl FnMut(&PassRow),
    ) -> Result<RenderResult> {
        let total_s = start.elapsed().as_secs_f64();
        for share in &mut self.shares {
            share.paths_per_s = share.samples as f64 * self.pixels as f64 / share.seconds.max(1e-9);
        }
        let failures = self
            .errors
            .iter()
            .map(|(d, e)| format!("{}: {e:#}", self.shares[*d].device))
            .collect::<Vec<_>>()
            .join("; ");
        let Some(done) = self.consistent() else {
            bail!("the samples read back are not one range from sample {} ({})", asked.start, failures);
        };
        if done.is_empty() {
            if interrupted {
                bail!("interrupted before the first samples were done");
            }
            if self.shares.len() == 1 {
                if let Some((_, e)) = self.errors.pop() {
                    return Err(e);
                }
            }
            bail!("0 of {} samples rendered: every device failed ({})", asked.end - asked.start, failures);
        }
        let stopped = if done.end == asked.end {
            None
        } else if interrupted {
            Some(Stopped::Interrupted)
        } else {
            Some(Stopped::Failed(failures))
        };
        let samples = done.end - done.start;
        let (sums, image) = if self.read.iter().flatten().count() == 1 {
            // One device's sums are the total as they are (an f32 through f64
            // and back is exact): no copy of the image's worth of sums.
            let sums = self.read.iter_mut().find_map(Option::take).map(|r| r.0).unwrap_or_default();
            let image = mean_image(self.width, self.height, &sums, samples);
            (sums, image)
        } else {
            let total = self.sums_f64();
            (total.par_iter().map(|t| t.map(|v| v as f32)).collect(), mean_image(self.width, self.height, &total, samples))
        };
        let grid = Grid::new(asked.clone(), 1);
        if self.rows.last().is_none_or(|r| r.spp != done.end - self.first) {
            // The last row always measures the error (as far as it is defined).
            let row = self.row(&grid, done.end, start, Some(&sums), reference);
            on_pass(&row);
            self.rows.push(row);
        }
        Ok(RenderResult {
            image,
            sums,
            rows: self.rows,
            build_ms: self.build_ms,
            render_ms: self.kernel_ms,
            total_s,
            plan: self.plan.ok_or_else(|| anyhow!("no device prepared the render"))?,
            samples: done,
            stopped,
            shares: self.shares,
        })
    }
}

/// The end of the run of `ranges` that starts at `first` and has no gap.
fn prefix_end(first: u32, ranges: &[Range<u32>]) -> u32 {
    let mut sorted: Vec<&Range<u32>> = ranges.iter().collect();
    sorted.sort_by_key(|r| r.start);
    let mut end = first;
    for r in sorted {
        if r.start == end {
            end = r.end;
        } else if r.start > end {
            break;
        }
    }
    end
}
