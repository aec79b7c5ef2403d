//! A render, over any [`Backend`](crate::runtime::backend::Backend) and
//! any number of devices: the BVH (if any) is built on each device, then
//! chunks of samples are added to every pixel, the error is measured after
//! each pass (against a reference image or from the per-pixel variance),
//! and parts of a render made apart add up to the whole.
//!
//! | file | what it holds |
//! |---|---|
//! | `settings.rs` | what a render is asked for; passes and the first dispatch size |
//! | `dispatch_size.rs` | samples per dispatch, grown on a GPU to its measured rate |
//! | `integrator_choice.rs` | `--integrator auto`: a pilot of NEE against light paths |
//! | `variant.rs` | the plan: tree, layout and kernel variant for a scene and device |
//! | `prepared.rs` | one device's tree, buffers and accumulation |
//! | `instances.rs` | instances of meshes: their trees and what the kernel reads of them |
//! | `queue.rs` | the samples handed out to devices, cut on a fixed grid |
//! | `run.rs` | the one render loop: devices, checkpoints, stops, resumes |
//! | `devices.rs` | opening devices (`--devices`) and rendering on them |
//! | `sums.rs` | per-pixel sums, their image, the error measures |
//! | `outcome.rs` | what a render gives back |
//! | `parts.rs` | parts of a render as EXR files, and merging them |
//! | `lock.rs` | the lock beside `--out` for the life of a render |
//! | `image_io.rs` | reading and writing images |
pub mod devices;
pub mod dispatch_size;
pub mod image_io;
pub mod integrator_choice;
pub mod lock;
pub mod outcome;
pub mod parts;
pub mod instances;
pub mod prepared;
pub mod queue;
pub mod run;
pub mod settings;
pub mod sums;
pub mod variant;

pub use outcome::{PassRow, RenderResult, Share, Stopped};
pub use prepared::{light_table, Prepared};
pub use run::{render, render_with, Control, InjectedFailure};
pub use settings::{max_samples_per_dispatch, pass_schedule, Integrator, RenderSettings, Sampler, MAX_PATHS_PER_DISPATCH};
pub use sums::{add_sums, image_error, mean_image};
