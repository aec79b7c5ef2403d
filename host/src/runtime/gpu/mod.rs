//! The wgpu runtime: device set-up ([`context`]) and the [`Backend`]
//! implementation that records, times and submits dispatches ([`backend`]).
//!
//! [`Backend`]: crate::runtime::backend::Backend
pub mod backend;
pub mod context;

pub use backend::GpuBackend;
pub use context::{quiet_mesa_runtime_dir, GpuContext, COMMITTED_SHADER_PATH, SHADER_SPV};
